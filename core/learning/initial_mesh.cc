#include "core/learning/initial_mesh.h"

#include <array>
#include <cmath>

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

}  // namespace neuralmesh
