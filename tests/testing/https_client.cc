#include "tests/testing/https_client.h"

#include <arpa/inet.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>
#include <unistd.h>

#include <memory>

namespace neuralmesh::testing {
namespace {

std::string OpenSslReason() {
  std::string reason = "no reason given";
  for (unsigned long code = ERR_get_error(); code != 0; code = ERR_get_error()) {
    char text[256];
    ERR_error_string_n(code, text, sizeof(text));
    reason = text;
  }
  return reason;
}

// Trusts the certificates in `pem`; false when there is none.
bool TrustPem(SSL_CTX* context, const std::string& pem) {
  BIO* bio = BIO_new_mem_buf(pem.data(), static_cast<int>(pem.size()));
  X509_STORE* store = SSL_CTX_get_cert_store(context);
  int trusted = 0;
  while (X509* certificate = PEM_read_bio_X509(bio, nullptr, nullptr, nullptr)) {
    trusted += X509_STORE_add_cert(store, certificate) == 1;
    X509_free(certificate);
  }
  BIO_free(bio);
  ERR_clear_error();
  return trusted > 0;
}

// Presents the certificate of `chain` with `key` when the server asks; false when they do
// not make one.
bool UseClientCertificate(SSL_CTX* context, const std::string& chain, const std::string& key) {
  BIO* chain_bio = BIO_new_mem_buf(chain.data(), static_cast<int>(chain.size()));
  X509* certificate = PEM_read_bio_X509(chain_bio, nullptr, nullptr, nullptr);
  BIO_free(chain_bio);
  BIO* key_bio = BIO_new_mem_buf(key.data(), static_cast<int>(key.size()));
  EVP_PKEY* private_key = PEM_read_bio_PrivateKey(key_bio, nullptr, nullptr, nullptr);
  BIO_free(key_bio);
  const bool used = certificate != nullptr && private_key != nullptr &&
                    SSL_CTX_use_certificate(context, certificate) == 1 &&
                    SSL_CTX_use_PrivateKey(context, private_key) == 1;
  X509_free(certificate);
  EVP_PKEY_free(private_key);
  return used;
}

}  // namespace

HttpReply SendRawHttps(const HttpsTarget& target, const std::string& request, std::string* error) {
  std::string ignored;
  std::string& why = error != nullptr ? *error : ignored;
  ERR_clear_error();
  std::unique_ptr<SSL_CTX, decltype(&SSL_CTX_free)> context(SSL_CTX_new(TLS_client_method()),
                                                            SSL_CTX_free);
  if (!TrustPem(context.get(), target.ca)) {
    why = "no CA certificate to trust";
    return HttpReply();
  }
  SSL_CTX_set_verify(context.get(), SSL_VERIFY_PEER, nullptr);
  if (!target.client_chain.empty() &&
      !UseClientCertificate(context.get(), target.client_chain, target.client_key)) {
    why = "the client certificate and key cannot be used: " + OpenSslReason();
    return HttpReply();
  }
  const int fd = ConnectToLoopback(target.port);
  if (fd < 0) {
    why = "cannot connect";
    return HttpReply();
  }
  std::unique_ptr<SSL, decltype(&SSL_free)> tls(SSL_new(context.get()), SSL_free);
  SSL_set_fd(tls.get(), fd);
  in_addr address{};
  if (inet_pton(AF_INET, target.host.c_str(), &address) == 1) {
    X509_VERIFY_PARAM_set1_ip_asc(SSL_get0_param(tls.get()), target.host.c_str());
  } else {
    SSL_set_tlsext_host_name(tls.get(), target.host.c_str());
    SSL_set1_host(tls.get(), target.host.c_str());
  }
  std::string bytes;
  if (SSL_connect(tls.get()) != 1) {
    why = OpenSslReason();
  } else {
    SSL_write(tls.get(), request.data(), static_cast<int>(request.size()));
    char buffer[65536];
    int got;
    while ((got = SSL_read(tls.get(), buffer, sizeof(buffer))) > 0) bytes.append(buffer, got);
    ERR_clear_error();
  }
  tls.reset();
  close(fd);
  return ParseHttpReply(bytes);
}

HttpReply HttpsGet(const HttpsTarget& target, const std::string& path, const std::string& bearer,
                   std::string* error) {
  std::string request = "GET " + path + " HTTP/1.1\r\nHost: " + target.host + "\r\n";
  if (!bearer.empty()) request += "Authorization: Bearer " + bearer + "\r\n";
  return SendRawHttps(target, request + "\r\n", error);
}

}  // namespace neuralmesh::testing
