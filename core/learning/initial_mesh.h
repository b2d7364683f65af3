// The initial neural mesh: a regular tetrahedron around the data (Section 1.2), or, for data
// that form an open sheet, a flat disc in their best-fit plane (not in the paper; see
// LearnerOptions::initial_mesh), or a mesh learned before, to go on from (MakeStartMesh).
#ifndef NEURALMESH_CORE_LEARNING_INITIAL_MESH_H_
#define NEURALMESH_CORE_LEARNING_INITIAL_MESH_H_

#include "absl/status/statusor.h"
#include "core/bounding_box.h"
#include "core/learning/best_fit_plane.h"
#include "core/mesh.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

// A regular tetrahedron, outward oriented, centred on `box` with its vertices on the sphere
// through the box's corners. A degenerate box (one point) gives a unit-size tetrahedron there.
// The data's extremes lie outside it (most of a sphere's surface does), and the first Basic
// Steps pull its vertices out to them. Tried: the tetrahedron three times larger, whose
// inscribed sphere holds the box; the same speed, but on seeds 1-60 of the topology tests
// genus-2 seed 33 kept an extra handle (59 of 60 against 60 of 60).
Mesh MakeInitialTetrahedron(const BoundingBox& box);

// A disc of six triangles around one interior vertex at plane.center: a regular hexagon in the
// plane whose corners lie plane.radius from the centre (1 when the radius is 0 or not finite),
// the first along plane.u, oriented so that its faces' normals are plane.normal. Its border
// becomes the sheet's: its corners lie on the circle that holds the data's projection, and the
// first Basic Steps pull them in onto the data. The two sheets of topology_learning_test, seeds
// 1-30, one border and one layer in: 28 and 29 runs with this radius; 28 and 29 at 0.8 times
// it; 27 and 24 at 1.25 times; 12 and 27 at half (the rest folded over themselves). A finer
// start, a triangulated hexagon of 2, 3 or 5 rings, did as well and no better: 57-59 of 60 on
// seeds 1-30, 58 of 60 on seeds 31-60 (this disc: 57 and 59). All of these were measured
// before Step 5 closed crack tips (hole_closing.h), which most of the failures were.
Mesh MakeInitialDisc(const BestFitPlane& plane);

// A mesh to go on learning from (Learner::CreateFrom), such as one a learner snapshotted
// earlier: `start` as a half-edge mesh whose every vertex meets the learner's invariants
// (mesh_validation.h). Returns INVALID_ARGUMENT saying what is wrong when it has fewer than 4
// vertices, a coordinate that is not finite, a face index out of range or repeated, faces
// that do not form an orientable 2-manifold (with or without boundary), a vertex no face uses
// or of too low a valence, or a face of zero area.
absl::StatusOr<Mesh> MakeStartMesh(const TriangleMesh& start);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_INITIAL_MESH_H_
