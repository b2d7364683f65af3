#include "core/triangle_mesh.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace neuralmesh {

absl::Status MoveOrigin(const Origin& origin, TriangleMesh* mesh) {
  if (origin == mesh->origin) return absl::OkStatus();
  std::vector<Vec3f> moved(mesh->positions.size());
  for (size_t i = 0; i < moved.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double value = mesh->origin[c] - origin[c] + double{mesh->positions[i][c]};
      if (!(std::fabs(value) <= std::numeric_limits<float>::max())) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "relative to (%.15g, %.15g, %.15g), vertex %d would lie beyond a float's range",
            origin[0], origin[1], origin[2], i));
      }
      moved[i][c] = static_cast<float>(value);
    }
  }
  mesh->positions = std::move(moved);
  mesh->origin = origin;
  return absl::OkStatus();
}

TriangleMesh ToTriangleMesh(const Mesh& mesh) {
  TriangleMesh out;
  std::vector<uint32_t> index(mesh.n_vertices(), UINT32_MAX);
  out.positions.reserve(mesh.n_vertices());
  for (auto vh : mesh.vertices()) {
    if (mesh.status(vh).deleted()) continue;
    index[vh.idx()] = static_cast<uint32_t>(out.positions.size());
    const Vec3& p = mesh.point(vh);
    out.positions.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]),
                               static_cast<float>(p[2]));
  }
  out.faces.reserve(mesh.n_faces());
  for (auto fh : mesh.faces()) {
    if (mesh.status(fh).deleted()) continue;
    std::array<uint32_t, 3> tri;
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) tri[k++] = index[vh.idx()];
    out.faces.push_back(tri);
  }
  return out;
}

absl::StatusOr<Mesh> ToMesh(const TriangleMesh& triangles) {
  Mesh mesh;
  const size_t n = triangles.positions.size();
  std::vector<Mesh::VertexHandle> handles;
  handles.reserve(n);
  for (const Vec3f& p : triangles.positions) handles.push_back(mesh.add_vertex(Vec3(p[0], p[1], p[2])));
  for (size_t i = 0; i < triangles.faces.size(); ++i) {
    const auto& f = triangles.faces[i];
    if (f[0] >= n || f[1] >= n || f[2] >= n) {
      return absl::InvalidArgumentError(
          absl::StrCat("face ", i, " refers to a vertex index beyond the ", n, " vertices"));
    }
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) {
      return absl::InvalidArgumentError(absl::StrCat("face ", i, " repeats a vertex"));
    }
    // OpenMesh prints a complaint to its error stream and returns an invalid handle when a
    // face would make the mesh non-manifold; we turn that into a status.
    const Mesh::FaceHandle fh = mesh.add_face(handles[f[0]], handles[f[1]], handles[f[2]]);
    if (!fh.is_valid()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "face ", i, " (", f[0], ", ", f[1], ", ", f[2],
          ") makes the mesh non-manifold or inconsistently oriented"));
    }
  }
  return mesh;
}

}  // namespace neuralmesh
