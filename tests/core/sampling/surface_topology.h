// Topology of a TriangleMesh for the sampling tests: whether it is a closed, consistently
// oriented 2-manifold, and its Euler characteristic, component count and enclosed volume.
#ifndef NEURALMESH_TESTS_CORE_SAMPLING_SURFACE_TOPOLOGY_H_
#define NEURALMESH_TESTS_CORE_SAMPLING_SURFACE_TOPOLOGY_H_

#include <numeric>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "core/mesh_validation.h"
#include "core/triangle_mesh.h"

namespace neuralmesh::testing {

struct SurfaceTopology {
  std::string problem;  // Empty when the mesh is a closed oriented 2-manifold.
  long euler = 0;       // V - E + F.
  int components = 0;
  double volume = 0;  // Signed; > 0 when the faces are counter-clockwise seen from outside.
};

inline SurfaceTopology MeasureTopology(const TriangleMesh& triangles) {
  SurfaceTopology topology;
  absl::StatusOr<Mesh> mesh = ToMesh(triangles);
  if (!mesh.ok()) {
    topology.problem = std::string(mesh.status().message());
    return topology;
  }
  const absl::Status valid = ValidateMesh(*mesh);
  if (!valid.ok()) {
    topology.problem = std::string(valid.message());
    return topology;
  }
  for (auto h : mesh->halfedges()) {
    if (mesh->is_boundary(h)) {
      topology.problem = "the mesh has a boundary";
      return topology;
    }
  }
  topology.euler = static_cast<long>(mesh->n_vertices()) - static_cast<long>(mesh->n_edges()) +
                   static_cast<long>(mesh->n_faces());
  std::vector<int> parent(mesh->n_vertices());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (auto e : mesh->edges()) {
    const auto h = mesh->halfedge_handle(e, 0);
    parent[find(mesh->from_vertex_handle(h).idx())] = find(mesh->to_vertex_handle(h).idx());
  }
  for (size_t v = 0; v < parent.size(); ++v) topology.components += find(v) == static_cast<int>(v);
  for (const auto& f : triangles.faces) {
    const Vec3 a(triangles.positions[f[0]]), b(triangles.positions[f[1]]),
        c(triangles.positions[f[2]]);
    topology.volume += OpenMesh::dot(a, OpenMesh::cross(b, c)) / 6.0;
  }
  return topology;
}

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_CORE_SAMPLING_SURFACE_TOPOLOGY_H_
