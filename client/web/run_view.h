// `neuralmesh view`: serves the live viewer of one neuralmesh-server's sessions over HTTP or
// HTTPS (client/web/viewer_service.h) until SIGINT or SIGTERM.
#ifndef NEURALMESH_CLIENT_WEB_RUN_VIEW_H_
#define NEURALMESH_CLIENT_WEB_RUN_VIEW_H_

#include <functional>
#include <ostream>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/reconstruction_client.h"

namespace neuralmesh::client::web {

struct ViewOptions {
  std::string server;                     // The neuralmesh-server, HOST:PORT.
  std::string listen = "127.0.0.1:8080";  // Where browsers connect, HOST:PORT (port 0: any).
  std::string web_root;                   // Empty: the source tree's client/web.
  ClientOptions connection;                // Connect timeout, TLS, access token.
  std::string key;  // Empty: every browser is let in; else the key it must bring (viewer_key.h).
  // PEM text. Set: browsers connect over HTTPS with this certificate (and intermediates) and
  // its key. Empty: plain HTTP.
  std::string tls_certificate_chain;
  std::string tls_private_key;
  // With HTTPS: called on SIGHUP for the certificate chain and key read again (from their
  // files), PEM text as above. Null: SIGHUP changes nothing.
  struct TlsPem {
    std::string certificate_chain;
    std::string private_key;
  };
  std::function<absl::StatusOr<TlsPem>()> reread_tls;
  // With a key: called on SIGHUP for the key read again (from its file, checked by
  // ParseViewerKey). Null: SIGHUP keeps the key.
  std::function<absl::StatusOr<std::string>()> reread_key;
};

// The client/web folder of the source tree this binary was built from.
std::string DefaultWebRoot();

// Checks the web root, connects to the server, listens, prints
// "viewer: http://HOST:PORT/ (sessions of SERVER)" (https:// with a certificate) and serves
// until interrupted. On SIGHUP an HTTPS viewer takes the certificate and key of
// `reread_tls` for the connections that follow (a renewed certificate, without a restart),
// and a keyed viewer the key of `reread_key` for the requests that follow (browsers holding
// the old key's cookie are let in no more), saying so on `out`; a certificate and key that
// do not make a TLS identity, or a key file that does not hold a key, leave the old ones in
// place, and `err` says why. Errors: NOT_FOUND for a web root without the viewer's files,
// INVALID_ARGUMENT for a malformed --listen or a certificate and key that do not make a TLS
// identity (one without the other included), UNAVAILABLE when the server cannot be reached or
// the address cannot be bound, UNAUTHENTICATED when the server refuses the viewer's access
// token (or its lack of one). A --listen address that is not a loopback one gets a warning on
// `err` without a key (anyone gets in), and with a key over plain HTTP (it crosses the network
// in the clear).
absl::Status RunView(const ViewOptions& options, std::ostream& out, std::ostream& err);

}  // namespace neuralmesh::client::web

#endif  // NEURALMESH_CLIENT_WEB_RUN_VIEW_H_
