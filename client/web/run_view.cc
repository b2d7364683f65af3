#include "client/web/run_view.h"

#include <memory>
#include <string_view>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "client/interrupt.h"
#include "client/reconstruction_client.h"
#include "client/reload_signal.h"
#include "client/web/viewer_service.h"
#include "core/status_macros.h"
#include "http/http_server.h"

namespace neuralmesh::client::web {

using ::neuralmesh::http::HttpRequest;
using ::neuralmesh::http::HttpServer;
using ::neuralmesh::http::HttpServerOptions;
using ::neuralmesh::http::TlsServerContext;

namespace {

struct HostPort {
  std::string host;
  int port = 0;
};

// "HOST:PORT" or "[IPV6]:PORT".
absl::StatusOr<HostPort> ParseListenAddress(const std::string& address) {
  const size_t colon = address.rfind(':');
  HostPort parsed;
  if (colon == std::string::npos || colon == 0 ||
      !absl::SimpleAtoi(address.substr(colon + 1), &parsed.port) || parsed.port < 0 ||
      parsed.port > 65535) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--listen=", address, " is not HOST:PORT (for example 127.0.0.1:8080; port 0: any)"));
  }
  parsed.host = address.substr(0, colon);
  if (parsed.host.size() >= 2 && parsed.host.front() == '[' && parsed.host.back() == ']') {
    parsed.host = parsed.host.substr(1, parsed.host.size() - 2);
  }
  return parsed;
}

// Whether `host` (as --listen names it) is a loopback address: localhost, 127.0.0.0/8, ::1.
bool IsLoopback(absl::string_view host) {
  return host == "localhost" || host == "::1" || absl::StartsWith(host, "127.");
}

// SIGHUP: the certificate and key read again replace those of `http`'s new handshakes.
void RenewCertificate(const ViewOptions& options, HttpServer& http, std::ostream& out,
                      std::ostream& err) {
  absl::StatusOr<ViewOptions::TlsPem> pem = options.reread_tls();
  absl::Status replaced = pem.status();
  if (pem.ok()) {
    absl::StatusOr<std::shared_ptr<const TlsServerContext>> tls =
        TlsServerContext::Create(pem->certificate_chain, pem->private_key);
    replaced = tls.ok() ? http.ReplaceTls(*std::move(tls)) : tls.status();
  }
  if (replaced.ok()) {
    out << "neuralmesh view: SIGHUP received; HTTPS certificate and key read again" << std::endl;
  } else {
    err << "neuralmesh view: SIGHUP received; the old HTTPS certificate stays: "
        << replaced.message() << std::endl;
  }
}

// SIGHUP: the viewer key read again replaces the one requests must bring.
void RenewKey(const ViewOptions& options, const std::string& url, ViewerService& viewer,
              std::ostream& out, std::ostream& err) {
  absl::StatusOr<std::string> key = options.reread_key();
  if (key.ok()) {
    viewer.ReplaceKey(*key);
    out << "neuralmesh view: SIGHUP received; viewer key read again: browsers open " << url
        << "?key=" << *key << std::endl;
  } else {
    err << "neuralmesh view: SIGHUP received; the old viewer key stays: "
        << key.status().message() << std::endl;
  }
}

// SIGHUP: the HTTPS certificate and the viewer key, each where the viewer has one.
void Reload(const ViewOptions& options, const std::string& url, HttpServer& http,
            ViewerService& viewer, std::ostream& out, std::ostream& err) {
  const bool https = std::string_view(http.scheme()) == "https" && options.reread_tls;
  const bool keyed = !options.key.empty() && options.reread_key;
  if (!https && !keyed) {
    out << "neuralmesh view: SIGHUP received; no HTTPS certificate or viewer key to read again"
        << std::endl;
    return;
  }
  if (https) RenewCertificate(options, http, out, err);
  if (keyed) RenewKey(options, url, viewer, out, err);
}

}  // namespace

std::string DefaultWebRoot() { return NEURALMESH_WEB_ROOT; }

absl::Status RunView(const ViewOptions& options, std::ostream& out, std::ostream& err) {
  if (options.server.empty()) return absl::InvalidArgumentError("--server HOST:PORT is required");
  const std::string web_root = options.web_root.empty() ? DefaultWebRoot() : options.web_root;
  NM_RETURN_IF_ERROR(CheckWebRoot(web_root));
  NM_ASSIGN_OR_RETURN(const HostPort listen, ParseListenAddress(options.listen));
  HttpServerOptions http_options;
  if (!options.tls_certificate_chain.empty() || !options.tls_private_key.empty()) {
    if (options.tls_certificate_chain.empty() || options.tls_private_key.empty()) {
      return absl::InvalidArgumentError(
          "HTTPS needs both a certificate (--view_tls_cert_file) and its key "
          "(--view_tls_key_file)");
    }
    NM_ASSIGN_OR_RETURN(
        http_options.tls,
        TlsServerContext::Create(options.tls_certificate_chain, options.tls_private_key));
  }
  NM_ASSIGN_OR_RETURN(std::unique_ptr<ReconstructionClient> client,
                      ReconstructionClient::Connect(options.server, options.connection));
  // One call before serving: a server that refuses the viewer (a missing or wrong access
  // token) is reported now, not as a 502 on every page.
  NM_RETURN_IF_ERROR(client->ListSessions().status());

  ViewerOptions viewer_options;
  viewer_options.web_root = web_root;
  viewer_options.key = options.key;
  viewer_options.https = http_options.tls != nullptr;
  ViewerService viewer(std::move(client), viewer_options);
  NM_ASSIGN_OR_RETURN(
      std::unique_ptr<HttpServer> http,
      HttpServer::Start(listen.host, listen.port,
                        [&viewer](const HttpRequest& request) { return viewer.Handle(request); },
                        http_options));
  const bool ipv6 = listen.host.find(':') != std::string::npos;
  const std::string url = absl::StrCat(http->scheme(), "://", ipv6 ? "[" : "", listen.host,
                                       ipv6 ? "]" : "", ":", http->port(), "/");
  out << "viewer: " << url << " (sessions of " << options.server << "); Ctrl-C stops it";
  if (!options.key.empty()) out << "; browsers open " << url << "?key=" << options.key;
  out << std::endl;
  if (options.key.empty() && !IsLoopback(listen.host)) {
    err << "neuralmesh view: warning: anyone who reaches " << listen.host
        << " sees every session of " << options.server
        << "; --view_key_file lets in only those given the key" << std::endl;
  } else if (!viewer_options.https && !IsLoopback(listen.host)) {
    err << "neuralmesh view: warning: the key crosses the network in the clear; "
           "--view_tls_cert_file and --view_tls_key_file serve HTTPS"
        << std::endl;
  }

  InterruptScope interrupt;
  ReloadSignalScope reload;
  for (int tick = 1; !InterruptScope::interrupted(); ++tick) {
    absl::SleepFor(absl::Milliseconds(100));
    if (tick % 50 == 0) viewer.DropIdleRelays();
    if (ReloadSignalScope::TakeRequest()) Reload(options, url, *http, viewer, out, err);
  }
  viewer.Stop();
  http->Shutdown();
  return absl::OkStatus();
}

}  // namespace neuralmesh::client::web
