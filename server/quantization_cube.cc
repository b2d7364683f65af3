#include "server/quantization_cube.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace neuralmesh::server {
namespace {

bool IsFiniteBox(const QuantizationBox& box) {
  return std::isfinite(box.range) && std::isfinite(box.origin[0]) && std::isfinite(box.origin[1]) &&
         std::isfinite(box.origin[2]);
}

// DracoExactBox of a finite `box`, checked for Draco; the message names `bounds`.
absl::StatusOr<QuantizationBox> UsableCube(const QuantizationBox& box, int bits,
                                           const BoundingBox& bounds) {
  const auto refuse = [&](absl::string_view why) {
    return absl::InvalidArgumentError(
        absl::StrCat("points from (", bounds.min[0], ", ", bounds.min[1], ", ", bounds.min[2],
                     ") to (", bounds.max[0], ", ", bounds.max[1], ", ", bounds.max[2],
                     ") need a quantization cube that meshes cannot be encoded in: ", why));
  };
  if (!IsFiniteBox(box)) return refuse("it is larger than a float can hold");
  const QuantizationBox exact = DracoExactBox(box);
  if (absl::Status status = CheckQuantizationBox(exact, bits); !status.ok()) {
    return refuse(status.message());
  }
  return exact;
}

}  // namespace

bool CubeContains(const QuantizationBox& box, const BoundingBox& bounds) {
  for (int c = 0; c < 3; ++c) {
    if (bounds.min[c] < box.origin[c] || bounds.max[c] > double{box.origin[c]} + box.range) {
      return false;
    }
  }
  return true;
}

absl::StatusOr<QuantizationBox> QuantizationCube(const BoundingBox& bounds, double enlarge,
                                                 int bits) {
  const Vec3 center = bounds.center();
  double edge = 0;
  for (int c = 0; c < 3; ++c) edge = std::max(edge, bounds.max[c] - bounds.min[c]);
  edge = edge > 0 ? edge * enlarge : 1.0;
  QuantizationBox box;
  box.range = static_cast<float>(edge);
  for (int c = 0; c < 3; ++c) box.origin[c] = static_cast<float>(center[c] - edge / 2);
  // The box every update announces is the one Draco quantizes against.
  return UsableCube(box, bits, bounds);
}

absl::StatusOr<QuantizationBox> GrowQuantizationCube(QuantizationBox box, const BoundingBox& bounds,
                                                     int bits) {
  // Each doubling either contains `bounds` at last or brings the range nearer to infinity,
  // which ends the loop within 256 rounds.
  while (IsFiniteBox(box) && !CubeContains(box, bounds)) {
    for (int c = 0; c < 3; ++c) box.origin[c] -= box.range / 2;
    box.range *= 2;
  }
  return UsableCube(box, bits, bounds);
}

}  // namespace neuralmesh::server
