// Step 2's vertex split (Section 2.2, Fig. 1).
//
//   e = (v, u) <- the longest edge at v
//   inside:   walk the star of v both ways from e, equally (k and k or k+1 edges), to e1, e2
//             that halve the star; the new vertex takes the half around e
//   boundary: cut the fan in the middle; the new vertex takes the half holding e and the
//             boundary edge on that side (a vertex of valence <= 4 is never split)
//   the new vertex is placed at the midpoint of e
#ifndef NEURALMESH_CORE_LEARNING_VERTEX_SPLIT_H_
#define NEURALMESH_CORE_LEARNING_VERTEX_SPLIT_H_

#include "core/learning/signal_counters.h"
#include "core/learning/vertex_ring_cache.h"
#include "core/mesh.h"

namespace neuralmesh {

// Whether the paper allows splitting `v`: not a boundary vertex of valence <= 4 (Section 2.2),
// and not an isolated or deleted vertex.
bool CanSplitVertex(const Mesh& mesh, Mesh::VertexHandle v);
// The same, reading v's ring from `rings` (which must agree with the mesh's connectivity)
// instead of walking its half-edges. So do the overloads with `rings` below, with bitwise the
// same results: both read the neighbours in WalkNeighbours' order (vertex_ring_cache.h), which
// is the order OpenMesh's vv_range visits them. Step 2 runs them on a neighbourhood that the
// Basic Steps before it have just read.
bool CanSplitVertex(const Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle v);

// Splits `v` and returns the new vertex, or an invalid handle when !CanSplitVertex. Keeps the
// mesh a valid manifold. O(valence).
Mesh::VertexHandle SplitVertex(Mesh& mesh, Mesh::VertexHandle v);
Mesh::VertexHandle SplitVertex(Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle v);

// F_v = l_v^2 with l_v the mean length of the edges at v (Eq. 5-6): the stand-in for the area of
// v's restricted Voronoi cell by which a split divides the signal counter.
double VoronoiAreaEstimate(const Mesh& mesh, Mesh::VertexHandle v);
double VoronoiAreaEstimate(const Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle v);

// Of `center` and its neighbours, the vertex that CanSplitVertex allows with the largest
// VoronoiAreaEstimate (ties: `center` first, then rotation order), or `center` when none is
// splittable. O(valence^2). Reads rings from `rings` (see CanSplitVertex).
Mesh::VertexHandle LargestCellNear(const Mesh& mesh, VertexRingCache& rings,
                                   Mesh::VertexHandle center);

// Eq. 5-6: after `v` was split into `v` and `v0`, v's counter (`counter`, its value before the
// split) is shared in proportion to F_v (VoronoiAreaEstimate): v0 gets counter F_v0 / (F_v +
// F_v0) and starts being tracked, v keeps the rest (each half when both F are 0); at `step`.
void ShareSplitCounter(const Mesh& mesh, VertexRingCache& rings, SignalCounters& counters,
                       Mesh::VertexHandle v, Mesh::VertexHandle v0, double counter, uint64_t step);

// Step 2's choice (learner_options.h, split_largest_cell_near_most_active): the vertex to
// split for the most active vertex of `counters` that has one. With `largest_cell_near`, the
// LargestCellNear of the most active vertex whose closed 1-ring holds a splittable vertex, so a
// border vertex of valence <= 4 still leads to a split next to it; without, the most active
// splittable vertex itself (the paper's rule). Invalid when no tracked vertex qualifies.
Mesh::VertexHandle ChooseSplitVertex(const Mesh& mesh, VertexRingCache& rings,
                                     SignalCounters& counters, bool largest_cell_near);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_VERTEX_SPLIT_H_
