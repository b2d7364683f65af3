#include "server/server_credentials.h"

#include <utility>

#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/access_tokens.h"

namespace neuralmesh::server {
namespace {

absl::Status CheckPem(const std::string& pem, const char* what) {
  if (absl::StrContains(pem, "-----BEGIN ")) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("the TLS ", what, " is not PEM text (no '-----BEGIN ' line)"));
}

}  // namespace

absl::StatusOr<PortCredentials> MakeServerCredentials(const ServerSecurity& security) {
  const ServerTls& tls = security.tls;
  if (!tls.enabled()) {
    if (!tls.private_key.empty() || !tls.client_ca_certificates.empty()) {
      return absl::InvalidArgumentError(
          "a TLS private key or client CA was given without a server certificate");
    }
    if (!security.access_tokens.empty()) {
      return absl::InvalidArgumentError(
          "access tokens need TLS: without it they would cross the network in the clear");
    }
    return PortCredentials{grpc::InsecureServerCredentials(), nullptr};
  }
  if (tls.private_key.empty()) {
    return absl::InvalidArgumentError("the TLS certificate was given without its private key");
  }
  if (absl::Status s = CheckPem(tls.certificate_chain, "certificate"); !s.ok()) return s;
  if (absl::Status s = CheckPem(tls.private_key, "private key"); !s.ok()) return s;
  grpc::SslServerCredentialsOptions options;
  options.pem_key_cert_pairs.push_back({tls.private_key, tls.certificate_chain});
  if (!tls.client_ca_certificates.empty()) {
    if (absl::Status s = CheckPem(tls.client_ca_certificates, "client CA"); !s.ok()) return s;
    options.pem_root_certs = tls.client_ca_certificates;
    options.client_certificate_request =
        GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  PortCredentials port{grpc::SslServerCredentials(options), nullptr};
  if (!security.access_tokens.empty()) {
    absl::StatusOr<std::shared_ptr<AccessTokenChecker>> checker =
        AccessTokenChecker::Create(security.access_tokens);
    if (!checker.ok()) return checker.status();
    port.token_checker = *std::move(checker);
    port.credentials->SetAuthMetadataProcessor(port.token_checker);
  }
  return port;
}

}  // namespace neuralmesh::server
