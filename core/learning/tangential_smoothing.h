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
// Normals are computed once per call (the moves are small). The arithmetic is written on raw
// coordinates: OpenMesh's vector temporaries cost several times more in this, the hottest loop.
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
  // Scratch storage reused across calls: the Basic Step allocates nothing.
  std::vector<int> ring_;
  std::vector<int> offsets_;     // Into neighbours_, per ring vertex (+1 end).
  std::vector<int> neighbours_;  // Vertex indices.
  std::vector<double> direction_;  // 3 per ring vertex: unit normal, or unit border tangent.
  std::vector<char> on_border_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_TANGENTIAL_SMOOTHING_H_
