#include "core/learning/tangential_smoothing.h"

#include <cmath>

namespace neuralmesh {
namespace {

// Normalises (x, y, z) into out[0..2], or writes zeros for a zero vector.
void StoreUnit(double x, double y, double z, double* out) {
  const double len = std::sqrt(x * x + y * y + z * z);
  const double inv = len > 0 ? 1.0 / len : 0.0;
  out[0] = x * inv;
  out[1] = y * inv;
  out[2] = z * inv;
}

}  // namespace

void OneRingSmoother::Smooth(Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle winner,
                             double alpha_l, int iterations) {
  ring_.clear();
  offsets_.clear();
  neighbours_.clear();
  direction_.clear();
  on_border_.clear();
  rings.AppendRing(mesh, winner.idx(), ring_);
  if (alpha_l <= 0 || iterations <= 0) return;

  // The points live in one contiguous array (an OpenMesh property); nothing below adds a
  // vertex, so the pointer stays valid.
  double* points = mesh.point(Mesh::VertexHandle(0)).data();
  auto at = [points](int v) { return points + 3 * static_cast<size_t>(v); };

  // Gather each ring vertex's neighbours once, and its normal (or border tangent).
  for (const int q : ring_) {
    const int first = static_cast<int>(neighbours_.size());
    offsets_.push_back(first);
    const bool border = rings.AppendRing(mesh, q, neighbours_);
    on_border_.push_back(border);
    direction_.resize(direction_.size() + 3);
    double* dir = direction_.data() + direction_.size() - 3;
    if (border) {
      // Only the two neighbours along the border count: b1 (the end of the outgoing boundary
      // half-edge) comes first in the ring, b0 (the start of the incoming one) last.
      const int b1 = neighbours_[first];
      const int b0 = neighbours_.back();
      neighbours_.resize(first);
      neighbours_.push_back(b0);
      neighbours_.push_back(b1);
      const double* p0 = at(b0);
      const double* p1 = at(b1);
      StoreUnit(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2], dir);
      continue;
    }
    const int count = static_cast<int>(neighbours_.size()) - first;
    const double* p = at(q);
    double nx = 0, ny = 0, nz = 0;
    for (int i = 0; i < count; ++i) {
      const double* a = at(neighbours_[first + i]);
      const double* b = at(neighbours_[first + (i + 1 == count ? 0 : i + 1)]);
      const double ax = a[0] - p[0], ay = a[1] - p[1], az = a[2] - p[2];
      const double bx = b[0] - p[0], by = b[1] - p[1], bz = b[2] - p[2];
      nx += ay * bz - az * by;
      ny += az * bx - ax * bz;
      nz += ax * by - ay * bx;
    }
    StoreUnit(nx, ny, nz, dir);
  }
  offsets_.push_back(static_cast<int>(neighbours_.size()));

  const size_t m = ring_.size();
  for (int it = 0; it < iterations; ++it) {
    for (size_t i = 0; i < m; ++i) {
      const int begin = offsets_[i], end = offsets_[i + 1];
      double cx = 0, cy = 0, cz = 0;
      for (int k = begin; k < end; ++k) {
        const double* u = at(neighbours_[k]);
        cx += u[0];
        cy += u[1];
        cz += u[2];
      }
      double* p = at(ring_[i]);
      const double inv = 1.0 / (end - begin);
      const double lx = cx * inv - p[0], ly = cy * inv - p[1], lz = cz * inv - p[2];
      const double* d = direction_.data() + 3 * i;
      const double dot = lx * d[0] + ly * d[1] + lz * d[2];
      double tx, ty, tz;
      if (on_border_[i]) {  // Along the border tangent.
        tx = dot * d[0];
        ty = dot * d[1];
        tz = dot * d[2];
      } else {  // Off the normal.
        tx = lx - dot * d[0];
        ty = ly - dot * d[1];
        tz = lz - dot * d[2];
      }
      p[0] += alpha_l * tx;
      p[1] += alpha_l * ty;
      p[2] += alpha_l * tz;
    }
  }
}

}  // namespace neuralmesh
