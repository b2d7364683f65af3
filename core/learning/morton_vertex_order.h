// Renumbers the vertices of a mesh in Morton (Z-order) order of their positions, so that
// vertices close in space get close indices.
//
// Why: the learner's Basic Step reads and writes the winner, its 1-ring and their rings (about
// 19 vertices) in the positions, the ring cache, the octree's index and the signal counters,
// all arrays indexed by vertex index. Vertex splits append vertices in the order they happen,
// so after a while neighbours are scattered over the whole index range and every one of those
// reads is a cache miss once the mesh outgrows the caches. In Morton order a 1-ring mostly
// shares a few cache lines.
//
//   code(v) = interleaved bits of the position of v quantised to 2^21 cells per axis of the
//             bounding box of all points
//   order   = vertices sorted by (code, old index)
//   new index of order[k] = k
//
// Every vertex property moves with its vertex (points, status, and any property a caller
// added); half-edges are pointed at the new indices. Edges, half-edges and faces keep their
// indices. Deleted vertices are renumbered like the others: call it after garbage_collection()
// so that they do not sit between live ones. O(v log v).
#ifndef NEURALMESH_CORE_LEARNING_MORTON_VERTEX_ORDER_H_
#define NEURALMESH_CORE_LEARNING_MORTON_VERTEX_ORDER_H_

#include <cstdint>
#include <vector>

#include "core/mesh.h"
#include "core/morton_code.h"

namespace neuralmesh {

// Renumbers the vertices of `mesh` in Morton order (see above). Returns the new index of each
// old vertex index, for callers that keep per-vertex data outside the mesh's properties.
std::vector<int> SortVerticesInMortonOrder(Mesh& mesh);

// Renumbers the edges of `mesh` (and with them their half-edges, which OpenMesh numbers 2e and
// 2e + 1) by their smaller vertex index, then their larger one. After the vertices are in
// Morton order, the half-edges around a vertex then lie in a few cache lines next to those of
// its neighbours: the walk around a vertex (the ring cache's refill after every Step 3, Steps
// 2-5) reads those lines instead of one scattered line per neighbour. Every edge and half-edge
// property moves with its element; vertices and faces keep their indices. Call it after
// garbage_collection(). O(e log e).
void SortEdgesByVertexIndex(Mesh& mesh);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_MORTON_VERTEX_ORDER_H_
