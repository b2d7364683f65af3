#include "http/server_connection.h"

#include <fcntl.h>
#include <openssl/err.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"

namespace neuralmesh::http {

ServerConnection::ServerConnection(int fd, absl::Time read_deadline,
                                   absl::Duration write_timeout)
    : fd_(fd), read_deadline_(read_deadline), write_timeout_(write_timeout) {
  const int flags = fcntl(fd_, F_GETFL);
  if (flags >= 0) fcntl(fd_, F_SETFL, flags | O_NONBLOCK);
}

ServerConnection::~ServerConnection() {
  if (tls_ != nullptr) SSL_free(tls_);
}

bool ServerConnection::Await(short events, absl::Time until) const {
  while (true) {
    const absl::Duration left = until - absl::Now();
    if (left <= absl::ZeroDuration()) return false;
    pollfd ready{fd_, events, 0};
    const int64_t ms = std::min<int64_t>(absl::ToInt64Milliseconds(left) + 1, INT_MAX);
    const int polled = poll(&ready, 1, static_cast<int>(ms));
    if (polled > 0) return true;  // Ready, or an error or hang-up that the next call reports.
    if (polled < 0 && errno != EINTR) return false;
  }
}

bool ServerConnection::AwaitTls(int result, absl::Time read_until) {
  switch (SSL_get_error(tls_, result)) {
    case SSL_ERROR_WANT_READ:
      return Await(POLLIN, read_until);
    case SSL_ERROR_WANT_WRITE:
      return Await(POLLOUT, absl::Now() + write_timeout_);
    default:
      return false;
  }
}

bool ServerConnection::StartsWithTlsHandshake() const {
  unsigned char first = 0;
  while (true) {
    const ssize_t got = recv(fd_, &first, 1, MSG_PEEK);
    if (got == 1) return first == 0x16;
    if (got < 0 && errno == EINTR) continue;
    if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK) && Await(POLLIN, read_deadline_)) {
      continue;
    }
    return false;
  }
}

bool ServerConnection::client_certificate_verified() const {
  if (tls_ == nullptr) return false;
  X509* certificate = SSL_get1_peer_certificate(tls_);
  if (certificate == nullptr) return false;
  X509_free(certificate);
  return SSL_get_verify_result(tls_) == X509_V_OK;
}

std::string ServerConnection::client_common_name() const {
  if (tls_ == nullptr) return "";
  X509* certificate = SSL_get1_peer_certificate(tls_);
  if (certificate == nullptr) return "";
  std::string name;
  const X509_NAME* subject = X509_get_subject_name(certificate);
  const int at = SSL_get_verify_result(tls_) == X509_V_OK
                     ? X509_NAME_get_index_by_NID(subject, NID_commonName, -1)
                     : -1;
  if (at >= 0) {
    const ASN1_STRING* text = X509_NAME_ENTRY_get_data(X509_NAME_get_entry(subject, at));
    unsigned char* utf8 = nullptr;
    const int length = ASN1_STRING_to_UTF8(&utf8, text);
    if (length > 0) name.assign(reinterpret_cast<const char*>(utf8), length);
    OPENSSL_free(utf8);
  }
  X509_free(certificate);
  return name;
}

absl::Status ServerConnection::AcceptTls(const TlsServerContext& context) {
  ERR_clear_error();
  tls_ = SSL_new(context.get());
  if (tls_ == nullptr || SSL_set_fd(tls_, fd_) != 1) {
    return absl::UnavailableError(TakeOpenSslError("cannot start TLS on the connection"));
  }
  while (true) {
    const int accepted = SSL_accept(tls_);
    if (accepted == 1) return absl::OkStatus();
    if (!AwaitTls(accepted, read_deadline_)) break;
  }
  std::string reason = TakeOpenSslError("the client closed, stopped answering or took too long");
  SSL_free(tls_);
  tls_ = nullptr;  // Nothing more goes through it, not even a close_notify.
  return absl::UnavailableError(absl::StrCat("TLS handshake: ", reason));
}

size_t ServerConnection::Receive(char* buffer, size_t size) {
  const int chunk = static_cast<int>(std::min<size_t>(size, INT_MAX));
  while (true) {
    if (tls_ != nullptr) {
      ERR_clear_error();
      const int got = SSL_read(tls_, buffer, chunk);
      if (got > 0) return static_cast<size_t>(got);
      if (!AwaitTls(got, read_deadline_)) return 0;
      continue;
    }
    const ssize_t got = recv(fd_, buffer, static_cast<size_t>(chunk), 0);
    if (got > 0) return static_cast<size_t>(got);
    if (got == 0) return 0;
    if (errno == EINTR) continue;
    if ((errno != EAGAIN && errno != EWOULDBLOCK) || !Await(POLLIN, read_deadline_)) return 0;
  }
}

bool ServerConnection::SendAll(absl::string_view data) {
  while (!data.empty()) {
    const int chunk = static_cast<int>(std::min<size_t>(data.size(), INT_MAX));
    if (tls_ != nullptr) {
      ERR_clear_error();
      // Without SSL_MODE_ENABLE_PARTIAL_WRITE a write sends all of its chunk or none; one that
      // must wait is called again with the same arguments.
      const int sent = SSL_write(tls_, data.data(), chunk);
      if (sent > 0) {
        data.remove_prefix(static_cast<size_t>(sent));
      } else if (!AwaitTls(sent, absl::Now() + write_timeout_)) {
        return false;
      }
      continue;
    }
    const ssize_t sent = send(fd_, data.data(), static_cast<size_t>(chunk), MSG_NOSIGNAL);
    if (sent > 0) {
      data.remove_prefix(static_cast<size_t>(sent));
    } else if (sent < 0 && errno == EINTR) {
      continue;
    } else if (sent == 0 || (errno != EAGAIN && errno != EWOULDBLOCK) ||
               !Await(POLLOUT, absl::Now() + write_timeout_)) {
      return false;
    }
  }
  return true;
}

void ServerConnection::EndSending(absl::Duration linger) {
  if (tls_ != nullptr) {
    ERR_clear_error();
    SSL_shutdown(tls_);  // Our close_notify (unsent if the socket is full); not the client's.
  }
  shutdown(fd_, SHUT_WR);
  const absl::Time until = absl::Now() + linger;
  char discard[4096];
  for (size_t drained = 0; drained < (size_t{1} << 20);) {
    const ssize_t got = recv(fd_, discard, sizeof(discard), 0);
    if (got > 0) {
      drained += static_cast<size_t>(got);
    } else if (got == 0 || (errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK) ||
               !Await(POLLIN, until)) {
      break;
    }
  }
}

}  // namespace neuralmesh::http
