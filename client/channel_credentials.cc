#include "client/channel_credentials.h"

#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace neuralmesh::client {
namespace {

absl::Status CheckPem(const std::string& pem, const char* what) {
  if (pem.empty() || absl::StrContains(pem, "-----BEGIN ")) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("the TLS ", what, " is not PEM text (no '-----BEGIN ' line)"));
}

}  // namespace

absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> MakeChannelCredentials(
    const ClientSecurity& security) {
  const ClientTls& tls = security.tls;
  if (!tls.enabled) {
    if (!security.access_token.empty()) {
      return absl::InvalidArgumentError(
          "an access token needs TLS: without it the token would cross the network in the "
          "clear");
    }
    if (!tls.root_certificates.empty() || !tls.certificate_chain.empty() ||
        !tls.private_key.empty() || !tls.server_name.empty()) {
      return absl::InvalidArgumentError(
          "TLS certificates, keys or a server name were given without TLS");
    }
    return grpc::InsecureChannelCredentials();
  }
  if (tls.certificate_chain.empty() != tls.private_key.empty()) {
    return absl::InvalidArgumentError(
        "a client certificate needs its private key and a private key its certificate");
  }
  if (absl::Status s = CheckPem(tls.root_certificates, "CA certificates"); !s.ok()) return s;
  if (absl::Status s = CheckPem(tls.certificate_chain, "client certificate"); !s.ok()) return s;
  if (absl::Status s = CheckPem(tls.private_key, "client private key"); !s.ok()) return s;
  grpc::SslCredentialsOptions options;
  options.pem_root_certs = tls.root_certificates;
  options.pem_cert_chain = tls.certificate_chain;
  options.pem_private_key = tls.private_key;
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::SslCredentials(options);
  if (security.access_token.empty()) return credentials;
  for (const char c : security.access_token) {
    if (c <= ' ' || c > '~') {
      return absl::InvalidArgumentError(
          "the access token may hold printable ASCII characters only, no spaces");
    }
  }
  return grpc::CompositeChannelCredentials(credentials,
                                           grpc::AccessTokenCredentials(security.access_token));
}

}  // namespace neuralmesh::client
