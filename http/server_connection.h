// One accepted connection of an HttpServer: bytes in and out over its socket, in the clear or
// through TLS (tls_server_context.h). The socket is non-blocking, and every wait is bounded:
// reads (the TLS handshake included) by one deadline for the whole request, so that a client
// that trickles its bytes is dropped as one that sends none is, and each write by a timeout
// for the client to take more. shutdown(2) of the socket from another thread ends any wait.
#ifndef NEURALMESH_HTTP_SERVER_CONNECTION_H_
#define NEURALMESH_HTTP_SERVER_CONNECTION_H_

#include <cstddef>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "absl/time/time.h"
#include "http/tls_server_context.h"

typedef struct ssl_st SSL;

namespace neuralmesh::http {

class ServerConnection {
 public:
  // `fd` (made non-blocking here) stays the caller's to close, after this object is gone.
  ServerConnection(int fd, absl::Time read_deadline, absl::Duration write_timeout);
  ~ServerConnection();

  ServerConnection(const ServerConnection&) = delete;
  ServerConnection& operator=(const ServerConnection&) = delete;

  // Whether the client's first byte opens a TLS handshake (a TLS record of type 22), without
  // taking it; false also when nothing came before the read deadline.
  bool StartsWithTlsHandshake() const;

  // The server's side of the TLS handshake; from then on Receive and SendAll go through TLS.
  // UNAVAILABLE with the reason when it fails (a client that does not trust the certificate,
  // speaks no TLS, or has not finished by the read deadline).
  absl::Status AcceptTls(const TlsServerContext& context);

  // Whether the client sent, in the handshake of AcceptTls, a certificate that the context's
  // client CAs signed (false without TLS or without client CAs).
  bool client_certificate_verified() const;

  // The common name of that verified certificate's subject (its first, as gRPC takes it);
  // empty without one, or when it has none.
  std::string client_common_name() const;

  // Up to `size` bytes; 0 when the peer closed, the read deadline passed or the connection
  // failed.
  size_t Receive(char* buffer, size_t size);

  // Writes all of `data`; false when the peer went away or took nothing for the write timeout.
  bool SendAll(absl::string_view data);

  // Ends the sending side (after TLS's close_notify), then reads and drops what the client
  // still sends until it closes its side, for at most `linger`: closing with unread bytes (the
  // rest of a refused request) would reset the connection, and the client could lose the
  // answer.
  void EndSending(absl::Duration linger);

 private:
  // Waits until the socket is ready for `events` (POLLIN, POLLOUT) or `until` passes.
  bool Await(short events, absl::Time until) const;
  // After an SSL call that returned `result`: waits for what it wants and says whether to try
  // again (false: it failed, or the wait timed out).
  bool AwaitTls(int result, absl::Time read_until);

  const int fd_;
  const absl::Time read_deadline_;
  const absl::Duration write_timeout_;
  SSL* tls_ = nullptr;
};

}  // namespace neuralmesh::http

#endif  // NEURALMESH_HTTP_SERVER_CONNECTION_H_
