// Draco decoding (core/io/draco_codec.h): .drc files read by the CLI, and the
// PointBatch.draco_point_cloud bytes that any client can send the server. Properties:
//  - DecodeMesh and DecodePointCloud return OK or INVALID_ARGUMENT, and never crash;
//  - a decoded mesh has finite positions and faces in range; a decoded cloud passes
//    ValidatePointCloud, as the header promises;
//  - what decodes is encoded again, or rejected with INVALID_ARGUMENT (a spread of positions
//    that Draco cannot quantize), and that encoding decodes to as many points (and, for a
//    mesh, faces that are still in range).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/io/draco_codec.h"
#include "core/point_cloud.h"
#include "fuzz/fuzz_check.h"

namespace {

using neuralmesh::DracoOptions;
using neuralmesh::PointCloud;
using neuralmesh::TriangleMesh;

void CheckFailure(const absl::Status& status) {
  FUZZ_CHECK(status.code() == absl::StatusCode::kInvalidArgument && !status.message().empty(),
             "decoding failed with %s", status.ToString().c_str());
}

void CheckMesh(const TriangleMesh& mesh) {
  for (const auto& p : mesh.positions) {
    FUZZ_CHECK(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]),
               "a decoded position is not finite");
  }
  for (const auto& face : mesh.faces) {
    for (uint32_t index : face) {
      FUZZ_CHECK(index < mesh.positions.size(), "a decoded face refers to vertex %u of %zu",
                 index, mesh.positions.size());
    }
  }
}

void CheckMeshDecoding(std::string_view bytes) {
  const absl::StatusOr<TriangleMesh> mesh = neuralmesh::DecodeMesh(bytes);
  if (!mesh.ok()) return CheckFailure(mesh.status());
  CheckMesh(*mesh);
  const absl::StatusOr<std::string> encoded = neuralmesh::EncodeMesh(*mesh, DracoOptions{});
  // A decoded mesh may hold only degenerate faces, which EncodeMesh rejects.
  if (!encoded.ok()) return CheckFailure(encoded.status());
  const absl::StatusOr<TriangleMesh> again = neuralmesh::DecodeMesh(*encoded);
  FUZZ_CHECK(again.ok(), "a re-encoded mesh does not decode: %s",
             again.status().ToString().c_str());
  CheckMesh(*again);
}

void CheckPointCloudDecoding(std::string_view bytes) {
  const absl::StatusOr<PointCloud> cloud = neuralmesh::DecodePointCloud(bytes);
  if (!cloud.ok()) return CheckFailure(cloud.status());
  const absl::Status valid = neuralmesh::ValidatePointCloud(*cloud);
  FUZZ_CHECK(valid.ok(), "a decoded cloud is invalid: %s", valid.ToString().c_str());
  if (cloud->empty()) return;
  const absl::StatusOr<std::string> encoded =
      neuralmesh::EncodePointCloud(*cloud, DracoOptions{});
  // Draco decodes values of any spread, but cannot quantize a spread below about 6e-36 at 11
  // bits (nor above the float range): EncodePointCloud must reject those.
  if (!encoded.ok()) return CheckFailure(encoded.status());
  const absl::StatusOr<PointCloud> again = neuralmesh::DecodePointCloud(*encoded);
  FUZZ_CHECK(again.ok() && again->size() == cloud->size(),
             "a re-encoded cloud of %zu points decodes to %s", cloud->size(),
             again.ok() ? std::to_string(again->size()).c_str()
                        : again.status().ToString().c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  CheckMeshDecoding(bytes);
  CheckPointCloudDecoding(bytes);
  return 0;
}
