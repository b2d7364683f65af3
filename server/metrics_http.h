// The server's metrics over HTTP or HTTPS (neuralmesh-server --metrics_port, --metrics_tls),
// for Prometheus and for the probes of container orchestrators:
//
//   GET /metrics  the counters of ServerMetrics and the gauges of what the server holds now
//                 (sessions by state, points, vertices, watchers, sessions still to restore),
//                 in the Prometheus text format
//   GET /healthz  200 "serving" while the server takes calls, 503 once it is shutting down
//   GET /         which pages there are
//
// Totals only, like ServerMetrics: no session id, name or client. Other paths get 404, other
// methods 405 (http/http_server.h). With a token (--metrics_token_file), /metrics answers only
// requests that bring it ("Authorization: Bearer TOKEN"; 401 otherwise), and with client
// certificates (--metrics_client_certificate) only clients that present one the server's
// client CAs signed, and where clients have roles by their certificates' common names
// (--client_roles_file, --client_certificate_role), one whose name has a role (403
// otherwise); /healthz and / stay open to probes, as they tell nothing but whether the server
// serves.
#ifndef NEURALMESH_SERVER_METRICS_HTTP_H_
#define NEURALMESH_SERVER_METRICS_HTTP_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "absl/strings/string_view.h"
#include "http/http_message.h"
#include "server/access_tokens.h"
#include "server/server_metrics.h"
#include "server/session_manager.h"

namespace neuralmesh::server {

// Who may read /metrics: anyone, or those who bring a token that may be replaced while the
// server runs (SIGHUP). Thread-safe.
class MetricsAccess {
 public:
  // Empty: anyone. Else a secret as http::ParseSecret gives it.
  explicit MetricsAccess(std::string token) : token_(std::move(token)) {}

  // Whether `request` may read /metrics.
  bool Admits(const http::HttpRequest& request) const ABSL_LOCKS_EXCLUDED(mu_);
  // For the requests from now on. INVALID_ARGUMENT (the old token kept) for an empty one.
  absl::Status Replace(std::string token) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  mutable absl::Mutex mu_;
  std::string token_ ABSL_GUARDED_BY(mu_);
};

// What the pages read; the pointers must outlive the HTTP server that answers with them.
struct MetricsSources {
  const ServerMetrics* metrics = nullptr;
  const SessionManager* sessions = nullptr;
  // Whether the server takes calls (false once it shuts down).
  std::function<bool()> serving;
  int worker_threads = 0;
  absl::Time start_time;  // Of the process, or of the server.
  std::shared_ptr<const MetricsAccess> access;  // Null: anyone may read /metrics.
  // Whether /metrics needs a verified client certificate (http::HttpRequest::
  // client_certificate) besides what `access` asks.
  bool require_client_certificate = false;
  // With it: the role of a certificate's common name (null: any certificate will do); a
  // client whose name has none is refused.
  std::function<std::optional<AccessRole>(absl::string_view common_name)> client_role;
};

// The /metrics page's text.
std::string RenderMetrics(const MetricsSources& sources);

// The answer to one request.
http::HttpResponse AnswerMetricsRequest(const http::HttpRequest& request,
                                        const MetricsSources& sources);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_METRICS_HTTP_H_
