#include "core/learning/tangential_smoothing.h"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

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

// The C_L passes in ring order. Only the product with q_{i-1}, carried in registers from the
// update before, waits for that update: this chain through the ring is what bounds the speed
// of the loop, so it is kept one product and two sums deep.
//
// Both versions below evaluate the same expressions in the same order (the AVX2 one four lanes
// at a time, the fourth lane unused), and the file is compiled without contraction into fused
// multiply-adds (core/CMakeLists.txt), so they give bitwise the same positions: a seed gives
// the same mesh whichever one the CPU runs.
void SmoothPassesScalar(const OneRingSmoother::RingVertex* ring, OneRingSmoother::Position* q,
                        const int* moving, int m, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    double px = q[m - 1].v[0], py = q[m - 1].v[1], pz = q[m - 1].v[2];
    for (int i = 0; i < m; ++i) {
      const OneRingSmoother::RingVertex& r = ring[i];
      double* qi = q[i].v;
      double sx = 0, sy = 0, sz = 0;
      for (int k = r.first_moving; k < r.end_moving; ++k) {
        const double* u = q[moving[k]].v;
        sx += u[0];
        sy += u[1];
        sz += u[2];
      }
      double next[3];
      for (int c = 0; c < 3; ++c) {
        const double t =
            ((r.own[0][c] * qi[0] + r.own[1][c] * qi[1]) + r.own[2][c] * qi[2]) +
            (((r.neighbour[0][c] * sx + r.neighbour[1][c] * sy) + r.neighbour[2][c] * sz) +
             r.offset[c]);
        next[c] = (r.previous[0][c] * px + r.previous[1][c] * py) + (r.previous[2][c] * pz + t);
      }
      px = qi[0] = next[0];
      py = qi[1] = next[1];
      pz = qi[2] = next[2];
    }
  }
}

#if defined(__x86_64__)
__attribute__((target("avx2"))) void SmoothPassesAvx2(const OneRingSmoother::RingVertex* ring,
                                                      OneRingSmoother::Position* q,
                                                      const int* moving, int m, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    __m256d previous = _mm256_load_pd(q[m - 1].v);
    for (int i = 0; i < m; ++i) {
      const OneRingSmoother::RingVertex& r = ring[i];
      double* qi = q[i].v;
      __m256d sx = _mm256_setzero_pd(), sy = sx, sz = sx;
      for (int k = r.first_moving; k < r.end_moving; ++k) {
        const double* u = q[moving[k]].v;
        sx = _mm256_add_pd(sx, _mm256_broadcast_sd(u));
        sy = _mm256_add_pd(sy, _mm256_broadcast_sd(u + 1));
        sz = _mm256_add_pd(sz, _mm256_broadcast_sd(u + 2));
      }
      const __m256d own = _mm256_add_pd(
          _mm256_add_pd(_mm256_mul_pd(_mm256_load_pd(r.own[0]), _mm256_broadcast_sd(qi)),
                        _mm256_mul_pd(_mm256_load_pd(r.own[1]), _mm256_broadcast_sd(qi + 1))),
          _mm256_mul_pd(_mm256_load_pd(r.own[2]), _mm256_broadcast_sd(qi + 2)));
      const __m256d others = _mm256_add_pd(
          _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_load_pd(r.neighbour[0]), sx),
                                      _mm256_mul_pd(_mm256_load_pd(r.neighbour[1]), sy)),
                        _mm256_mul_pd(_mm256_load_pd(r.neighbour[2]), sz)),
          _mm256_load_pd(r.offset));
      const __m256d t = _mm256_add_pd(own, others);
      const __m256d px = _mm256_permute4x64_pd(previous, 0x00);
      const __m256d py = _mm256_permute4x64_pd(previous, 0x55);
      const __m256d pz = _mm256_permute4x64_pd(previous, 0xaa);
      previous = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_load_pd(r.previous[0]), px),
                                             _mm256_mul_pd(_mm256_load_pd(r.previous[1]), py)),
                               _mm256_add_pd(_mm256_mul_pd(_mm256_load_pd(r.previous[2]), pz), t));
      _mm256_store_pd(qi, previous);
    }
  }
}

bool CpuHasAvx2() { return __builtin_cpu_supports("avx2"); }
#else
void SmoothPassesAvx2(const OneRingSmoother::RingVertex* ring, OneRingSmoother::Position* q,
                      const int* moving, int m, int iterations) {
  SmoothPassesScalar(ring, q, moving, m, iterations);
}

bool CpuHasAvx2() { return false; }
#endif

}  // namespace

OneRingSmoother::OneRingSmoother(bool allow_simd) : simd_(allow_simd && CpuHasAvx2()) {}

