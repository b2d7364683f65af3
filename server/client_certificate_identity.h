// Under mutual TLS without access tokens: the client of a call is the common name of the
// certificate it presented, with one role for all (session_access.h), so that sessions belong
// to the client that created them (neuralmesh-server --client_certificate_role).
#ifndef NEURALMESH_SERVER_CLIENT_CERTIFICATE_IDENTITY_H_
#define NEURALMESH_SERVER_CLIENT_CERTIFICATE_IDENTITY_H_

#include <grpcpp/security/auth_metadata_processor.h>

#include "server/access_tokens.h"

namespace neuralmesh::server {

// The processor gRPC runs for every call on a mutual TLS port: it puts the certificate's
// common name (kClientProperty) and `role` (kRoleProperty) into the call's AuthContext, or
// ends the call with UNAUTHENTICATED when the certificate has no common name. Thread-safe.
class ClientCertificateIdentity : public grpc::AuthMetadataProcessor {
 public:
  explicit ClientCertificateIdentity(AccessRole role) : role_(role) {}

  bool IsBlocking() const override { return false; }
  grpc::Status Process(const InputMetadata& auth_metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed_auth_metadata,
                       OutputMetadata* response_metadata) override;

 private:
  const AccessRole role_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_CLIENT_CERTIFICATE_IDENTITY_H_
