#include "server/server_metrics.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace neuralmesh::server {
namespace {

absl::string_view RpcTypeName(RpcType type) {
  switch (type) {
    case RpcType::kUnary:
      return "unary";
    case RpcType::kClientStream:
      return "client_stream";
    case RpcType::kServerStream:
      return "server_stream";
    case RpcType::kBidiStream:
      return "bidi_stream";
  }
  return "unary";
}

// gRPC's names of its status codes, as the metrics of other gRPC servers label them.
absl::string_view StatusCodeName(int code) {
  static constexpr absl::string_view kNames[] = {
      "OK",       "Canceled",       "Unknown",          "InvalidArgument",   "DeadlineExceeded",
      "NotFound", "AlreadyExists",  "PermissionDenied", "ResourceExhausted", "FailedPrecondition",
      "Aborted",  "OutOfRange",     "Unimplemented",    "Internal",          "Unavailable",
      "DataLoss", "Unauthenticated"};
  return code >= 0 && code < static_cast<int>(std::size(kNames)) ? kNames[code] : "Unknown";
}

// grpc_service and grpc_method of "/package.Service/Method".
MetricLabels MethodLabels(absl::string_view full_method, RpcType type) {
  absl::string_view name = full_method;
  if (!name.empty() && name.front() == '/') name.remove_prefix(1);
  const size_t slash = name.rfind('/');
  absl::string_view service = slash == absl::string_view::npos ? "" : name.substr(0, slash);
  absl::string_view method = slash == absl::string_view::npos ? name : name.substr(slash + 1);
  return {{"grpc_service", std::string(service)},
          {"grpc_method", std::string(method)},
          {"grpc_type", std::string(RpcTypeName(type))}};
}

}  // namespace

const std::vector<double>& ServerMetrics::HandlingSecondsBounds() {
  static const std::vector<double> bounds = {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25,
                                             0.5,   1,      2.5,   5,    10,    30,   60,  300};
  return bounds;
}

void ServerMetrics::AddLearning(uint64_t basic_steps, absl::Duration took) {
  basic_steps_.fetch_add(basic_steps);
  learning_nanoseconds_.fetch_add(absl::ToInt64Nanoseconds(took));
}

void ServerMetrics::AddMeshPublished(uint64_t draco_bytes) {
  meshes_published_.fetch_add(1);
  mesh_bytes_published_.fetch_add(draco_bytes);
}

void ServerMetrics::AddMeshPainted(absl::Duration took) {
  meshes_painted_.fetch_add(1);
  painting_nanoseconds_.fetch_add(absl::ToInt64Nanoseconds(took));
}

void ServerMetrics::CountSessionEnded(v1::SessionState state) {
  switch (state) {
    case v1::SESSION_STATE_FINISHED:
      sessions_finished_.fetch_add(1);
      break;
    case v1::SESSION_STATE_CANCELLED:
      sessions_cancelled_.fetch_add(1);
      break;
    case v1::SESSION_STATE_FAILED:
      sessions_failed_.fetch_add(1);
      break;
    default:
      break;
  }
}

ServerMetrics::MethodCounts& ServerMetrics::MethodLocked(absl::string_view full_method) {
  auto it = methods_.find(full_method);
  if (it == methods_.end()) it = methods_.emplace(std::string(full_method), MethodCounts()).first;
  return it->second;
}

void ServerMetrics::CountRpcStarted(absl::string_view full_method, RpcType type) {
  absl::MutexLock lock(&mu_);
  MethodCounts& counts = MethodLocked(full_method);
  counts.type = type;
  ++counts.started;
}

