// Draco encoding (core/io/draco_codec.h) of any mesh and point cloud, with any options: what
// the server does with every learned mesh (whatever scale the client's points have) and the CLI
// with every .drc it writes. The input's first bytes choose the options, the rest are float
// positions (any bits: tiny, huge, non-finite) and 16-bit face indices. Properties:
//  - EncodeMesh and EncodePointCloud return OK or INVALID_ARGUMENT with a message, and never
//    crash, whatever the scale of the positions;
//  - what they encode decodes: a cloud to as many points, and every decoded position lies
//    within half a quantization step of an input position (of a point, or of a vertex of a
//    proper face for a mesh: Edgebreaker drops the rest).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/io/draco_codec.h"
#include "core/point_cloud.h"
#include "core/triangle_mesh.h"
#include "fuzz/fuzz_check.h"

namespace {

using neuralmesh::DracoOptions;
using neuralmesh::kMaxQuantizationBits;
using neuralmesh::PointCloud;
using neuralmesh::QuantizationBox;
using neuralmesh::TriangleMesh;
using neuralmesh::Vec3f;

// Reads the input front to back; past its end every read gives zeros.
class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  template <typename T>
  T Read() {
    T value{};
    const size_t n = std::min(sizeof(T), size_ - std::min(size_, offset_));
    if (n > 0) std::memcpy(&value, data_ + offset_, n);
    offset_ += sizeof(T);
    return value;
  }
  size_t remaining() const { return offset_ < size_ ? size_ - offset_ : 0; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t offset_ = 0;
};

void CheckFailure(const absl::Status& status) {
  FUZZ_CHECK(status.code() == absl::StatusCode::kInvalidArgument && !status.message().empty(),
             "encoding failed with %s", status.ToString().c_str());
}

// Half a grid step of the quantization, with slack for Draco's float arithmetic (its
// dequantization adds q * step to the origin in float). A fixed box's grid is the box as Draco
// reads it (six decimals), which may be coarser than the one given.
float Tolerance(const std::vector<Vec3f>& positions, const DracoOptions& options) {
  float range = 0, magnitude = 0;
  if (options.quantization_box.has_value()) {
    const QuantizationBox box = neuralmesh::BoxAsDracoReadsIt(*options.quantization_box);
    range = box.range;
    for (int c = 0; c < 3; ++c) magnitude = std::max(magnitude, std::abs(box.origin[c]));
  } else {
    for (int c = 0; c < 3; ++c) {
      float lo = positions[0][c], hi = positions[0][c];
      for (const Vec3f& p : positions) lo = std::min(lo, p[c]), hi = std::max(hi, p[c]);
      range = std::max(range, hi - lo);
      magnitude = std::max({magnitude, std::abs(lo), std::abs(hi)});
    }
  }
  const double step = range / (std::ldexp(1.0, options.position_quantization_bits) - 1.0);
  const double slack = 8.0 * std::numeric_limits<float>::epsilon() * (magnitude + range);
  return static_cast<float>(0.5 * step * (1 + 1e-5) + slack) + std::numeric_limits<float>::min();
}

bool Near(const Vec3f& p, const std::vector<Vec3f>& candidates, float tolerance) {
  for (const Vec3f& q : candidates) {
    if (std::abs(p[0] - q[0]) <= tolerance && std::abs(p[1] - q[1]) <= tolerance &&
        std::abs(p[2] - q[2]) <= tolerance) {
      return true;
    }
  }
  return false;
}

void CheckMesh(const TriangleMesh& mesh, const DracoOptions& options) {
  const absl::StatusOr<std::string> bytes = neuralmesh::EncodeMesh(mesh, options);
  if (!bytes.ok()) return CheckFailure(bytes.status());
  const absl::StatusOr<TriangleMesh> decoded = neuralmesh::DecodeMesh(*bytes);
  FUZZ_CHECK(decoded.ok(), "an encoded mesh does not decode: %s",
             decoded.status().ToString().c_str());
  std::vector<Vec3f> used;
  for (const auto& f : mesh.faces) {
    if (f[0] == f[1] || f[1] == f[2] || f[2] == f[0]) continue;
    for (uint32_t v : f) used.push_back(mesh.positions[v]);
  }
  const float tolerance = Tolerance(mesh.positions, options);
  for (const Vec3f& p : decoded->positions) {
    FUZZ_CHECK(Near(p, used, tolerance), "decoded vertex (%g, %g, %g) is no input vertex (+- %g)",
               p[0], p[1], p[2], tolerance);
  }
}

void CheckPointCloud(const PointCloud& cloud, const DracoOptions& options) {
  const absl::StatusOr<std::string> bytes = neuralmesh::EncodePointCloud(cloud, options);
  if (!bytes.ok()) return CheckFailure(bytes.status());
  const absl::StatusOr<PointCloud> decoded = neuralmesh::DecodePointCloud(*bytes);
  FUZZ_CHECK(decoded.ok(), "an encoded cloud does not decode: %s",
             decoded.status().ToString().c_str());
  FUZZ_CHECK(decoded->size() == cloud.size(), "%zu points encoded, %zu decoded", cloud.size(),
             decoded->size());
  FUZZ_CHECK(decoded->normals.size() == cloud.normals.size() &&
                 decoded->weights.size() == cloud.weights.size(),
             "normals or weights lost");
  const float tolerance = Tolerance(cloud.positions, options);
  for (const Vec3f& p : decoded->positions) {
    FUZZ_CHECK(Near(p, cloud.positions, tolerance),
               "decoded point (%g, %g, %g) is no input point (+- %g)", p[0], p[1], p[2], tolerance);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ByteReader in(data, size);
  DracoOptions options;
  // One bit past the maximum, to check that it is rejected.
  options.position_quantization_bits = 1 + in.Read<uint8_t>() % (kMaxQuantizationBits + 1);
  options.normal_quantization_bits = 2 + in.Read<uint8_t>() % kMaxQuantizationBits;
  options.weight_quantization_bits = 1 + in.Read<uint8_t>() % (kMaxQuantizationBits + 1);
  options.encode_speed = in.Read<uint8_t>() % 11;
  options.decode_speed = in.Read<uint8_t>() % 11;
  const uint8_t flags = in.Read<uint8_t>();
  options.shrink_small_meshes = (flags & 1) != 0;
  if ((flags & 2) != 0) {
    QuantizationBox box;
    for (int c = 0; c < 3; ++c) box.origin[c] = in.Read<float>();
    box.range = in.Read<float>();
    options.quantization_box = box;
  }
  const size_t num_points = 1 + in.Read<uint8_t>() % 64;
  PointCloud cloud;
  for (size_t i = 0; i < num_points; ++i) {
    Vec3f p;
    for (int c = 0; c < 3; ++c) p[c] = in.Read<float>();
    cloud.positions.push_back(p);
  }
  if ((flags & 4) != 0) {
    for (size_t i = 0; i < num_points; ++i) {
      Vec3f n;
      for (int c = 0; c < 3; ++c) n[c] = in.Read<float>();
      cloud.normals.push_back(n);
    }
  }
  if ((flags & 8) != 0) {
    for (size_t i = 0; i < num_points; ++i) cloud.weights.push_back(in.Read<float>());
  }
  if ((flags & 16) != 0) {
    // The server's way: a cube around the data, enlarged a little, computed in double.
    double lo[3], hi[3], edge = 0;
    for (int c = 0; c < 3; ++c) {
      lo[c] = hi[c] = cloud.positions[0][c];
      for (const Vec3f& p : cloud.positions) lo[c] = std::min<double>(lo[c], p[c]);
      for (const Vec3f& p : cloud.positions) hi[c] = std::max<double>(hi[c], p[c]);
      edge = std::max(edge, hi[c] - lo[c]);
    }
    edge = edge > 0 ? edge * 1.1 : 1.0;
    QuantizationBox box;
    box.range = static_cast<float>(edge);
    for (int c = 0; c < 3; ++c) box.origin[c] = static_cast<float>((lo[c] + hi[c] - edge) / 2);
    options.quantization_box = box;
  }
  TriangleMesh mesh;
  mesh.positions = cloud.positions;
  while (in.remaining() >= 6) {
    std::array<uint32_t, 3> face;
    for (uint32_t& v : face) v = in.Read<uint16_t>() % num_points;
    mesh.faces.push_back(face);
  }
  CheckPointCloud(cloud, options);
  CheckMesh(mesh, options);
  return 0;
}
