// Structural checks of a neural mesh: the invariants every step of the learner keeps.
#ifndef NEURALMESH_CORE_MESH_VALIDATION_H_
#define NEURALMESH_CORE_MESH_VALIDATION_H_

#include "absl/status/status.h"
#include "core/mesh.h"

namespace neuralmesh {

// Checks, over the live (not deleted) elements of `mesh`, that
//  - the half-edge links are consistent (opposite, next, prev, face, to/from vertex), and no
//    live element refers to a deleted one;
//  - every face is a triangle with three distinct vertices;
//  - every edge has at least one face (no dangling edge) and no two edges join the same
//    pair of vertices;
//  - every vertex is manifold: its faces form one fan (at most one boundary gap), it is not
//    isolated, its stored outgoing half-edge is a boundary one when it lies on a boundary
//    (OpenMesh's invariant), and its valence is at least 3 inside and 2 on a boundary.
// Returns OK or INTERNAL with a message naming the first offending element. O(v + f).
absl::Status ValidateMesh(const Mesh& mesh);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_MESH_VALIDATION_H_
