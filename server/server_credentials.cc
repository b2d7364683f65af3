#include "server/server_credentials.h"

#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/access_tokens.h"
#include "server/client_certificate_identity.h"

namespace neuralmesh::server {

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
    PortCredentials plaintext;
    plaintext.credentials = grpc::InsecureServerCredentials();
    return plaintext;
  }
  if (security.names_clients_by_certificate()) {
    if (tls.client_ca_certificates.empty()) {
      return absl::InvalidArgumentError(
          "client certificate roles need mutual TLS (client CAs): without it clients present "
          "no certificate");
    }
    if (!security.access_tokens.empty()) {
      return absl::InvalidArgumentError(
          "client certificate roles and access tokens do not go together: with tokens, each "
          "token names its client and role");
    }
  }
  absl::StatusOr<std::unique_ptr<ServerTlsIdentity>> identity = ServerTlsIdentity::Create(tls);
  if (!identity.ok()) return identity.status();
  PortCredentials port;
  port.tls_identity = *std::move(identity);
  port.credentials = port.tls_identity->credentials();
  if (!security.access_tokens.empty()) {
    absl::StatusOr<std::shared_ptr<AccessTokenChecker>> checker =
        AccessTokenChecker::Create(security.access_tokens);
    if (!checker.ok()) return checker.status();
    port.token_checker = *std::move(checker);
    port.credentials->SetAuthMetadataProcessor(port.token_checker);
  } else if (security.names_clients_by_certificate()) {
    port.certificate_identity = std::make_shared<ClientCertificateIdentity>(
        security.client_roles, security.client_certificate_role);
    port.credentials->SetAuthMetadataProcessor(port.certificate_identity);
  }
  return port;
}

}  // namespace neuralmesh::server
