// A plain indexed triangle mesh: the exchange format between the learner, file I/O, Draco,
// the mesh report and the network. Unlike `Mesh` it may hold any triangle soup, including
// non-manifold input read from a file.
#ifndef NEURALMESH_CORE_TRIANGLE_MESH_H_
#define NEURALMESH_CORE_TRIANGLE_MESH_H_

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/mesh.h"
#include "core/origin.h"
#include "core/rgb.h"

namespace neuralmesh {

struct TriangleMesh {
  std::vector<Vec3f> positions;
  std::vector<std::array<uint32_t, 3>> faces;  // Counter-clockwise seen from outside.
  std::vector<Rgb> colors;  // Empty, or one colour per vertex (point_colors.h paints them).
  // Where the positions' (0, 0, 0) lies in the coordinates of the data they came from
  // (georeferenced scans: see PointCloud::origin); writers put it back. Zero for most meshes.
  Origin origin = kNoOrigin;

  bool empty() const { return positions.empty(); }
};

// Expresses the positions of `mesh` relative to `origin` instead of mesh->origin (the same
// places, so a translation by their difference), and sets mesh->origin. Positions far from the
// new origin keep only a float's resolution there.
// Returns INVALID_ARGUMENT, leaving `mesh` as it was, when a position would lie beyond a
// float's range.
absl::Status MoveOrigin(const Origin& origin, TriangleMesh* mesh);

// Copies the live (not deleted) vertices and faces of `mesh`, renumbered densely in
// handle order. O(v + f).
TriangleMesh ToTriangleMesh(const Mesh& mesh);

// Builds a half-edge mesh from `triangles`.
// Returns INVALID_ARGUMENT when a face index is out of range or degenerate, or when the faces
// do not form an orientable 2-manifold (with or without boundary).
absl::StatusOr<Mesh> ToMesh(const TriangleMesh& triangles);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_TRIANGLE_MESH_H_
