// An axis-aligned bounding box.
#ifndef NEURALMESH_CORE_BOUNDING_BOX_H_
#define NEURALMESH_CORE_BOUNDING_BOX_H_

#include <algorithm>
#include <limits>

#include "core/mesh.h"

namespace neuralmesh {

struct BoundingBox {
  Vec3 min{std::numeric_limits<double>::infinity()};
  Vec3 max{-std::numeric_limits<double>::infinity()};

  bool empty() const { return !(min[0] <= max[0]); }
  void Extend(const Vec3& p) {
    for (int i = 0; i < 3; ++i) {
      min[i] = std::min(min[i], p[i]);
      max[i] = std::max(max[i], p[i]);
    }
  }
  void Extend(const BoundingBox& b) {
    if (b.empty()) return;
    Extend(b.min);
    Extend(b.max);
  }
  Vec3 center() const { return (min + max) * 0.5; }
  double diagonal() const { return empty() ? 0.0 : (max - min).norm(); }
  bool Contains(const Vec3& p) const {
    return p[0] >= min[0] && p[0] <= max[0] && p[1] >= min[1] && p[1] <= max[1] &&
           p[2] >= min[2] && p[2] <= max[2];
  }
  // The squared distance from `p` to the box: 0 inside, infinity for an empty box.
  double SquaredDistance(const Vec3& p) const {
    if (empty()) return std::numeric_limits<double>::infinity();
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
      const double d = std::max({min[i] - p[i], 0.0, p[i] - max[i]});
      sum += d * d;
    }
    return sum;
  }
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_BOUNDING_BOX_H_