void ServerMetrics::CountRpcHandled(absl::string_view full_method, RpcType type, int code,
                                    absl::Duration took) {
  absl::MutexLock lock(&mu_);
  MethodCounts& counts = MethodLocked(full_method);
  counts.type = type;
  ++counts.handled[code];
  if (type != RpcType::kUnary) return;
  const std::vector<double>& bounds = HandlingSecondsBounds();
  const double seconds = absl::ToDoubleSeconds(took);
  if (counts.seconds_buckets.empty()) counts.seconds_buckets.assign(bounds.size() + 1, 0);
  const size_t bucket = std::lower_bound(bounds.begin(), bounds.end(), seconds) - bounds.begin();
  ++counts.seconds_buckets[bucket];
  counts.seconds_sum += seconds;
}

void ServerMetrics::AppendTo(PrometheusText& out) const {
  out.Single("neuralmesh_points_accepted_total", "counter",
             "Points the sessions took from uploads (outliers held back included).",
             points_accepted_.load());
  out.Single("neuralmesh_basic_steps_total", "counter",
             "Basic Steps (Section 2.1 of the paper) the sessions' learners ran.",
             basic_steps_.load());
  out.Single("neuralmesh_learning_seconds_total", "counter",
             "Time the worker threads spent learning, summed over the threads.",
             static_cast<double>(learning_nanoseconds_.load()) * 1e-9);
  out.Single("neuralmesh_meshes_published_total", "counter",
             "Meshes published to the sessions' watchers (milestones, refreshes, final meshes).",
             meshes_published_.load());
  out.Single("neuralmesh_mesh_bytes_published_total", "counter",
             "Draco bytes of the meshes published (once per mesh, whatever the watchers).",
             mesh_bytes_published_.load());
  out.Single("neuralmesh_meshes_painted_total", "counter",
             "Meshes given vertex colours from their session's coloured points before encoding.",
             meshes_painted_.load());
  out.Single("neuralmesh_painting_seconds_total", "counter",
             "Time the encoder threads spent painting meshes, summed over the threads.",
             static_cast<double>(painting_nanoseconds_.load()) * 1e-9);
  out.Single("neuralmesh_sessions_created_total", "counter", "Sessions created by clients.",
             sessions_created_.load());
  out.Family("neuralmesh_sessions_ended_total", "counter",
             "Sessions that reached an end, by how it ended.");
  out.Sample("neuralmesh_sessions_ended_total", {{"state", "finished"}}, sessions_finished_.load());
  out.Sample("neuralmesh_sessions_ended_total", {{"state", "cancelled"}},
             sessions_cancelled_.load());
  out.Sample("neuralmesh_sessions_ended_total", {{"state", "failed"}}, sessions_failed_.load());
  out.Family("neuralmesh_sessions_deleted_total", "counter",
             "Sessions deleted, by a client's call or for being idle (--idle_timeout).");
  out.Sample("neuralmesh_sessions_deleted_total", {{"reason", "call"}}, sessions_deleted_.load());
  out.Sample("neuralmesh_sessions_deleted_total", {{"reason", "idle"}}, sessions_reaped_.load());

  absl::MutexLock lock(&mu_);
  out.Family("grpc_server_started_total", "counter", "gRPC calls started on the server.");
  for (const auto& [name, counts] : methods_) {
    out.Sample("grpc_server_started_total", MethodLabels(name, counts.type), counts.started);
  }
  out.Family("grpc_server_handled_total", "counter",
             "gRPC calls completed on the server, by status code.");
  for (const auto& [name, counts] : methods_) {
    for (const auto& [code, handled] : counts.handled) {
      MetricLabels labels = MethodLabels(name, counts.type);
      labels.emplace_back("grpc_code", std::string(StatusCodeName(code)));
      out.Sample("grpc_server_handled_total", labels, handled);
    }
  }
  out.Family("grpc_server_handling_seconds", "histogram",
             "Time from the start of a unary gRPC call to its status.");
  for (const auto& [name, counts] : methods_) {
    if (counts.seconds_buckets.empty()) continue;
    out.Histogram("grpc_server_handling_seconds", MethodLabels(name, counts.type),
                  HandlingSecondsBounds(), counts.seconds_buckets, counts.seconds_sum);
  }
}

}  // namespace neuralmesh::server
