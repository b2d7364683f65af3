// The TLS side of an HttpServer that speaks HTTPS: an OpenSSL server context made from a
// certificate chain and its private key (PEM text), shared by the connections that start while
// it is the server's (HttpServer::ReplaceTls swaps it for new ones).
//
// TLS 1.2 and 1.3, OpenSSL's default ciphers; no client certificates are asked for.
#ifndef NEURALMESH_HTTP_TLS_SERVER_CONTEXT_H_
#define NEURALMESH_HTTP_TLS_SERVER_CONTEXT_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

typedef struct ssl_ctx_st SSL_CTX;

namespace neuralmesh::http {

class TlsServerContext {
 public:
  // From PEM text: `certificate_chain` holds the server's certificate, then any intermediates;
  // `private_key` is the certificate's key. With `client_ca_certificates` (PEM, one or more
  // CAs) the handshake asks the client for a certificate and fails when one is sent that
  // those CAs did not sign; a client may still send none (ServerConnection::
  // client_certificate_verified says which, so that pages for probes can stay open).
  // INVALID_ARGUMENT saying which part is wrong (no certificate, not PEM, a key that does not
  // belong to the certificate, client CAs that are not PEM certificates) with OpenSSL's
  // reason.
  static absl::StatusOr<std::shared_ptr<const TlsServerContext>> Create(
      absl::string_view certificate_chain, absl::string_view private_key,
      absl::string_view client_ca_certificates = {});
  ~TlsServerContext();

  TlsServerContext(const TlsServerContext&) = delete;
  TlsServerContext& operator=(const TlsServerContext&) = delete;

  // For SSL_new; thread-safe to share.
  SSL_CTX* get() const { return context_; }

 private:
  explicit TlsServerContext(SSL_CTX* context) : context_(context) {}

  SSL_CTX* const context_;
};

// The reason OpenSSL gave for its latest failure on this thread (its error queue, emptied),
// or `fallback` when it gave none.
std::string TakeOpenSslError(absl::string_view fallback);

}  // namespace neuralmesh::http

#endif  // NEURALMESH_HTTP_TLS_SERVER_CONTEXT_H_
