#include "core/learning/tangential_smoothing.h"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "core/avx2_clone.h"

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

// Sorts the neighbours of one ring vertex q_i into those that move during the smoothing
// (other vertices of the winner's ring: their slots are appended to `moving`, except q_{i-1},
// which is only flagged) and those that stay put (the winner, the second ring).
struct NeighbourSorter {
  const int* slot_of_vertex;  // By vertex: the slot in the winner's ring, or -1.
  int* moving;
  int num_moving;
  int previous;  // The slot of q_{i-1}.
  bool has_previous;

  // Records neighbour u; returns whether it stays put.
  bool operator()(int u) {
    const int slot = slot_of_vertex[u];
    const bool is_previous = slot == previous;
    has_previous |= is_previous;
    moving[num_moving] = slot;
    num_moving += (slot >= 0) & !is_previous;
    return slot < 0;
  }
};

// The sums over the ring of an interior vertex p (neighbours b_k in rotation order): the
// area-weighted normal n = sum of (b_k-1 - p) x (b_k - p), and f = the sum of the neighbours
// that `sorter` finds stay put. The scalar and the AVX2 versions evaluate the same expressions
// in the same order (the AVX2 one with x, y, z in three lanes), so they give bitwise the same
// sums. (Both work on a local copy of the sorter, which the compiler keeps in registers.)
void InteriorSumsScalar(const double* points, const double* p, const int32_t* neighbours,
                        int count, NeighbourSorter& shared_sorter, double n[3], double f[3]) {
  NeighbourSorter sorter = shared_sorter;
  const double* last = points + 3 * static_cast<size_t>(neighbours[count - 1]);
  double ax = last[0] - p[0], ay = last[1] - p[1], az = last[2] - p[2];
  double nx = 0, ny = 0, nz = 0, fx = 0, fy = 0, fz = 0;
  for (int k = 0; k < count; ++k) {
    const int u = neighbours[k];
    const double* b = points + 3 * static_cast<size_t>(u);
    const double bx = b[0] - p[0], by = b[1] - p[1], bz = b[2] - p[2];
    nx += ay * bz - az * by;
    ny += az * bx - ax * bz;
    nz += ax * by - ay * bx;
    ax = bx;
    ay = by;
    az = bz;
    const double stays = sorter(u) ? 1.0 : 0.0;
    fx += stays * b[0];
    fy += stays * b[1];
    fz += stays * b[2];
  }
  shared_sorter = sorter;
  n[0] = nx;
  n[1] = ny;
  n[2] = nz;
  f[0] = fx;
  f[1] = fy;
  f[2] = fz;
}

#if defined(__x86_64__)
__attribute__((target("avx2"))) void InteriorSumsAvx2(const double* points, const double* p,
                                                      const int32_t* neighbours, int count,
                                                      NeighbourSorter& shared_sorter,
                                                      double n[3], double f[3]) {
  NeighbourSorter sorter = shared_sorter;
  // Positions are three doubles: loaded into lanes 0-2, lane 3 zero and never read from memory.
  const __m256i xyz = _mm256_set_epi64x(0, -1, -1, -1);
  constexpr int kYzx = _MM_SHUFFLE(3, 0, 2, 1);  // (x, y, z, w) -> (y, z, x, w).
  const __m256d pv = _mm256_maskload_pd(p, xyz);
  __m256d a = _mm256_sub_pd(
      _mm256_maskload_pd(points + 3 * static_cast<size_t>(neighbours[count - 1]), xyz), pv);
  __m256d a_yzx = _mm256_permute4x64_pd(a, kYzx);
  // Lanes of `cross`: (nz, nx, ny) terms: ax by - ay bx, ay bz - az by, az bx - ax bz.
  __m256d cross = _mm256_setzero_pd();
  __m256d stay = _mm256_setzero_pd();
  for (int k = 0; k < count; ++k) {
    const int u = neighbours[k];
    const __m256d b_raw = _mm256_maskload_pd(points + 3 * static_cast<size_t>(u), xyz);
    const __m256d b = _mm256_sub_pd(b_raw, pv);
    const __m256d b_yzx = _mm256_permute4x64_pd(b, kYzx);
    cross = _mm256_add_pd(cross, _mm256_sub_pd(_mm256_mul_pd(a, b_yzx), _mm256_mul_pd(a_yzx, b)));
    a = b;
    a_yzx = b_yzx;
    // b_raw or +0 by a mask, not 1 or 0 times b_raw, which compiles to a branch that
    // mispredicts: the same sums, as adding -0 or +0 to a sum that starts at +0 is the same.
    const __m256d keep = _mm256_castsi256_pd(_mm256_set1_epi64x(-int64_t{sorter(u)}));
    stay = _mm256_add_pd(stay, _mm256_and_pd(keep, b_raw));
  }
  shared_sorter = sorter;
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, _mm256_permute4x64_pd(cross, kYzx));
  n[0] = lanes[0];
  n[1] = lanes[1];
  n[2] = lanes[2];
  _mm256_store_pd(lanes, stay);
  f[0] = lanes[0];
  f[1] = lanes[1];
  f[2] = lanes[2];
}
#else
void InteriorSumsAvx2(const double* points, const double* p, const int32_t* neighbours, int count,
                      NeighbourSorter& sorter, double n[3], double f[3]) {
  InteriorSumsScalar(points, p, neighbours, count, sorter, n, f);
}
#endif

