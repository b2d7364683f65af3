// The server's counters for its metrics endpoint (metrics_http.h): what its sessions did (points
// accepted, Basic Steps learned, meshes painted and published, sessions created, ended and
// deleted) and the
// gRPC calls it handled (rpc_metrics_interceptor.h), from the start of the process. Sessions
// add to them as the work happens; a restored session's earlier work is not counted again.
//
// The figures are totals over all sessions: no session id, name or client appears in them, so
// that scraping the endpoint reveals nothing a session's owner would keep to itself, and the
// number of series stays bounded however many sessions come and go.
#ifndef NEURALMESH_SERVER_SERVER_METRICS_H_
#define NEURALMESH_SERVER_SERVER_METRICS_H_

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "neuralmesh/v1/reconstruction.pb.h"
#include "server/prometheus_text.h"

namespace neuralmesh::server {

// How a gRPC method streams (grpc_type in the metrics, as go-grpc-prometheus names them).
enum class RpcType { kUnary, kClientStream, kServerStream, kBidiStream };

class ServerMetrics {
 public:
  // Upper bounds, in seconds, of the buckets of the unary calls' handling time.
  static const std::vector<double>& HandlingSecondsBounds();

  // Thread-safe, all of them.
  void AddPointsAccepted(uint64_t points) { points_accepted_.fetch_add(points); }
  void AddLearning(uint64_t basic_steps, absl::Duration took);
  void AddMeshPublished(uint64_t draco_bytes);
  // A mesh painted with its session's point colours (color_source.h), which took `took`.
  void AddMeshPainted(absl::Duration took);
  void CountSessionCreated() { sessions_created_.fetch_add(1); }
  // `state`: FINISHED, CANCELLED or FAILED (others are ignored).
  void CountSessionEnded(v1::SessionState state);
  void CountSessionDeleted(bool idle) {
    (idle ? sessions_reaped_ : sessions_deleted_).fetch_add(1);
  }

  // A call of `full_method` ("/package.Service/Method") began; it ended with `code` (a
  // grpc::StatusCode) after `took`.
  void CountRpcStarted(absl::string_view full_method, RpcType type) ABSL_LOCKS_EXCLUDED(mu_);
  void CountRpcHandled(absl::string_view full_method, RpcType type, int code, absl::Duration took)
      ABSL_LOCKS_EXCLUDED(mu_);

  // Writes every counter's family and samples.
  void AppendTo(PrometheusText& out) const ABSL_LOCKS_EXCLUDED(mu_);

 private:
  struct MethodCounts {
    RpcType type = RpcType::kUnary;
    uint64_t started = 0;
    std::map<int, uint64_t> handled;        // By status code.
    std::vector<uint64_t> seconds_buckets;  // Unary calls: HandlingSecondsBounds() + 1 buckets.
    double seconds_sum = 0;
  };
  // The counts of `full_method`, new ones when it had none.
  MethodCounts& MethodLocked(absl::string_view full_method) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  std::atomic<uint64_t> points_accepted_{0};
  std::atomic<uint64_t> basic_steps_{0};
  std::atomic<int64_t> learning_nanoseconds_{0};
  std::atomic<uint64_t> meshes_published_{0};
  std::atomic<uint64_t> mesh_bytes_published_{0};
  std::atomic<uint64_t> meshes_painted_{0};
  std::atomic<int64_t> painting_nanoseconds_{0};
  std::atomic<uint64_t> sessions_created_{0};
  std::atomic<uint64_t> sessions_finished_{0};
  std::atomic<uint64_t> sessions_cancelled_{0};
  std::atomic<uint64_t> sessions_failed_{0};
  std::atomic<uint64_t> sessions_deleted_{0};
  std::atomic<uint64_t> sessions_reaped_{0};

  mutable absl::Mutex mu_;
  std::map<std::string, MethodCounts, std::less<>> methods_ ABSL_GUARDED_BY(mu_);
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SERVER_METRICS_H_
