// The server's metrics over plain HTTP (neuralmesh-server --metrics_port), for Prometheus and
// for the probes of container orchestrators:
//
//   GET /metrics  the counters of ServerMetrics and the gauges of what the server holds now
//                 (sessions by state, points, vertices, watchers, sessions still to restore),
//                 in the Prometheus text format
//   GET /healthz  200 "serving" while the server takes calls, 503 once it is shutting down
//   GET /         which pages there are
//
// Totals only, like ServerMetrics: no session id, name or client. Other paths get 404, other
// methods 405 (http/http_server.h).
#ifndef NEURALMESH_SERVER_METRICS_HTTP_H_
#define NEURALMESH_SERVER_METRICS_HTTP_H_

#include <functional>
#include <string>

#include "absl/time/time.h"
#include "http/http_message.h"
#include "server/server_metrics.h"
#include "server/session_manager.h"

namespace neuralmesh::server {

// What the pages read; the pointers must outlive the HTTP server that answers with them.
struct MetricsSources {
  const ServerMetrics* metrics = nullptr;
  const SessionManager* sessions = nullptr;
  // Whether the server takes calls (false once it shuts down).
  std::function<bool()> serving;
  int worker_threads = 0;
  absl::Time start_time;  // Of the process, or of the server.
};

// The /metrics page's text.
std::string RenderMetrics(const MetricsSources& sources);

// The answer to one request.
http::HttpResponse AnswerMetricsRequest(const http::HttpRequest& request,
                                        const MetricsSources& sources);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_METRICS_HTTP_H_
