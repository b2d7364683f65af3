// The boundary loops of a mesh, shared by the steps that work on them (hole closing, boundary
// merging, bridge cutting).
#ifndef NEURALMESH_CORE_LEARNING_BOUNDARY_LOOPS_H_
#define NEURALMESH_CORE_LEARNING_BOUNDARY_LOOPS_H_

#include <vector>

#include "core/mesh.h"

namespace neuralmesh {

// One boundary loop: the from-vertex of each boundary half-edge, in half-edge order
// (loop[i] -> loop[i + 1] is a boundary half-edge).
using VertexLoop = std::vector<Mesh::VertexHandle>;

// Every boundary loop of the live half-edges of `mesh`, in the order of their first half-edge.
// O(h).
std::vector<VertexLoop> CollectBoundaryLoops(const Mesh& mesh);

// The boundary loop that starts with the boundary half-edge `start`; with `visited` (indexed by
// half-edge), marks its half-edges there. O(loop length).
VertexLoop BoundaryLoopFrom(const Mesh& mesh, Mesh::HalfedgeHandle start,
                            std::vector<bool>* visited = nullptr);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_BOUNDARY_LOOPS_H_
