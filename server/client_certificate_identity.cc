#include "server/client_certificate_identity.h"

#include <grpc/grpc_security_constants.h>

#include <string>
#include <vector>

namespace neuralmesh::server {

grpc::Status ClientCertificateIdentity::Process(const InputMetadata& /*auth_metadata*/,
                                                grpc::AuthContext* context,
                                                OutputMetadata* /*consumed_auth_metadata*/,
                                                OutputMetadata* /*response_metadata*/) {
  const std::vector<grpc::string_ref> names =
      context->FindPropertyValues(GRPC_X509_CN_PROPERTY_NAME);
  if (names.empty() || names.front().empty()) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "the client certificate has no common name to name its client by");
  }
  context->AddProperty(kClientProperty, names.front());
  context->AddProperty(kRoleProperty, std::string(AccessRoleName(role_)));
  return grpc::Status::OK;
}

}  // namespace neuralmesh::server
