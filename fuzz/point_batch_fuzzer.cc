// The server's reading of a client's PointBatch (server/proto_conversion.h) and the append of
// the result to a session's point cloud, on any bytes that parse as a neuralmesh.v1.PointBatch
// (packed float32 arrays or Draco). Properties:
//  - PointBatchFromProto returns a cloud or INVALID_ARGUMENT / RESOURCE_EXHAUSTED with a
//    message, and never crashes;
//  - a returned cloud holds 1 to max_batch_points points, normals and weights empty or one
//    per point;
//  - GrowingPointCloud::Append takes it whole or rejects it whole with INVALID_ARGUMENT.
#include <cstddef>
#include <cstdint>

#include "core/sampling/growing_point_cloud.h"
#include "fuzz/fuzz_check.h"
#include "neuralmesh/v1/reconstruction.pb.h"
#include "server/proto_conversion.h"

namespace {

// Small enough that the fuzzer reaches the limit; the server's default is 2M.
constexpr size_t kMaxBatchPoints = 4096;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  neuralmesh::v1::PointBatch batch;
  if (!batch.ParseFromArray(data, static_cast<int>(size))) return 0;
  const absl::StatusOr<neuralmesh::PointCloud> cloud =
      neuralmesh::server::PointBatchFromProto(batch, kMaxBatchPoints);
  if (!cloud.ok()) {
    const absl::StatusCode code = cloud.status().code();
    FUZZ_CHECK((code == absl::StatusCode::kInvalidArgument ||
                code == absl::StatusCode::kResourceExhausted) &&
                   !cloud.status().message().empty(),
               "rejected with %s", cloud.status().ToString().c_str());
    return 0;
  }
  const size_t n = cloud->size();
  FUZZ_CHECK(n >= 1 && n <= kMaxBatchPoints, "a batch of %zu points was accepted", n);
  FUZZ_CHECK(cloud->normals.empty() || cloud->normals.size() == n, "%zu normals for %zu points",
             cloud->normals.size(), n);
  FUZZ_CHECK(cloud->weights.empty() || cloud->weights.size() == n, "%zu weights for %zu points",
             cloud->weights.size(), n);

  neuralmesh::GrowingPointCloud session_points;
  const absl::Status appended = session_points.Append(*cloud);
  if (appended.ok()) {
    FUZZ_CHECK(session_points.size() == n, "%zu points appended, %zu held", n,
               session_points.size());
  } else {
    FUZZ_CHECK(appended.code() == absl::StatusCode::kInvalidArgument &&
                   !appended.message().empty(),
               "append failed with %s", appended.ToString().c_str());
    FUZZ_CHECK(session_points.size() == 0, "a rejected batch left %zu points",
               session_points.size());
  }
  return 0;
}
