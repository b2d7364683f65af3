#include "server/server.h"

#include <algorithm>
#include <utility>

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server_builder.h>
#include <grpcpp/support/channel_arguments.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/status_macros.h"
#include "http/bearer_token.h"
#include "http/tls_server_context.h"
#include "server/metrics_http.h"
#include "server/rpc_metrics_interceptor.h"

namespace neuralmesh::server {
namespace {

constexpr char kServiceName[] = "neuralmesh.v1.ReconstructionService";
// How long unary calls may take to finish once the streams are gone.
constexpr absl::Duration kUnaryGrace = absl::Milliseconds(200);

// The host of "host:port" ("[::]:50051" gives "::").
std::string HostOf(absl::string_view address) {
  const size_t colon = address.rfind(':');
  absl::string_view host = colon == absl::string_view::npos ? address : address.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  return std::string(host);
}

// The metrics page's TLS: the certificate and key of `tls`, and with
// metrics_client_certificate its client CAs.
absl::StatusOr<std::shared_ptr<const http::TlsServerContext>> MetricsTlsContext(
    const ServerOptions& options, const ServerTls& tls) {
  return http::TlsServerContext::Create(
      tls.certificate_chain, tls.private_key,
      options.metrics_client_certificate ? tls.client_ca_certificates : std::string());
}

}  // namespace

ReconstructionServer::ReconstructionServer(const ServerOptions& options) : options_(options) {}

absl::StatusOr<std::unique_ptr<ReconstructionServer>> ReconstructionServer::Start(
    const ServerOptions& options) {
  if (options.worker_threads < 1 || options.encoder_threads < 1 || options.filter_threads < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "worker_threads (", options.worker_threads, "), encoder_threads (", options.encoder_threads,
        ") and filter_threads (", options.filter_threads, ") must be at least 1"));
  }
  if (options.time_slice <= absl::ZeroDuration()) {
    return absl::InvalidArgumentError("time_slice must be positive");
  }
  if (options.max_message_bytes < 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_message_bytes is ", options.max_message_bytes,
                     "; it must be at least 1024"));
  }
  if (options.limits.max_sessions < 1 || options.limits.max_points_per_session < 4 ||
      options.limits.max_batch_points < 1) {
    return absl::InvalidArgumentError(
        "max_sessions, max_batch_points must be at least 1 and max_points_per_session at "
        "least 4");
  }
  if (options.limits.idle_timeout <= absl::ZeroDuration()) {
    return absl::InvalidArgumentError("idle_timeout must be positive");
  }
  if (options.metrics_port < -1 || options.metrics_port > 65535) {
    return absl::InvalidArgumentError(absl::StrCat(
        "metrics_port is ", options.metrics_port, "; it must be in [0, 65535], or -1 for none"));
  }
  if ((options.metrics_tls || !options.metrics_token.empty()) && options.metrics_port < 0) {
    return absl::InvalidArgumentError(
        "metrics_tls and metrics_token are for the metrics page, and there is none "
        "(metrics_port)");
  }
  if (options.metrics_tls && !options.security.tls.enabled()) {
    return absl::InvalidArgumentError(
        "metrics_tls serves the metrics page with the server's TLS certificate, and there is "
        "none (tls_cert_file)");
  }
  if (options.metrics_client_certificate &&
      (!options.metrics_tls || options.security.tls.client_ca_certificates.empty())) {
    return absl::InvalidArgumentError(
        "metrics_client_certificate asks the metrics page's clients for a certificate signed "
        "by the server's client CAs: it needs metrics_tls and client CAs (tls_client_ca_file)");
  }
  if (!options.metrics_token.empty()) {
    absl::StatusOr<std::string> token =
        http::ParseSecret(options.metrics_token, "the metrics token");
    if (!token.ok()) return token.status();
    if (*token != options.metrics_token) {
      return absl::InvalidArgumentError("the metrics token has whitespace around it");
    }
  }
  std::shared_ptr<const http::TlsServerContext> metrics_tls;
  if (options.metrics_tls) {
    absl::StatusOr<std::shared_ptr<const http::TlsServerContext>> context =
        MetricsTlsContext(options, options.security.tls);
    if (!context.ok()) {
      return absl::Status(context.status().code(),
                          absl::StrCat("metrics page: ", context.status().message()));
    }
    metrics_tls = *std::move(context);
  }

  absl::StatusOr<PortCredentials> credentials = MakeServerCredentials(options.security);
  if (!credentials.ok()) return credentials.status();

  std::unique_ptr<ReconstructionServer> server(new ReconstructionServer(options));
  server->token_checker_ = credentials->token_checker;
  if (!options.security.client_roles.empty()) {
    server->certificate_identity_ = credentials->certificate_identity;
  }
  server->tls_identity_ = credentials->tls_identity;
  server->pool_ = std::make_unique<WorkerPool>(options.worker_threads, options.time_slice);
  server->encoder_ = std::make_unique<Executor>(options.encoder_threads);
  server->filter_ = std::make_unique<Executor>(options.filter_threads);
  server->reactors_ = std::make_unique<ReactorRegistry>();
  if (!options.state_dir.empty()) {
    absl::StatusOr<std::unique_ptr<SessionStore>> store =
        SessionStore::Open(options.state_dir, options.state_sync, options.checkpoint_interval);
    if (!store.ok()) return store.status();
    server->store_ = *std::move(store);
  }
  const std::shared_ptr<EventLog> log =
      options.event_sink ? std::make_shared<EventLog>(options.event_sink) : nullptr;
  server->manager_ =
      std::make_unique<SessionManager>(options.limits, server->pool_.get(), server->encoder_.get(),
                                       log, server->store_.get(), &server->metrics_);
  // Stored sessions are restored while the server takes calls (calls on them get UNAVAILABLE
  // until then): a large state directory does not hold up the start.
  server->manager_->StartRestore();
  server->service_ = std::make_unique<ReconstructionService>(
      server->manager_.get(), server->reactors_.get(), server->filter_.get());

  // Both switches are process-wide and must be set before the builder is created.
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  grpc::ServerBuilder builder;
  if (!options.address.empty()) {
    builder.AddListeningPort(options.address, credentials->credentials, &server->port_);
  }
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  builder.SetMaxSendMessageSize(options.max_message_bytes);
  // Clients that watch a quiet session ping to find out whether the server still answers
  // (ClientOptions::keepalive_time); gRPC's default refuses more than one ping in 5 minutes
  // from a client that sends no data and then drops its connection.
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 1000);
  // And the server finds clients that vanished without closing their connections (a watcher
  // behind a dropped network), so that their calls end; it keeps pinging a client that only
  // listens (gRPC stops after two pings without data otherwise).
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, 60 * 1000);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 20 * 1000);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
  builder.RegisterService(server->service_.get());
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> creators;
  creators.push_back(RpcMetricsInterceptorFactory(&server->metrics_));
  if (log != nullptr && options.log_calls != CallLogLevel::kNone) {
    creators.push_back(CallLogInterceptorFactory(log, options.log_calls));
  }
  builder.experimental().SetInterceptorCreators(std::move(creators));
  server->server_ = builder.BuildAndStart();
  if (server->server_ == nullptr || (!options.address.empty() && server->port_ == 0)) {
    server->server_.reset();
    return absl::UnavailableError(
        absl::StrCat("cannot listen on \"", options.address, "\" (in use or not local?)"));
  }
  grpc::HealthCheckServiceInterface* health = server->server_->GetHealthCheckService();
  if (health != nullptr) {
    health->SetServingStatus(true);
    health->SetServingStatus(kServiceName, true);
  }
  if (options.metrics_port >= 0) {
    MetricsSources sources;
    sources.metrics = &server->metrics_;
    sources.sessions = server->manager_.get();
    sources.worker_threads = options.worker_threads;
    sources.start_time = absl::Now();
    ReconstructionServer* self = server.get();
    sources.serving = [self] {
      absl::MutexLock lock(&self->shutdown_mu_);
      return !self->shutting_down_;
    };
    if (!options.metrics_token.empty()) {
      server->metrics_access_ = std::make_shared<MetricsAccess>(options.metrics_token);
      sources.access = server->metrics_access_;
    }
    sources.require_client_certificate = options.metrics_client_certificate;
    // Where clients have roles by their certificates, the page follows them, as renewed.
    if (std::shared_ptr<ClientCertificateIdentity> identity = server->certificate_identity_) {
      sources.client_role = [identity](absl::string_view common_name) {
        return identity->RoleOf(common_name);
      };
    }
    std::string host =
        options.metrics_host.empty() ? HostOf(options.address) : options.metrics_host;
    if (host.empty()) host = "127.0.0.1";  // In-process only: no network the server listens on.
    server->metrics_host_ = host;
    http::HttpServerOptions http_options;
    http_options.tls = std::move(metrics_tls);
    absl::StatusOr<std::unique_ptr<http::HttpServer>> http = http::HttpServer::Start(
        host, options.metrics_port,
        [sources](const http::HttpRequest& request) {
          return AnswerMetricsRequest(request, sources);
        },
        http_options);
    if (!http.ok()) {
      server->Shutdown(absl::ZeroDuration());
      return absl::Status(http.status().code(),
                          absl::StrCat("metrics page: ", http.status().message()));
    }
    server->metrics_http_ = *std::move(http);
  }
  return server;
}

