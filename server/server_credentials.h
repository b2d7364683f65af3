// How neuralmesh-server's port is secured: plaintext, TLS, or mutual TLS, and optionally
// bearer tokens on top of TLS (access_tokens.h).
#ifndef NEURALMESH_SERVER_SERVER_CREDENTIALS_H_
#define NEURALMESH_SERVER_SERVER_CREDENTIALS_H_

#include <grpcpp/security/server_credentials.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/access_tokens.h"
#include "server/tls_identity.h"

namespace neuralmesh::server {

struct ServerSecurity {
  ServerTls tls;
  // Set: every call but the health service's must carry one of these tokens (needs TLS).
  std::vector<AccessToken> access_tokens;
  // Set, under mutual TLS without tokens: the common name of a client's certificate names its
  // client, with this role (client_certificate_identity.h). Unset: every client is an admin.
  std::optional<AccessRole> client_certificate_role;
};

struct PortCredentials {
  std::shared_ptr<grpc::ServerCredentials> credentials;
  std::shared_ptr<AccessTokenChecker> token_checker;  // Null without access tokens.
  // Null for plaintext. `credentials` must not outlive it.
  std::shared_ptr<ServerTlsIdentity> tls_identity;
};

// The credentials of the listening port. INVALID_ARGUMENT when the parts do not go together
// (a key without a certificate, a client CA or tokens without TLS, a bad token), or gRPC does
// not take the certificate and key (CheckServerTls).
absl::StatusOr<PortCredentials> MakeServerCredentials(const ServerSecurity& security);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SERVER_CREDENTIALS_H_
