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
// Normals are computed once per call (the moves are small). Only the ring vertices move, so the
// neighbours of a ring vertex that are not in the ring (the winner, the second ring) are summed
// once per call, and the C_L passes read and write local copies of the ring's positions (in
// the same order as in place: Gauss-Seidel, each update sees the ones before it). The
// arithmetic is written on raw coordinates: OpenMesh's vector temporaries cost several times
// more in this, the hottest loop.
#ifndef NEURALMESH_CORE_LEARNING_TANGENTIAL_SMOOTHING_H_
#define NEURALMESH_CORE_LEARNING_TANGENTIAL_SMOOTHING_H_

#include <vector>

#include "core/learning/vertex_ring_cache.h"
#include "core/mesh.h"

namespace neuralmesh {

class OneRingSmoother {
 public:
  // Smooths the 1-ring of `winner`, reading rings through `rings` (which the caller keeps
  // up to date with the connectivity). The vertices it moved (indices) are in moved()
  // afterwards.
  void Smooth(Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle winner, double alpha_l,
              int iterations);
  const std::vector<int>& moved() const { return ring_; }

 private:
  // A vertex of the winner's 1-ring while it is smoothed.
  struct RingVertex {
    double p[3];          // Its position, written back to the mesh at the end.
    double direction[3];  // Unit normal, or unit border tangent.
    double fixed_sum[3];  // The sum of its neighbours that do not move.
    double previous_weight[3][3];  // M: how its update depends on the previous ring vertex.
    double inverse_count;  // 1 / the number of neighbours its centroid averages.
    int first_moving;      // Its other neighbours that move: moving_[first_moving, end_moving).
    int end_moving;
    bool has_previous;  // Whether the previous ring vertex is one of its neighbours.
    bool border;
  };
  // Scratch storage reused across calls: the Basic Step allocates nothing.
  std::vector<int> ring_;
  std::vector<RingVertex> local_;  // Parallel to ring_.
  std::vector<int> moving_;        // Slots in ring_.
  std::vector<int> slot_of_vertex_;  // By vertex index: the slot in ring_, or -1 (between calls:
                                     // all -1).
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_TANGENTIAL_SMOOTHING_H_
