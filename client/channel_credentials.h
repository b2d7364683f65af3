// How the client's channel to neuralmesh-server is secured: plaintext, TLS (server
// certificate checked against the system's CAs or given ones), mutual TLS (a client
// certificate too), and an access token sent with every call (server/access_tokens.h).
#ifndef NEURALMESH_CLIENT_CHANNEL_CREDENTIALS_H_
#define NEURALMESH_CLIENT_CHANNEL_CREDENTIALS_H_

#include <grpcpp/security/credentials.h>

#include <memory>
#include <string>

#include "absl/status/statusor.h"

namespace neuralmesh::client {

// PEM text (file contents, not paths).
struct ClientTls {
  bool enabled = false;
  // The CAs that may sign the server's certificate; empty: the system's (gRPC's roots).
  std::string root_certificates;
  // The client's certificate and key, for servers that ask for one (mutual TLS).
  std::string certificate_chain;
  std::string private_key;
  // The name the server's certificate must carry, when it is not the host dialled (a tunnel
  // or port forward to 127.0.0.1); empty: the host of the address.
  std::string server_name;
};

struct ClientSecurity {
  ClientTls tls;
  // Sent as "authorization: Bearer TOKEN" with every call; needs TLS.
  std::string access_token;
};

// The channel credentials. INVALID_ARGUMENT when the parts do not go together (a token, PEM
// text or a server name without TLS, a certificate without its key or the reverse) or a PEM
// text is not PEM. The server name is a channel argument: ReconstructionClient::Connect sets
// it.
absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> MakeChannelCredentials(
    const ClientSecurity& security);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_CHANNEL_CREDENTIALS_H_
