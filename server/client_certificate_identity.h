// Under mutual TLS without access tokens: the client of a call is the common name of the
// certificate it presented, so that sessions belong to the client that created them
// (session_access.h). Its role comes from the client roles file (neuralmesh-server
// --client_roles_file: one "COMMON_NAME ROLE" a line), and for common names not in it from
// --client_certificate_role; a certificate that neither gives a role is refused.
#ifndef NEURALMESH_SERVER_CLIENT_CERTIFICATE_IDENTITY_H_
#define NEURALMESH_SERVER_CLIENT_CERTIFICATE_IDENTITY_H_

#include <functional>
#include <map>
#include <optional>
#include <string>

#include <grpcpp/security/auth_metadata_processor.h>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"
#include "server/access_tokens.h"

namespace neuralmesh::server {

// Roles by certificate common name.
using ClientRoles = std::map<std::string, AccessRole, std::less<>>;

// A client roles file: one client a line, its common name then its role (admin, user or
// reader), the role last so that a common name may hold spaces; blank lines and lines that
// start with '#' are skipped. INVALID_ARGUMENT naming the line for a line without both, an
// unknown role or a common name listed twice, and for a file without any client.
absl::StatusOr<ClientRoles> ParseClientRoles(absl::string_view text);

// The processor gRPC runs for every call on a mutual TLS port: it puts the certificate's
// common name (kClientProperty) and its role (kRoleProperty) into the call's AuthContext; ends
// the call with UNAUTHENTICATED when the certificate has no common name, PERMISSION_DENIED
// when the common name has no role. Thread-safe.
class ClientCertificateIdentity : public grpc::AuthMetadataProcessor {
 public:
  // `roles` by common name; `others` for every other common name (none: refused).
  ClientCertificateIdentity(ClientRoles roles, std::optional<AccessRole> others)
      : roles_(std::move(roles)), others_(others) {}

  // Replaces the roles by common name for calls that start from now on (SIGHUP).
  void ReplaceRoles(ClientRoles roles) ABSL_LOCKS_EXCLUDED(mu_);

  // The role of a certificate with this common name; none when it has none (refused).
  std::optional<AccessRole> RoleOf(absl::string_view common_name) const ABSL_LOCKS_EXCLUDED(mu_);

  bool IsBlocking() const override { return false; }
  grpc::Status Process(const InputMetadata& auth_metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed_auth_metadata,
                       OutputMetadata* response_metadata) override ABSL_LOCKS_EXCLUDED(mu_);

 private:
  mutable absl::Mutex mu_;
  ClientRoles roles_ ABSL_GUARDED_BY(mu_);
  const std::optional<AccessRole> others_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_CLIENT_CERTIFICATE_IDENTITY_H_
