#include "http/tls_server_context.h"

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include <memory>

#include "absl/strings/str_cat.h"

namespace neuralmesh::http {
namespace {

struct BioFree {
  void operator()(BIO* bio) const { BIO_free(bio); }
};
struct X509Free {
  void operator()(X509* certificate) const { X509_free(certificate); }
};
struct KeyFree {
  void operator()(EVP_PKEY* key) const { EVP_PKEY_free(key); }
};
struct ContextFree {
  void operator()(SSL_CTX* context) const { SSL_CTX_free(context); }
};

std::unique_ptr<BIO, BioFree> ReadOnlyBio(absl::string_view text) {
  return std::unique_ptr<BIO, BioFree>(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
}

}  // namespace

std::string TakeOpenSslError(absl::string_view fallback) {
  std::string reason(fallback);
  // The last error is the one closest to the failing call; earlier ones are its causes.
  for (unsigned long code = ERR_get_error(); code != 0; code = ERR_get_error()) {
    char text[256];
    ERR_error_string_n(code, text, sizeof(text));
    reason = text;
  }
  return reason;
}

namespace {

// Makes `context` ask clients for a certificate and verify one that is sent against the CAs
// of `pem`, which it names to clients as those it takes.
absl::Status AskClientCertificates(SSL_CTX* context, absl::string_view pem) {
  if (pem.find("-----BEGIN CERTIFICATE-----") == absl::string_view::npos) {
    return absl::InvalidArgumentError("the client CA file holds no PEM certificate");
  }
  X509_STORE* store = SSL_CTX_get_cert_store(context);
  STACK_OF(X509_NAME)* names = sk_X509_NAME_new_null();
  std::unique_ptr<BIO, BioFree> bio = ReadOnlyBio(pem);
  int count = 0;
  while (true) {
    std::unique_ptr<X509, X509Free> ca(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
    if (ca == nullptr) break;
    ++count;
    X509_NAME* name = X509_NAME_dup(X509_get_subject_name(ca.get()));
    if (X509_STORE_add_cert(store, ca.get()) != 1 || name == nullptr ||
        sk_X509_NAME_push(names, name) == 0) {
      X509_NAME_free(name);
      sk_X509_NAME_pop_free(names, X509_NAME_free);
      return absl::InvalidArgumentError(absl::StrCat("client CA certificate ", count,
                                                     " cannot be used: ",
                                                     TakeOpenSslError("refused")));
    }
  }
  ERR_clear_error();  // The end of the file reads as "no start line".
  if (count == 0) {
    sk_X509_NAME_pop_free(names, X509_NAME_free);
    return absl::InvalidArgumentError("the client CA certificates cannot be read");
  }
  SSL_CTX_set_client_CA_list(context, names);  // Takes `names`.
  SSL_CTX_set_verify(context, SSL_VERIFY_PEER, nullptr);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::shared_ptr<const TlsServerContext>> TlsServerContext::Create(
    absl::string_view certificate_chain, absl::string_view private_key,
    absl::string_view client_ca_certificates) {
  ERR_clear_error();
  if (certificate_chain.find("-----BEGIN CERTIFICATE-----") == absl::string_view::npos) {
    return absl::InvalidArgumentError("the TLS certificate file holds no PEM certificate");
  }
  if (private_key.find("PRIVATE KEY-----") == absl::string_view::npos) {
    return absl::InvalidArgumentError("the TLS key file holds no PEM private key");
  }
  std::unique_ptr<SSL_CTX, ContextFree> context(SSL_CTX_new(TLS_server_method()));
  if (context == nullptr) {
    return absl::InternalError(TakeOpenSslError("cannot make an OpenSSL context"));
  }
  SSL_CTX_set_min_proto_version(context.get(), TLS1_2_VERSION);
  SSL_CTX_set_options(context.get(), SSL_OP_NO_RENEGOTIATION);
  SSL_CTX_set_session_cache_mode(context.get(), SSL_SESS_CACHE_OFF);

  std::unique_ptr<BIO, BioFree> chain = ReadOnlyBio(certificate_chain);
  std::unique_ptr<X509, X509Free> leaf(PEM_read_bio_X509(chain.get(), nullptr, nullptr, nullptr));
  if (leaf == nullptr || SSL_CTX_use_certificate(context.get(), leaf.get()) != 1) {
    return absl::InvalidArgumentError(absl::StrCat("the TLS certificate cannot be read: ",
                                                   TakeOpenSslError("not a PEM certificate")));
  }
  while (true) {
    std::unique_ptr<X509, X509Free> intermediate(
        PEM_read_bio_X509(chain.get(), nullptr, nullptr, nullptr));
    if (intermediate == nullptr) break;
    if (SSL_CTX_add1_chain_cert(context.get(), intermediate.get()) != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("an intermediate certificate after the first cannot be used: ",
                       TakeOpenSslError("refused")));
    }
  }
  ERR_clear_error();  // The end of the chain reads as "no start line".

  std::unique_ptr<BIO, BioFree> key_text = ReadOnlyBio(private_key);
  std::unique_ptr<EVP_PKEY, KeyFree> key(
      PEM_read_bio_PrivateKey(key_text.get(), nullptr, nullptr, nullptr));
  if (key == nullptr) {
    return absl::InvalidArgumentError(absl::StrCat("the TLS private key cannot be read: ",
                                                   TakeOpenSslError("not a PEM private key")));
  }
  if (SSL_CTX_use_PrivateKey(context.get(), key.get()) != 1 ||
      SSL_CTX_check_private_key(context.get()) != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("the TLS private key does not belong to the certificate: ",
                     TakeOpenSslError("they do not match")));
  }
  if (!client_ca_certificates.empty()) {
    const absl::Status asked = AskClientCertificates(context.get(), client_ca_certificates);
    if (!asked.ok()) return asked;
  }
  return std::shared_ptr<const TlsServerContext>(new TlsServerContext(context.release()));
}

TlsServerContext::~TlsServerContext() { SSL_CTX_free(context_); }

}  // namespace neuralmesh::http
