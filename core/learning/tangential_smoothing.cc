#include "core/learning/tangential_smoothing.h"

#include <algorithm>
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
  const VertexRingCache::RingView winner_ring = rings.Ring(mesh, winner.idx());
  ring_.assign(winner_ring.neighbours, winner_ring.neighbours + winner_ring.size);
  if (alpha_l <= 0 || iterations <= 0) return;
  const int m = static_cast<int>(ring_.size());
  if (local_.size() < ring_.size()) local_.resize(ring_.size());

  // The points live in one contiguous array (an OpenMesh property); nothing below adds a
  // vertex, so the pointer stays valid.
  double* points = mesh.point(Mesh::VertexHandle(0)).data();
  auto at = [points](int v) { return points + 3 * static_cast<size_t>(v); };
  // slot_of_vertex_[v]: the slot of v in ring_, or -1 when v does not move.
  if (slot_of_vertex_.size() < mesh.n_vertices()) slot_of_vertex_.resize(mesh.n_vertices(), -1);
  for (int i = 0; i < m; ++i) {
    slot_of_vertex_[ring_[i]] = i;
    // On a large mesh these are cache misses; issued together they overlap.
    rings.Prefetch(ring_[i]);
    __builtin_prefetch(at(ring_[i]));
  }

  // Gathered once per call: each ring vertex's position, its normal (or border tangent), and
  // its neighbours split into those that stay put during the smoothing (the winner and the
  // second ring: summed here once) and those that move (other ring vertices).
  moving_.clear();
  for (int i = 0; i < m; ++i) {
    RingVertex& r = local_[i];
    const double* p = at(ring_[i]);
    for (int c = 0; c < 3; ++c) r.p[c] = p[c];
    const VertexRingCache::RingView view = rings.Ring(mesh, ring_[i]);
    const int32_t* neighbours = view.neighbours;
    int count = view.size;
    int32_t border_pair[2];
    double d[3];
    r.border = view.boundary;
    if (r.border) {
      // Only the two neighbours along the border count: b1 (the end of the outgoing boundary
      // half-edge) comes first in the ring, b0 (the start of the incoming one) last.
      border_pair[0] = neighbours[count - 1];
      border_pair[1] = neighbours[0];
      const double* p0 = at(border_pair[0]);
      const double* p1 = at(border_pair[1]);
      StoreUnit(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2], d);
      neighbours = border_pair;
      count = 2;
    } else {
      // Area-weighted normal: the sum of (a_k - q) x (a_k+1 - q) around the ring.
      const double* last = at(neighbours[count - 1]);
      double ax = last[0] - p[0], ay = last[1] - p[1], az = last[2] - p[2];
      double nx = 0, ny = 0, nz = 0;
      for (int k = 0; k < count; ++k) {
        const double* b = at(neighbours[k]);
        const double bx = b[0] - p[0], by = b[1] - p[1], bz = b[2] - p[2];
        nx += ay * bz - az * by;
        ny += az * bx - ax * bz;
        nz += ax * by - ay * bx;
        ax = bx;
        ay = by;
        az = bz;
      }
      StoreUnit(nx, ny, nz, d);
    }
    for (int c = 0; c < 3; ++c) r.direction[c] = d[c];
    r.inverse_count = 1.0 / static_cast<double>(count);

    // The tangential projection P (I - d d^T off the normal, d d^T along a border) and
    //   M = alpha_L / count * P,
    // the part of the update that is linear in the previous ring vertex (see below).
    const double scale = alpha_l * r.inverse_count;
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        const double along = d[a] * d[b];
        r.previous_weight[a][b] = scale * (r.border ? along : (a == b ? 1.0 : 0.0) - along);
      }
    }

    const int previous = i == 0 ? m - 1 : i - 1;
    r.has_previous = false;
    r.fixed_sum[0] = r.fixed_sum[1] = r.fixed_sum[2] = 0;
    r.first_moving = static_cast<int>(moving_.size());
    for (int k = 0; k < count; ++k) {
      const int u = neighbours[k];
      const int slot = slot_of_vertex_[u];
      if (slot == previous && m > 1) {
        r.has_previous = true;
      } else if (slot >= 0) {
        moving_.push_back(slot);
      } else {
        const double* q = at(u);
        for (int c = 0; c < 3; ++c) r.fixed_sum[c] += q[c];
      }
    }
    r.end_moving = static_cast<int>(moving_.size());
  }

  // C_L passes of Gauss-Seidel tangential smoothing in ring order (each update sees the ones
  // before it), on local copies of the positions:
  //   q_i += alpha_L P_i (centroid_i - q_i).
  // Vertex i - 1, just updated, is usually a neighbour of q_i; the update is split into
  //   K_i = q_i + alpha_L P_i ((sum of the other neighbours) / count - q_i)
  //   q_i = K_i + M_i q_{i-1},
  // so that only the short matrix product waits for q_{i-1}, not the whole projection: this
  // chain through the ring is what bounds the speed of the loop.
  for (int it = 0; it < iterations; ++it) {
    for (int i = 0; i < m; ++i) {
      RingVertex& r = local_[i];
      double sx = r.fixed_sum[0], sy = r.fixed_sum[1], sz = r.fixed_sum[2];
      for (int k = r.first_moving; k < r.end_moving; ++k) {
        const double* u = local_[moving_[k]].p;
        sx += u[0];
        sy += u[1];
        sz += u[2];
      }
      const double lx = sx * r.inverse_count - r.p[0];
      const double ly = sy * r.inverse_count - r.p[1];
      const double lz = sz * r.inverse_count - r.p[2];
      const double* d = r.direction;
      const double dot = lx * d[0] + ly * d[1] + lz * d[2];
      double tx, ty, tz;
      if (r.border) {  // Along the border tangent.
        tx = dot * d[0];
        ty = dot * d[1];
        tz = dot * d[2];
      } else {  // Off the normal.
        tx = lx - dot * d[0];
        ty = ly - dot * d[1];
        tz = lz - dot * d[2];
      }
      double kx = r.p[0] + alpha_l * tx;
      double ky = r.p[1] + alpha_l * ty;
      double kz = r.p[2] + alpha_l * tz;
      if (r.has_previous) {
        const double* u = local_[i == 0 ? m - 1 : i - 1].p;
        const double(*w)[3] = r.previous_weight;
        kx += w[0][0] * u[0] + w[0][1] * u[1] + w[0][2] * u[2];
        ky += w[1][0] * u[0] + w[1][1] * u[1] + w[1][2] * u[2];
        kz += w[2][0] * u[0] + w[2][1] * u[1] + w[2][2] * u[2];
      }
      r.p[0] = kx;
      r.p[1] = ky;
      r.p[2] = kz;
    }
  }
  for (int i = 0; i < m; ++i) {
    double* p = at(ring_[i]);
    for (int c = 0; c < 3; ++c) p[c] = local_[i].p[c];
    slot_of_vertex_[ring_[i]] = -1;
  }
}

}  // namespace neuralmesh
