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

// Appends elements [begin, end) of `values` to `bytes`, as PackRange packs them.
template <typename T>
void AppendRange(const std::vector<T>& values, size_t begin, size_t end, std::string* bytes) {
  bytes->append(reinterpret_cast<const char*>(values.data() + begin), (end - begin) * sizeof(T));
}

}  // namespace

v1::PackedPoints PackPoints(const PointCloud& cloud, size_t begin, size_t end) {
  v1::PackedPoints packed;
  AppendPackedPoints(cloud, begin, end, &packed);
  return packed;
}

void AppendPackedPoints(const PointCloud& cloud, size_t begin, size_t end,
                        v1::PackedPoints* packed) {
  AppendRange(cloud.positions, begin, end, packed->mutable_positions());
  if (!cloud.weights.empty()) AppendRange(cloud.weights, begin, end, packed->mutable_weights());
  if (!cloud.normals.empty()) AppendRange(cloud.normals, begin, end, packed->mutable_normals());
  if (!cloud.colors.empty()) AppendRange(cloud.colors, begin, end, packed->mutable_colors());
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