void OneRingSmoother::Smooth(Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle winner,
                             double alpha_l, int iterations) {
  const VertexRingCache::RingView winner_ring = rings.Ring(mesh, winner.idx());
  ring_.assign(winner_ring.neighbours, winner_ring.neighbours + winner_ring.size);
  if (alpha_l <= 0 || iterations <= 0) return;
  const int m = static_cast<int>(ring_.size());
  if (local_.size() < ring_.size()) {
    local_.resize(ring_.size());
    q_.resize(ring_.size());
  }

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
  // second ring: summed into c_i) and those that move (other ring vertices). One pass over
  // the neighbours does both, without branches on the kind of neighbour: which neighbour is
  // the winner or a ring vertex changes from one ring vertex to the next, and mispredicted
  // branches cost more here than the arithmetic.
  int num_moving = 0;
  for (int i = 0; i < m; ++i) {
    RingVertex& r = local_[i];
    const double* p = at(ring_[i]);
    double* q = q_[i].v;
    q[0] = p[0];
    q[1] = p[1];
    q[2] = p[2];
    q[3] = 0;
    const VertexRingCache::RingView view = rings.Ring(mesh, ring_[i]);
    if (moving_.size() < static_cast<size_t>(num_moving + view.size)) {
      moving_.resize(2 * static_cast<size_t>(num_moving + view.size));
    }
    const int previous = m > 1 ? (i == 0 ? m - 1 : i - 1) : -2;  // -2: matches no slot.
    r.first_moving = num_moving;
    bool has_previous = false;
    double fx = 0, fy = 0, fz = 0;  // The sum of the neighbours that stay put.
    auto classify = [&](int u, const double* b) {
      const int slot = slot_of_vertex_[u];
      const bool is_previous = slot == previous;
      const double stays = slot < 0 ? 1.0 : 0.0;
      has_previous |= is_previous;
      fx += stays * b[0];
      fy += stays * b[1];
      fz += stays * b[2];
      moving_[num_moving] = slot;
      num_moving += (slot >= 0) & !is_previous;
    };
    double d[3];
    int count;
    const bool border = view.boundary;
    if (border) {
      // Only the two neighbours along the border count: b1 (the end of the outgoing boundary
      // half-edge) comes first in the ring, b0 (the start of the incoming one) last.
      const int b0 = view.neighbours[view.size - 1];
      const int b1 = view.neighbours[0];
      const double* p0 = at(b0);
      const double* p1 = at(b1);
      classify(b0, p0);
      classify(b1, p1);
      StoreUnit(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2], d);
      count = 2;
    } else {
      // Area-weighted normal: the sum of (a_k - q) x (a_k+1 - q) around the ring.
      count = view.size;
      const double* last = at(view.neighbours[count - 1]);
      double ax = last[0] - p[0], ay = last[1] - p[1], az = last[2] - p[2];
      double nx = 0, ny = 0, nz = 0;
      for (int k = 0; k < count; ++k) {
        const int u = view.neighbours[k];
        const double* b = at(u);
        const double bx = b[0] - p[0], by = b[1] - p[1], bz = b[2] - p[2];
        nx += ay * bz - az * by;
        ny += az * bx - ax * bz;
        nz += ax * by - ay * bx;
        ax = bx;
        ay = by;
        az = bz;
        classify(u, b);
      }
      StoreUnit(nx, ny, nz, d);
    }
    r.end_moving = num_moving;

    // P = I - d d^T off the normal, d d^T along a border; A = I - alpha_L P and
    // G = alpha_L / count P, and G again for q_{i-1} when it is a neighbour.
    const double scale = alpha_l / static_cast<double>(count);
    const double identity = border ? 0.0 : 1.0;
    const double sign = border ? 1.0 : -1.0;
    const double previous_on = has_previous ? 1.0 : 0.0;
    // P is symmetric (d[row] * d[col] == d[col] * d[row] exactly): six distinct entries. The
    // loops are unrolled so that no element tests its row and column at run time: built
    // element by element, the matrices took more instructions than the rest of the gather.
    // (0.0 + x is kept: it turns -0 into +0, as the formula does.)
    const double p00 = identity + sign * (d[0] * d[0]);
    const double p11 = identity + sign * (d[1] * d[1]);
    const double p22 = identity + sign * (d[2] * d[2]);
    const double p01 = 0.0 + sign * (d[1] * d[0]);
    const double p02 = 0.0 + sign * (d[2] * d[0]);
    const double p12 = 0.0 + sign * (d[2] * d[1]);
    const double proj[3][4] = {{p00, p01, p02, 0}, {p01, p11, p12, 0}, {p02, p12, p22, 0}};
#pragma GCC unroll 3
    for (int col = 0; col < 3; ++col) {
#pragma GCC unroll 4
      for (int row = 0; row < 4; ++row) {
        const double diagonal = row == col ? 1.0 : 0.0;
        r.own[col][row] = row < 3 ? diagonal - alpha_l * proj[col][row] : 0.0;
        r.neighbour[col][row] = scale * proj[col][row];
        r.previous[col][row] = previous_on * r.neighbour[col][row];
      }
    }
    for (int row = 0; row < 3; ++row) {
      r.offset[row] =
          (r.neighbour[0][row] * fx + r.neighbour[1][row] * fy) + r.neighbour[2][row] * fz;
    }
    r.offset[3] = 0;
  }

  if (simd_) {
    SmoothPassesAvx2(local_.data(), q_.data(), moving_.data(), m, iterations);
  } else {
    SmoothPassesScalar(local_.data(), q_.data(), moving_.data(), m, iterations);
  }
  for (int i = 0; i < m; ++i) {
    double* p = at(ring_[i]);
    for (int c = 0; c < 3; ++c) p[c] = q_[i].v[c];
    slot_of_vertex_[ring_[i]] = -1;
  }
}

}  // namespace neuralmesh
