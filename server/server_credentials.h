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
#include "server/client_certificate_identity.h"
#include "server/tls_identity.h"

namespace neuralmesh::server {

struct ServerSecurity {
  ServerTls tls;
  // Set: every call but the health service's must carry one of these tokens (needs TLS).
  std::vector<AccessToken> access_tokens;
  // Under mutual TLS without tokens (client_certificate_identity.h): the common name of a
  // client's certificate names its client, whose role is its own in `client_roles`, else
  // `client_certificate_role`; a client that neither gives a role is refused. Both empty:
  // every client is an unnamed admin.
  ClientRoles client_roles;
  std::optional<AccessRole> client_certificate_role;

  bool names_clients_by_certificate() const {
    return !client_roles.empty() || client_certificate_role.has_value();
  }
};

struct PortCredentials {
  std::shared_ptr<grpc::ServerCredentials> credentials;
  std::shared_ptr<AccessTokenChecker> token_checker;  // Null without access tokens.
  // Null unless clients are named by their certificates.
  std::shared_ptr<ClientCertificateIdentity> certificate_identity;
  // Null for plaintext. `credentials` must not outlive it.
  std::shared_ptr<ServerTlsIdentity> tls_identity;
};

// The credentials of the listening port. INVALID_ARGUMENT when the parts do not go together
// (a key without a certificate, a client CA or tokens without TLS, a bad token), or gRPC does
// not take the certificate and key (CheckServerTls).
absl::StatusOr<PortCredentials> MakeServerCredentials(const ServerSecurity& security);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SERVER_CREDENTIALS_H_
