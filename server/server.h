// The neuralmesh gRPC server: the reconstruction service plus the standard health service
// (grpc.health.v1.Health) and server reflection, on a bounded learning pool.
#ifndef NEURALMESH_SERVER_SERVER_H_
#define NEURALMESH_SERVER_SERVER_H_

#include <memory>
#include <string>
#include <vector>

#include <grpcpp/channel.h>
#include <grpcpp/server.h>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "http/http_server.h"
#include "server/call_log_interceptor.h"
#include "server/event_log.h"
#include "server/executor.h"
#include "server/metrics_http.h"
#include "server/reactor_registry.h"
#include "server/reconstruction_service.h"
#include "server/server_credentials.h"
#include "server/server_metrics.h"
#include "server/session_manager.h"
#include "server/session_store.h"
#include "server/worker_pool.h"

namespace neuralmesh::server {

struct ServerOptions {
  // host:port to listen on ("127.0.0.1:0" picks a free port); empty: in-process only.
  std::string address = "127.0.0.1:0";
  // TLS, mutual TLS and access tokens of the listening port (none: plaintext, open to all).
  ServerSecurity security;
  int worker_threads = 2;                            // Learning threads, shared by all sessions.
  int encoder_threads = 1;                           // Draco encoding threads.
  // Threads that ingest the batches of sessions that filter outliers, off gRPC's threads.
  int filter_threads = 1;
  absl::Duration time_slice = absl::Milliseconds(20);  // Learning per session per turn.
  int max_message_bytes = 64 << 20;                  // Both directions.
  SessionLimits limits;
  // Where each session's creation, end and deletion are recorded (event_log.h); null: nowhere.
  EventLog::Sink event_sink;
  // Which gRPC calls are recorded there too (call_log_interceptor.h).
  CallLogLevel log_calls = CallLogLevel::kNone;
  // The state directory (session_store.h): sessions kept on disk and restored at Start, so
  // that they outlive a restart. Empty: sessions live in memory only.
  std::string state_dir;
  // With state_dir: each batch and state change is on the disk (fdatasync) before it is
  // acknowledged; false: in the kernel's hands, which survives a crash of the server but
  // perhaps not one of the machine.
  bool state_sync = true;
  // With state_dir: a refresh of a learning session is kept as its learner checkpoint when at
  // least this long has passed since its last one (every milestone is kept), so that a restart
  // costs at most about this much learning. Zero: milestones only.
  absl::Duration checkpoint_interval = kDefaultCheckpointInterval;
  // The metrics page (metrics_http.h) at metrics_host (empty: the host of `address`) and this
  // port; 0 picks a free one, -1: none.
  int metrics_port = -1;
  std::string metrics_host;
  // The metrics page speaks HTTPS with the certificate and key of security.tls (needs TLS),
  // and ReplaceTls renews it with them; false: plain HTTP.
  bool metrics_tls = false;
  // With metrics_tls and client CAs (security.tls.client_ca_certificates): /metrics answers
  // only clients that present a certificate those CAs signed (403 otherwise); / and /healthz
  // stay open to probes without one.
  bool metrics_client_certificate = false;
  // Set: /metrics asks for this token (http::ParseSecret's rules) as "Authorization: Bearer";
  // empty: anyone who reaches the page reads it.
  std::string metrics_token;
};

class ReconstructionServer {
 public:
  // Builds and starts the server, after restoring the sessions of options.state_dir.
  // INVALID_ARGUMENT for bad options (security included); UNAVAILABLE when the address cannot
  // be bound or gRPC rejects the TLS certificate or key; FAILED_PRECONDITION when another
  // server uses the state directory, and the errno's code when it cannot be created.
  static absl::StatusOr<std::unique_ptr<ReconstructionServer>> Start(
      const ServerOptions& options);
  ~ReconstructionServer();  // Shutdown with a 5 s grace period.

  ReconstructionServer(const ReconstructionServer&) = delete;
  ReconstructionServer& operator=(const ReconstructionServer&) = delete;

  // The bound port (0 when in-process only) and "host:port" to dial. The in-process channel
  // bypasses TLS and access tokens: it is for callers inside the process.
  int port() const { return port_; }
  std::string target() const;
  // The port of the metrics page; -1 without one.
  int metrics_port() const { return metrics_http_ != nullptr ? metrics_http_->port() : -1; }
  // The address of the metrics page, "http://HOST:PORT/metrics" (https:// with metrics_tls);
  // empty without one.
  std::string metrics_url() const;

