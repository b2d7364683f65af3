#include "proto/packing.h"

#include <cstring>
#include <string>
#include <vector>

namespace neuralmesh {
namespace {

// Elements [begin, end) of `values` as bytes (this machine is little-endian, as the API).
template <typename T>
std::string PackRange(const std::vector<T>& values, size_t begin, size_t end) {
  std::string bytes((end - begin) * sizeof(T), '\0');
  if (!bytes.empty()) std::memcpy(bytes.data(), values.data() + begin, bytes.size());
  return bytes;
}

}  // namespace

v1::PackedPoints PackPoints(const PointCloud& cloud, size_t begin, size_t end) {
  v1::PackedPoints packed;
  packed.set_positions(PackRange(cloud.positions, begin, end));
  if (!cloud.weights.empty()) packed.set_weights(PackRange(cloud.weights, begin, end));
  if (!cloud.normals.empty()) packed.set_normals(PackRange(cloud.normals, begin, end));
  if (!cloud.colors.empty()) packed.set_colors(PackRange(cloud.colors, begin, end));
  return packed;
}

v1::PointBatch PackPointBatch(const PointCloud& cloud, size_t begin, size_t end) {
  v1::PointBatch batch;
  batch.mutable_first_point()->set_value(begin);
  *batch.mutable_packed() = PackPoints(cloud, begin, end);
  return batch;
}

v1::PackedMesh PackMesh(const TriangleMesh& mesh) {
  v1::PackedMesh packed;
  packed.set_positions(PackRange(mesh.positions, 0, mesh.positions.size()));
  packed.set_faces(PackRange(mesh.faces, 0, mesh.faces.size()));
  return packed;
}

}  // namespace neuralmesh
