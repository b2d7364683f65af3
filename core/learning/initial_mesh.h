// The initial neural mesh (Section 1.2): a regular tetrahedron around the data.
#ifndef NEURALMESH_CORE_LEARNING_INITIAL_MESH_H_
#define NEURALMESH_CORE_LEARNING_INITIAL_MESH_H_

#include "core/bounding_box.h"
#include "core/mesh.h"

namespace neuralmesh {

// A regular tetrahedron, outward oriented, centred on `box`, whose inscribed sphere is the
// sphere through the box's corners, so every point of the box is inside it. A degenerate box
// (one point) gives the tetrahedron around the unit sphere there.
Mesh MakeInitialTetrahedron(const BoundingBox& box);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_INITIAL_MESH_H_