ReconstructionServer::~ReconstructionServer() { Shutdown(); }

std::string ReconstructionServer::target() const {
  std::string host = HostOf(options_.address);
  if (host.empty() || host == "0.0.0.0" || host == "::") host = "127.0.0.1";
  return absl::StrCat(host, ":", port_);
}

std::shared_ptr<grpc::Channel> ReconstructionServer::InProcessChannel() {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(options_.max_message_bytes);
  args.SetMaxSendMessageSize(options_.max_message_bytes);
  return server_->InProcessChannel(args);
}

absl::Status ReconstructionServer::ReplaceAccessTokens(std::vector<AccessToken> tokens) {
  if (token_checker_ == nullptr) {
    return absl::FailedPreconditionError(
        "the server was started without access tokens; tokens cannot be added to it running");
  }
  return token_checker_->ReplaceTokens(std::move(tokens));
}

absl::Status ReconstructionServer::ReplaceClientRoles(ClientRoles roles) {
  if (certificate_identity_ == nullptr) {
    return absl::FailedPreconditionError(
        "the server was started without client roles; they cannot be added to it running");
  }
  if (roles.empty()) return absl::InvalidArgumentError("no client roles");
  certificate_identity_->ReplaceRoles(std::move(roles));
  return absl::OkStatus();
}

