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

// The sum of the lengths of a loop's edges.
double LoopPerimeter(const Mesh& mesh, const VertexLoop& loop);

// The index in `loops` of the loop of greatest perimeter, the first among equals; -1 when
// `loops` is empty.
int LongestLoop(const Mesh& mesh, const std::vector<VertexLoop>& loops);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_BOUNDARY_LOOPS_H_
