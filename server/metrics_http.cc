#include "server/metrics_http.h"

#include <cstdint>
#include <map>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "core/version.h"
#include "http/bearer_token.h"
#include "server/prometheus_text.h"

namespace neuralmesh::server {
namespace {

// "learning" for SESSION_STATE_LEARNING.
std::string StateLabel(v1::SessionState state) {
  return absl::AsciiStrToLower(absl::StripPrefix(v1::SessionState_Name(state), "SESSION_STATE_"));
}

}  // namespace

bool MetricsAccess::Admits(const http::HttpRequest& request) const {
  absl::MutexLock lock(&mu_);
  return token_.empty() || http::SameSecret(http::BearerTokenOf(request), token_);
}

absl::Status MetricsAccess::Replace(std::string token) {
  if (token.empty()) return absl::InvalidArgumentError("an empty metrics token");
  absl::MutexLock lock(&mu_);
  token_ = std::move(token);
  return absl::OkStatus();
}

std::string RenderMetrics(const MetricsSources& sources) {
  const SessionManager::Census census = sources.sessions->TakeCensus();
  std::map<v1::SessionState, uint64_t> by_state;
  for (int s = v1::SessionState_MIN; s <= v1::SessionState_MAX; ++s) {
    if (v1::SessionState_IsValid(s) && s != v1::SESSION_STATE_UNSPECIFIED) {
      by_state[static_cast<v1::SessionState>(s)] = 0;
    }
  }
  uint64_t points = 0, vertices = 0, watchers = 0, outliers_held = 0;
  for (const std::shared_ptr<Session>& session : census.sessions) {
    const v1::Session info = session->ToProto();
    ++by_state[info.state()];
    points += info.learning().points_received();
    vertices += info.vertex_count();
    watchers += info.watchers();
    outliers_held += info.learning().outliers_held();
  }

  PrometheusText out;
  out.Family("neuralmesh_build_info", "gauge", "The server's version, as a label; always 1.");
  out.Sample("neuralmesh_build_info", {{"version", NeuralmeshVersion()}}, uint64_t{1});
  out.Single("neuralmesh_start_time_seconds", "gauge",
             "When the server started, in seconds since the Unix epoch.",
             absl::ToDoubleSeconds(sources.start_time - absl::UnixEpoch()));
  out.Single("neuralmesh_worker_threads", "gauge",
             "Learning threads, shared by all sessions in time slices (--worker_threads).",
             static_cast<uint64_t>(sources.worker_threads));
  out.Family("neuralmesh_sessions", "gauge", "Sessions held, by state.");
  for (const auto& [state, count] : by_state) {
    out.Sample("neuralmesh_sessions", {{"state", StateLabel(state)}}, count);
  }
  out.Single("neuralmesh_sessions_limit", "gauge",
             "Sessions the server holds at most (--max_sessions).",
             static_cast<uint64_t>(sources.sessions->limits().max_sessions));
  out.Single("neuralmesh_sessions_to_restore", "gauge",
             "Stored sessions still to be restored after a restart (--state_dir).",
             static_cast<uint64_t>(census.to_restore));
  out.Single("neuralmesh_points", "gauge", "Points the sessions held have received.", points);
  out.Single("neuralmesh_outliers_held", "gauge",
             "Points the sessions hold back as possible outliers, to judge again.", outliers_held);
  out.Single("neuralmesh_mesh_vertices", "gauge",
             "Vertices of the sessions' latest published meshes, summed.", vertices);
  out.Single("neuralmesh_watchers", "gauge",
             "Calls following the sessions' meshes (watch streams, waiting GetMesh calls).",
             watchers);
  sources.metrics->AppendTo(out);
  return out.str();
}

http::HttpResponse AnswerMetricsRequest(const http::HttpRequest& request,
                                        const MetricsSources& sources) {
  if (request.path == "/metrics") {
    if (sources.require_client_certificate && !request.client_certificate) {
      return http::TextResponse(403,
                                "/metrics needs a client certificate signed by the server's "
                                "client CA (--tls_client_ca_file)");
    }
    if (sources.require_client_certificate && sources.client_role &&
        !sources.client_role(request.client_common_name).has_value()) {
      return http::TextResponse(
          403, absl::StrCat("the client certificate's common name \"",
                            request.client_common_name,
                            "\" has no role on this server (--client_roles_file)"));
    }
    if (sources.access != nullptr && !sources.access->Admits(request)) {
      return http::BearerChallenge(
          "neuralmesh metrics",
          http::BearerTokenOf(request).empty()
              ? "/metrics needs the token of --metrics_token_file: send 'Authorization: Bearer "
                "TOKEN'"
              : "/metrics refused the token: it is not the one of --metrics_token_file");
    }
    http::HttpResponse response = http::TextResponse(200, "");
    response.content_type = kPrometheusTextContentType;
    response.body = RenderMetrics(sources);
    return response;
  }
  if (request.path == "/healthz") {
    return sources.serving() ? http::TextResponse(200, "serving")
                             : http::TextResponse(503, "shutting down");
  }
  if (request.path == "/") {
    return http::TextResponse(200,
                              "neuralmesh-server: /metrics (Prometheus text format), /healthz");
  }
  return http::TextResponse(
      404, absl::StrCat("no page ", request.path, "; this server has /metrics and /healthz"));
}

}  // namespace neuralmesh::server