absl::Status ReconstructionServer::ReplaceTls(const ServerTls& tls) {
  if (tls_identity_ == nullptr) {
    return absl::FailedPreconditionError(
        "the server was started without TLS; TLS cannot be turned on while it runs");
  }
  std::shared_ptr<const http::TlsServerContext> metrics_tls;
  if (options_.metrics_tls && metrics_http_ != nullptr) {
    absl::StatusOr<std::shared_ptr<const http::TlsServerContext>> context =
        MetricsTlsContext(options_, tls);
    if (!context.ok()) return context.status();
    metrics_tls = *std::move(context);
  }
  NM_RETURN_IF_ERROR(tls_identity_->Replace(tls));
  return metrics_tls != nullptr ? metrics_http_->ReplaceTls(std::move(metrics_tls))
                                : absl::OkStatus();
}

absl::Status ReconstructionServer::ReplaceMetricsToken(const std::string& token) {
  if (metrics_access_ == nullptr) {
    return absl::FailedPreconditionError(
        "the metrics page was started without a token; one cannot be added while it runs");
  }
  NM_ASSIGN_OR_RETURN(std::string parsed, http::ParseSecret(token, "the metrics token"));
  return metrics_access_->Replace(std::move(parsed));
}

std::string ReconstructionServer::metrics_url() const {
  if (metrics_http_ == nullptr) return "";
  const bool ipv6 = metrics_host_.find(':') != std::string::npos;
  return absl::StrCat(metrics_http_->scheme(), "://", ipv6 ? "[" : "", metrics_host_,
                      ipv6 ? "]" : "", ":", metrics_http_->port(), "/metrics");
}

void ReconstructionServer::Shutdown(absl::Duration grace) {
  {
    absl::MutexLock lock(&shutdown_mu_);
    if (shutting_down_) return;
    shutting_down_ = true;
  }
  if (server_ != nullptr) {
    if (grpc::HealthCheckServiceInterface* health = server_->GetHealthCheckService()) {
      health->SetServingStatus(false);
      health->SetServingStatus(kServiceName, false);
    }
  }
  const absl::Status unavailable = absl::UnavailableError("the server is shutting down");
  // Sessions first: their channels close, which ends watchers and Reconstruct calls.
  if (manager_ != nullptr) manager_->Shutdown(unavailable);
  // Then every remaining live reactor (uploads, waiting GetMesh calls).
  if (reactors_ != nullptr) reactors_->AbortAll(unavailable);
  if (server_ != nullptr) {
    // The aborted reactors finish at once; give them the grace period to reach OnDone. What is
    // left then are unary calls (which finish inline) and idle client connections, which gRPC
    // would otherwise wait for until the deadline: a short one closes them.
    reactors_->AwaitEmpty(absl::Now() + grace);
    server_->Shutdown(absl::ToChronoTime(absl::Now() + std::min(grace, kUnaryGrace)));
    server_->Wait();
  }
  // The metrics page answers until the end (/healthz: 503 meanwhile).
  if (metrics_http_ != nullptr) metrics_http_->Shutdown();
  // Batches still waiting to be filtered belong to calls that have ended: dropped.
  if (filter_ != nullptr) filter_->Shutdown();
  if (pool_ != nullptr) pool_->Shutdown();
  if (encoder_ != nullptr) encoder_->Shutdown();
  absl::MutexLock lock(&shutdown_mu_);
  shut_down_ = true;
}

void ReconstructionServer::Wait() {
  absl::MutexLock lock(&shutdown_mu_);
  auto done = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(shutdown_mu_) { return shut_down_; };
  shutdown_mu_.Await(absl::Condition(&done));
}

}  // namespace neuralmesh::server
