// The smoothing half of the Basic Step (Section 2.1): C_L iterations of Laplacian smoothing in
// the tangential direction with rate alpha_L on the 1-ring of the winner. "The winner learns
// from the signal and then its neighborhood is smoothed": the winner itself is not smoothed,
// so its tangential move toward the sample (which drives the density adaptation of Section
// 3.1) is kept.
//
//   for each neighbour q of the winner, C_L times:
//     L = centroid(1-ring(q)) - q
//     q += alpha_L (L - (L . n_q) n_q)          n_q: area-weighted normal at q
//   a boundary neighbour moves along its border instead: L is projected on the direction
//   between its two boundary neighbours, so borders neither shrink nor fray.
// Normals are computed once per call (the moves are small). With the normals fixed, each
// update is affine in the positions:
//   q_i <- A_i q_i + G_i (sum of the moving neighbours of q_i) + c_i
//   A_i = I - alpha_L P_i,  G_i = alpha_L / count_i P_i,  c_i = G_i (sum of the others),
// P_i the tangential projection (I - n n^T, or t t^T along a border), count_i the number of
// neighbours the centroid averages. Only the ring vertices move, so the neighbours that are
// not in the ring (the winner, the second ring) fold into c_i once per call, and the C_L
// passes run on local copies of the ring's positions, in the same order as in place
// (Gauss-Seidel: each update sees the ones before it).
#ifndef NEURALMESH_CORE_LEARNING_TANGENTIAL_SMOOTHING_H_
#define NEURALMESH_CORE_LEARNING_TANGENTIAL_SMOOTHING_H_

#include <vector>

#include "core/huge_page_allocator.h"
#include "core/learning/vertex_ring_cache.h"
#include "core/mesh.h"

namespace neuralmesh {

class OneRingSmoother {
 public:
  // With `allow_simd`, the gather (normals, sums, update matrices) and the C_L passes run on
  // AVX2 when the CPU has it, with bitwise the same results as without (false is for tests
  // that compare the two).
  explicit OneRingSmoother(bool allow_simd = true);

  // Smooths the 1-ring of `winner`, reading rings through `rings` (which the caller keeps
  // up to date with the connectivity). The vertices it moved (indices) are in moved()
  // afterwards.
  void Smooth(Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle winner, double alpha_l,
              int iterations);
  const std::vector<int>& moved() const { return ring_; }
  // Whether the passes run on AVX2.
  bool simd() const { return simd_; }

  // The affine update of one vertex of the winner's 1-ring; 3x3 matrices stored by columns,
  // each padded to four lanes. (Public only for the scalar and SIMD passes in the .cc.)
  struct alignas(32) RingVertex {
    double own[3][4];        // A_i.
    double neighbour[3][4];  // G_i, applied to the moving neighbours other than q_{i-1}.
    double previous[3][4];   // G_i if q_{i-1} (just updated) is a neighbour, else zero.
    double offset[4];        // c_i.
    int first_moving;        // The other moving neighbours: moving_[first_moving, end_moving).
    int end_moving;
  };
  struct alignas(32) Position {
    double v[4];  // x, y, z, 0.
  };

 private:
  bool simd_;
  // Scratch storage reused across calls: the Basic Step allocates nothing.
  std::vector<int> ring_;
  std::vector<RingVertex> local_;       // Parallel to ring_.
  std::vector<Position> q_;             // Parallel to ring_: the positions being smoothed.
  std::vector<int> moving_;             // Slots in ring_.
  HugePageVector<int> slot_of_vertex_;  // By vertex index: the slot in ring_, or -1 (between calls:
                                        // all -1).
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_TANGENTIAL_SMOOTHING_H_
