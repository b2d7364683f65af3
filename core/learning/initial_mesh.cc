#include "core/learning/initial_mesh.h"

#include <array>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/mesh_validation.h"
#include "core/status_macros.h"

namespace neuralmesh {

Mesh MakeInitialTetrahedron(const BoundingBox& box) {
  const Vec3 center = box.empty() ? Vec3(0, 0, 0) : box.center();
  double radius = box.diagonal() * 0.5;
  if (!(radius > 0) || !std::isfinite(radius)) radius = 1;
  const double s = radius / std::sqrt(3.0);
  Mesh mesh;
  const Mesh::VertexHandle v[4] = {mesh.add_vertex(center + Vec3(s, s, s)),
                                   mesh.add_vertex(center + Vec3(s, -s, -s)),
                                   mesh.add_vertex(center + Vec3(-s, s, -s)),
                                   mesh.add_vertex(center + Vec3(-s, -s, s))};
  mesh.add_face(v[0], v[1], v[2]);
  mesh.add_face(v[0], v[3], v[1]);
  mesh.add_face(v[0], v[2], v[3]);
  mesh.add_face(v[1], v[3], v[2]);
  return mesh;
}

Mesh MakeInitialDisc(const BestFitPlane& plane) {
  double radius = plane.radius;
  if (!(radius > 0) || !std::isfinite(radius)) radius = 1;
  Mesh mesh;
  const Mesh::VertexHandle center = mesh.add_vertex(plane.center);
  std::array<Mesh::VertexHandle, 6> corners;
  for (int i = 0; i < 6; ++i) {
    const double angle = i * M_PI / 3;
    corners[i] = mesh.add_vertex(plane.center + radius * (std::cos(angle) * plane.u +
                                                          std::sin(angle) * plane.v));
  }
  for (int i = 0; i < 6; ++i) mesh.add_face(center, corners[i], corners[(i + 1) % 6]);
  return mesh;
}

absl::StatusOr<Mesh> MakeStartMesh(const TriangleMesh& start) {
  if (start.positions.size() < 4) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the start mesh has ", start.positions.size(), " vertices; learning needs at least 4"));
  }
  for (size_t i = 0; i < start.positions.size(); ++i) {
    const Vec3f& p = start.positions[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return absl::InvalidArgumentError(
          absl::StrCat("vertex ", i, " of the start mesh has a coordinate that is not finite"));
    }
  }
  NM_ASSIGN_OR_RETURN(Mesh mesh, ToMesh(start));
  for (auto f : mesh.faces()) {
    auto corner = mesh.fv_begin(f);
    const Vec3 a = mesh.point(*corner);
    const Vec3 b = mesh.point(*++corner);
    const Vec3 c = mesh.point(*++corner);
    if (OpenMesh::cross(b - a, c - a).sqrnorm() == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("face ", f.idx(), " of the start mesh has zero area"));
    }
  }
  if (absl::Status valid = ValidateMesh(mesh); !valid.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("learning cannot go on from the start mesh: ", valid.message()));
  }
  return mesh;
}

}  // namespace neuralmesh
