// A small HTTP/1.1 server for the live viewer and the server's metrics, in the clear or over
// TLS (HTTPS): one thread accepts, one thread per connection reads a request head, calls the
// handler and writes its response, then closes the connection (browsers and scrapers open a new
// one per request, which on their few requests costs nothing).
//
//   NM_ASSIGN_OR_RETURN(std::unique_ptr<HttpServer> server,
//                       HttpServer::Start("127.0.0.1", 8080, handler));
//   ... server->port() ...
//   server->Shutdown();  // Or the destructor.
//
// Bad requests get 400 with a message, oversized heads 431, methods other than GET and HEAD
// 405, and connections beyond `max_connections` 503 (closed without an answer under TLS); a
// client that has not sent its whole request head `read_timeout` after connecting is dropped,
// however it trickles its bytes. Under TLS, a client that speaks plain HTTP gets 400 in plain
// HTTP saying that the port speaks HTTPS, and a failed handshake closes the connection. The
// handler runs on the connection's thread and may block (a long poll), so it must return once
// its owner is shut down: Shutdown() closes the sockets but waits for handlers in flight.
#ifndef NEURALMESH_HTTP_HTTP_SERVER_H_
#define NEURALMESH_HTTP_HTTP_SERVER_H_

#include <functional>
#include <memory>
#include <set>
#include <string>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "http/http_message.h"
#include "http/tls_server_context.h"

namespace neuralmesh::http {

struct HttpServerOptions {
  // Connections served at once; one more is answered 503 and closed.
  int max_connections = 64;
  // How long a connection may take, from its accept, to send its whole request head (the TLS
  // handshake included).
  absl::Duration read_timeout = absl::Seconds(10);
  // Set: HTTPS with this certificate and key (HttpServer::ReplaceTls changes them). Null: HTTP.
  std::shared_ptr<const TlsServerContext> tls;
};

using HttpHandler = std::function<HttpResponse(const HttpRequest&)>;

class HttpServer {
 public:
  // Listens on `host` ("127.0.0.1", "::1", "0.0.0.0", "localhost") and `port` (0: a free one).
  // INVALID_ARGUMENT for a host that does not resolve or a port outside [0, 65535];
  // UNAVAILABLE when the address cannot be bound (in use, not local), naming it.
  static absl::StatusOr<std::unique_ptr<HttpServer>> Start(const std::string& host, int port,
                                                           HttpHandler handler,
                                                           const HttpServerOptions& options = {});
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // The port listened on.
  int port() const { return port_; }

  // "https" when started with TLS, else "http".
  const char* scheme() const { return speaks_tls_ ? "https" : "http"; }

  // The certificate and key of the handshakes that start from now on (a renewed certificate);
  // connections already open go on. FAILED_PRECONDITION for a server started without TLS, and
  // INVALID_ARGUMENT for a null context.
  absl::Status ReplaceTls(std::shared_ptr<const TlsServerContext> tls) ABSL_LOCKS_EXCLUDED(mu_);

  // Stops listening, shuts down every open connection and waits until their threads, handlers
  // included, have returned. Idempotent.
  void Shutdown();

 private:
  HttpServer(int listen_fd, int wake_fd, int port, HttpHandler handler,
             const HttpServerOptions& options);

  void AcceptLoop();
  void Serve(int fd, absl::Time read_deadline);

  const int listen_fd_;  // Closed by Shutdown.
  const int wake_fd_;    // An eventfd that wakes the accept loop for Shutdown.
  const int port_;
  const bool speaks_tls_;
  const HttpHandler handler_;
  const HttpServerOptions options_;
  std::thread accept_thread_;

  absl::Mutex mu_;
  std::set<int> open_fds_ ABSL_GUARDED_BY(mu_);  // Connections whose thread still runs.
  std::shared_ptr<const TlsServerContext> tls_ ABSL_GUARDED_BY(mu_);
  bool shut_down_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace neuralmesh::http

#endif  // NEURALMESH_HTTP_HTTP_SERVER_H_
