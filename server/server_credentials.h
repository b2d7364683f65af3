// How neuralmesh-server's port is secured: plaintext, TLS, or mutual TLS, and optionally
// bearer tokens on top of TLS (access_tokens.h).
#ifndef NEURALMESH_SERVER_SERVER_CREDENTIALS_H_
#define NEURALMESH_SERVER_SERVER_CREDENTIALS_H_

#include <grpcpp/security/server_credentials.h>

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/access_tokens.h"

namespace neuralmesh::server {

// PEM text (the contents of the files, not their paths). All empty: plaintext.
struct ServerTls {
  std::string certificate_chain;  // The server's certificate, then any intermediates.
  std::string private_key;        // The certificate's key.
  // Set: mutual TLS. Clients must present a certificate signed by one of these CAs, or the
  // handshake fails.
  std::string client_ca_certificates;

  bool enabled() const { return !certificate_chain.empty(); }
};

struct ServerSecurity {
  ServerTls tls;
  // Set: every call but the health service's must carry one of these tokens (needs TLS).
  std::vector<AccessToken> access_tokens;
};

struct PortCredentials {
  std::shared_ptr<grpc::ServerCredentials> credentials;
  std::shared_ptr<AccessTokenChecker> token_checker;  // Null without access tokens.
};

// The credentials of the listening port. INVALID_ARGUMENT when the parts do not go together
// (a key without a certificate, a client CA or tokens without TLS, a bad token) or a PEM text
// does not look like one. gRPC itself parses the certificate and key when the port is bound.
absl::StatusOr<PortCredentials> MakeServerCredentials(const ServerSecurity& security);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SERVER_CREDENTIALS_H_
