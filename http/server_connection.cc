#include "http/server_connection.h"

#include <openssl/err.h>
#include <openssl/ssl.h>
#include <sys/socket.h>

#include <cerrno>
#include <climits>

#include "absl/strings/str_cat.h"

namespace neuralmesh::http {

ServerConnection::~ServerConnection() {
  if (tls_ != nullptr) SSL_free(tls_);
}

bool ServerConnection::StartsWithTlsHandshake() const {
  unsigned char first = 0;
  ssize_t got;
  do {
    got = recv(fd_, &first, 1, MSG_PEEK);
  } while (got < 0 && errno == EINTR);
  return got == 1 && first == 0x16;
}

absl::Status ServerConnection::AcceptTls(const TlsServerContext& context) {
  ERR_clear_error();
  tls_ = SSL_new(context.get());
  if (tls_ == nullptr || SSL_set_fd(tls_, fd_) != 1) {
    return absl::UnavailableError(TakeOpenSslError("cannot start TLS on the connection"));
  }
  const int accepted = SSL_accept(tls_);
  if (accepted != 1) {
    const int error = SSL_get_error(tls_, accepted);
    std::string reason = TakeOpenSslError(
        error == SSL_ERROR_SYSCALL ? "the client closed or stopped answering" : "failed");
    SSL_free(tls_);
    tls_ = nullptr;  // Nothing more goes through it, not even a close_notify.
    return absl::UnavailableError(absl::StrCat("TLS handshake: ", reason));
  }
  return absl::OkStatus();
}

size_t ServerConnection::Receive(char* buffer, size_t size) {
  if (tls_ != nullptr) {
    ERR_clear_error();
    const int got = SSL_read(tls_, buffer, static_cast<int>(size < INT_MAX ? size : INT_MAX));
    return got > 0 ? static_cast<size_t>(got) : 0;
  }
  while (true) {
    const ssize_t got = recv(fd_, buffer, size, 0);
    if (got < 0 && errno == EINTR) continue;
    return got > 0 ? static_cast<size_t>(got) : 0;
  }
}

bool ServerConnection::SendAll(absl::string_view data) {
  while (!data.empty()) {
    const size_t chunk = data.size() < INT_MAX ? data.size() : INT_MAX;
    if (tls_ != nullptr) {
      ERR_clear_error();
      // Without SSL_MODE_ENABLE_PARTIAL_WRITE a write sends all of its chunk or fails.
      if (SSL_write(tls_, data.data(), static_cast<int>(chunk)) <= 0) return false;
      data.remove_prefix(chunk);
      continue;
    }
    const ssize_t sent = send(fd_, data.data(), chunk, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) return false;
    data.remove_prefix(static_cast<size_t>(sent));
  }
  return true;
}

void ServerConnection::EndSending() {
  if (tls_ != nullptr) {
    ERR_clear_error();
    SSL_shutdown(tls_);  // Our close_notify; the client's is not waited for.
  }
  shutdown(fd_, SHUT_WR);
}

}  // namespace neuralmesh::http
