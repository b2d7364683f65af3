// Drops a mesh's deleted elements and renumbers the rest so that elements close in space get
// close indices: the vertices in Morton (Z-order) order of their positions, the edges by their
// vertices.
//
// Why: the learner's Basic Step reads and writes the winner, its 1-ring and their rings (about
// 19 vertices) in the positions, the ring cache, the octree's index and the signal counters,
// all arrays indexed by vertex index. Vertex splits append vertices in the order they happen,
// so after a while neighbours are scattered over the whole index range and every one of those
// reads is a cache miss once the mesh outgrows the caches. In Morton order a 1-ring mostly
// shares a few cache lines. The edges (and with them their half-edges, which OpenMesh numbers
// 2e and 2e + 1) follow the vertices: the half-edges around a vertex then lie in a few cache
// lines next to those of its neighbours, which the walks around vertices (the ring cache's
// refill after every Step 3, Steps 2-5) read.
//
// The result is the one of OpenMesh's garbage_collection() followed by
//
//   code(v)  = interleaved bits of the position of v quantised to 2^21 cells per axis of the
//              bounding box of the live points
//   vertices sorted by (code, index after garbage_collection)
//   edges sorted by (smaller new vertex index, larger one, index after garbage_collection)
//   faces in the order garbage_collection() leaves them
//
// element for element, link for link and property for property, in one pass over each kind of
// element instead of the collection's pass and two sorts' permutations: every vertex, edge,
// half-edge and face property moves with its element (points, status, and any property a
// caller added; those of the common value types by one gather, others by swaps). O(v log v + e
// + f).
#ifndef NEURALMESH_CORE_LEARNING_MORTON_VERTEX_ORDER_H_
#define NEURALMESH_CORE_LEARNING_MORTON_VERTEX_ORDER_H_

#include <vector>

#include "core/mesh.h"

namespace neuralmesh {

// Compacts and renumbers `mesh` (see above). Returns the new index of each old vertex index (-1
// for a deleted vertex), for callers that keep per-vertex data outside the mesh's properties.
std::vector<int> CompactInMortonOrder(Mesh& mesh);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_MORTON_VERTEX_ORDER_H_
