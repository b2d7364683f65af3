// One accepted connection of an HttpServer: bytes in and out over its socket, in the clear or
// through TLS (tls_server_context.h). The socket's timeouts (SO_RCVTIMEO, SO_SNDTIMEO) bound
// every call, the TLS handshake included; shutdown(2) of the socket from another thread ends
// a call that waits.
#ifndef NEURALMESH_HTTP_SERVER_CONNECTION_H_
#define NEURALMESH_HTTP_SERVER_CONNECTION_H_

#include <cstddef>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "http/tls_server_context.h"

typedef struct ssl_st SSL;

namespace neuralmesh::http {

class ServerConnection {
 public:
  // `fd` stays the caller's to close, after this object is gone.
  explicit ServerConnection(int fd) : fd_(fd) {}
  ~ServerConnection();

  ServerConnection(const ServerConnection&) = delete;
  ServerConnection& operator=(const ServerConnection&) = delete;

  // Whether the client's first byte opens a TLS handshake (a TLS record of type 22), without
  // taking it; false also when nothing came before the timeout.
  bool StartsWithTlsHandshake() const;

  // The server's side of the TLS handshake; from then on Receive and SendAll go through TLS.
  // UNAVAILABLE with OpenSSL's reason when it fails (a client that does not trust the
  // certificate, speaks no TLS, or stops answering).
  absl::Status AcceptTls(const TlsServerContext& context);

  // Up to `size` bytes; 0 when the peer closed, timed out or the connection failed.
  size_t Receive(char* buffer, size_t size);

  // Writes all of `data`; false when the peer went away or stopped reading.
  bool SendAll(absl::string_view data);

  // Ends the sending side (after TLS's close_notify), leaving the receiving side open.
  void EndSending();

 private:
  const int fd_;
  SSL* tls_ = nullptr;
};

}  // namespace neuralmesh::http

#endif  // NEURALMESH_HTTP_SERVER_CONNECTION_H_