// The affine update of one ring vertex (tangential_smoothing.h): P = I - d d^T off the
// normal d, or d d^T along a border direction d; A = I - alpha_L P, G = scale P (scale =
// alpha_L / count), G again for q_{i-1} if `previous_on` is 1 (zero if 0), and c = G f.
// The AVX2 version computes, lane by lane, the same expressions in the same order.
void BuildUpdateScalar(const double d[3], bool border, double alpha_l, double scale,
                       double previous_on, const double f[3], OneRingSmoother::RingVertex& r) {
  const double identity = border ? 0.0 : 1.0;
  const double sign = border ? 1.0 : -1.0;
  // P is symmetric (d[row] * d[col] == d[col] * d[row] exactly): six distinct entries. The
  // loops are unrolled so that no element tests its row and column at run time. (0.0 + x is
  // kept: it turns -0 into +0, as the formula does.)
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
    r.offset[row] = (r.neighbour[0][row] * f[0] + r.neighbour[1][row] * f[1]) +
                    r.neighbour[2][row] * f[2];
  }
  r.offset[3] = 0;
}

#if defined(__x86_64__)
__attribute__((target("avx2"))) void BuildUpdateAvx2(const double d[3], bool border,
                                                     double alpha_l, double scale,
                                                     double previous_on, const double f[3],
                                                     OneRingSmoother::RingVertex& r) {
  // Row `col` is the unit vector of lane `col` (a blend with a run-time mask would not compile
  // with clang, which wants the mask to be a constant).
  alignas(32) static constexpr double kUnit[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
  const __m256d zero = _mm256_setzero_pd();
  const __m256d sign = _mm256_set1_pd(border ? 1.0 : -1.0);
  const __m256d dv = _mm256_set_pd(0.0, d[2], d[1], d[0]);
  const __m256d alpha = _mm256_set1_pd(alpha_l);
  const __m256d g = _mm256_set1_pd(scale);
  const __m256d previous = _mm256_set1_pd(previous_on);
  __m256d columns[3];
#pragma GCC unroll 3
  for (int col = 0; col < 3; ++col) {
    const __m256d unit = _mm256_load_pd(kUnit[col]);  // 1.0 on the diagonal's lane.
    // Lane `row`: (identity on the diagonal, else 0.0) + sign * (d[row] * d[col]).
    const __m256d proj =
        _mm256_add_pd(border ? zero : unit,
                      _mm256_mul_pd(sign, _mm256_mul_pd(dv, _mm256_set1_pd(d[col]))));
    const __m256d neighbour = _mm256_mul_pd(g, proj);
    // Lane 3 of proj is +0, so every matrix gets +0 there, as the scalar version writes.
    _mm256_store_pd(r.own[col],
                    _mm256_sub_pd(unit, _mm256_mul_pd(alpha, proj)));
    _mm256_store_pd(r.neighbour[col], neighbour);
    _mm256_store_pd(r.previous[col], _mm256_mul_pd(previous, neighbour));
    columns[col] = neighbour;
  }
  const __m256d offset = _mm256_add_pd(
      _mm256_add_pd(_mm256_mul_pd(columns[0], _mm256_set1_pd(f[0])),
                    _mm256_mul_pd(columns[1], _mm256_set1_pd(f[1]))),
      _mm256_mul_pd(columns[2], _mm256_set1_pd(f[2])));
  _mm256_store_pd(r.offset, _mm256_blend_pd(offset, zero, 8));  // Lane 3: +0.
}
#else
void BuildUpdateAvx2(const double d[3], bool border, double alpha_l, double scale,
                     double previous_on, const double f[3], OneRingSmoother::RingVertex& r) {
  BuildUpdateScalar(d, border, alpha_l, scale, previous_on, f, r);
}
#endif

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

// Compiled for AVX2 and for the baseline (avx2_clone.h): what is left of the gather's scalar
// arithmetic takes fewer instructions in its AVX2 build (three-operand forms, the passes
// inlined; 5% fewer per Basic Step). No fused multiply-adds in either (core/CMakeLists.txt),
// so both give bitwise the same positions.
NEURALMESH_AVX2_CLONE void OneRingSmoother::Smooth(Mesh& mesh, VertexRingCache& rings,
                                                   Mesh::VertexHandle winner, double alpha_l,
                                                   int iterations) {
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
    r.first_moving = num_moving;
    NeighbourSorter sorter{slot_of_vertex_.data(), moving_.data(), num_moving,
                           m > 1 ? (i == 0 ? m - 1 : i - 1) : -2, false};  // -2: no slot.
    double f[3] = {0, 0, 0};  // The sum of the neighbours that stay put.
    double d[3];
    int count;
    const bool border = view.boundary;
    if (border) {
      // Only the two neighbours along the border count: b1 (the end of the outgoing boundary
      // half-edge) comes first in the ring, b0 (the start of the incoming one) last.
      const int b0 = view.neighbours[view.size - 1];
      const int b1 = view.neighbours[0];
      for (const int u : {b0, b1}) {
        const double* b = at(u);
        const double stays = sorter(u) ? 1.0 : 0.0;
        for (int c = 0; c < 3; ++c) f[c] += stays * b[c];
      }
      const double* p0 = at(b0);
      const double* p1 = at(b1);
      StoreUnit(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2], d);
      count = 2;
    } else {
      count = view.size;
      double n[3];
      if (simd_) {
        InteriorSumsAvx2(points, p, view.neighbours, count, sorter, n, f);
      } else {
        InteriorSumsScalar(points, p, view.neighbours, count, sorter, n, f);
      }
      StoreUnit(n[0], n[1], n[2], d);
    }
    num_moving = sorter.num_moving;
    r.end_moving = num_moving;

    const double scale = alpha_l / static_cast<double>(count);
    const double previous_on = sorter.has_previous ? 1.0 : 0.0;
    if (simd_) {
      BuildUpdateAvx2(d, border, alpha_l, scale, previous_on, f, r);
    } else {
      BuildUpdateScalar(d, border, alpha_l, scale, previous_on, f, r);
    }
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