  // A channel into the server without a socket (tests of the logic, in-process callers).
  std::shared_ptr<grpc::Channel> InProcessChannel();

  // Ends every open stream with UNAVAILABLE and waits up to `grace` for them to close, then
  // stops gRPC (unary calls still running get 200 ms more, idle connections are closed), then
  // stops learning and encoding. Idempotent; thread-safe.
  void Shutdown(absl::Duration grace = absl::Seconds(5)) ABSL_LOCKS_EXCLUDED(shutdown_mu_);

  // Blocks until Shutdown has completed.
  void Wait() ABSL_LOCKS_EXCLUDED(shutdown_mu_);

  // Replaces the access tokens for calls that start from now on (running calls go on), for a
  // reload without a restart. FAILED_PRECONDITION when the server was started without tokens,
  // INVALID_ARGUMENT (the old tokens kept) for an empty list, an invalid token or client name.
  absl::Status ReplaceAccessTokens(std::vector<AccessToken> tokens);

  // Replaces the server's TLS certificate, key and client CAs for the connections that start
  // about a second from now (ServerTlsIdentity::Replace), and with metrics_tls the metrics
  // page's certificate and key (and client CAs, with metrics_client_certificate) at once; connections and calls already running go on.
  // FAILED_PRECONDITION when the server was started without TLS, INVALID_ARGUMENT (the old
  // identity kept) when gRPC or OpenSSL does not take the new one or it would turn mutual TLS
  // on or off.
  absl::Status ReplaceTls(const ServerTls& tls);

  // Replaces the token that /metrics asks for, for requests from now on. FAILED_PRECONDITION
  // when the server was started without one, INVALID_ARGUMENT (the old one kept) for a token
  // that http::ParseSecret refuses.
  absl::Status ReplaceMetricsToken(const std::string& token);

  // Replaces the roles of clients named by their certificates (ServerSecurity::client_roles)
  // for calls that start from now on. FAILED_PRECONDITION when the server was started without
  // client roles; INVALID_ARGUMENT (the old roles kept) for an empty map.
  absl::Status ReplaceClientRoles(ClientRoles roles);

  SessionManager& sessions() { return *manager_; }
  // Blocks until the sessions of options.state_dir are restored (at once without one), and
  // returns what restoring found. Start returns before, and the server answers meanwhile
  // (SessionManager::StartRestore).
  RestoreReport WaitForRestore() const { return manager_->WaitForRestore(); }
  ReactorRegistry& reactors() { return *reactors_; }

 private:
  explicit ReconstructionServer(const ServerOptions& options);

  const ServerOptions options_;
  ServerMetrics metrics_;  // Outlives the sessions and the servers, which count with it.
  std::unique_ptr<WorkerPool> pool_;
  std::unique_ptr<Executor> encoder_;
  std::unique_ptr<Executor> filter_;
  std::unique_ptr<ReactorRegistry> reactors_;
  std::unique_ptr<SessionStore> store_;  // Null without a state directory; outlives manager_.
  std::unique_ptr<SessionManager> manager_;
  std::unique_ptr<ReconstructionService> service_;
  std::shared_ptr<AccessTokenChecker> token_checker_;  // Null without access tokens.
  // Null unless started with client roles.
  std::shared_ptr<ClientCertificateIdentity> certificate_identity_;
  std::shared_ptr<ServerTlsIdentity> tls_identity_;    // Null without TLS; outlives server_.
  std::unique_ptr<http::HttpServer> metrics_http_;  // Null without a metrics port.
  std::string metrics_host_;                        // Where metrics_http_ listens.
  std::shared_ptr<MetricsAccess> metrics_access_;   // Null without a metrics token.
  std::unique_ptr<grpc::Server> server_;  // Destroyed first.
  int port_ = 0;

  absl::Mutex shutdown_mu_;
  bool shutting_down_ ABSL_GUARDED_BY(shutdown_mu_) = false;
  bool shut_down_ ABSL_GUARDED_BY(shutdown_mu_) = false;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SERVER_H_
