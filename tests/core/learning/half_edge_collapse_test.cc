#include "core/learning/half_edge_collapse.h"

#include <cmath>

#include "core/mesh_validation.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

TEST(HalfEdgeCollapseTest, InteriorIrregularityIsEquationTen) {
  Mesh mesh = testing::MustToMesh(testing::Icosphere(2));
  for (auto h : mesh.halfedges()) {
    const auto v = mesh.from_vertex_handle(h), u = mesh.to_vertex_handle(h);
    const int a = mesh.valence(v), b = mesh.valence(u);
    const int c = mesh.valence(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
    const int d = mesh.valence(
        mesh.to_vertex_handle(mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h))));
    const double eq10 =
        std::sqrt(std::pow(a + b - 10, 2) + std::pow(c - 7, 2) + std::pow(d - 7, 2)) / 3;
    ASSERT_NEAR(CollapseIrregularity(mesh, h), eq10, 1e-12) << "half-edge " << h.idx();
  }
}

TEST(HalfEdgeCollapseTest, BorderIrregularityIsEquationEleven) {
  Mesh mesh = testing::MustToMesh(testing::GridPatch(4, 4));
  int checked = 0;
  for (auto h : mesh.halfedges()) {
    if (!mesh.is_boundary(mesh.opposite_halfedge_handle(h))) continue;
    // h is the inner half-edge of a border edge: one face, opposite vertex c.
    const auto c_vertex = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
    if (mesh.is_boundary(c_vertex)) continue;  // Eq. 11 assumes an inner opposite vertex.
    const int a = mesh.valence(mesh.from_vertex_handle(h)), b = mesh.valence(mesh.to_vertex_handle(h));
    const int c = mesh.valence(c_vertex);
    const double eq11 = std::sqrt(std::pow(a + b - 7, 2) + std::pow(c - 7, 2)) / 2;
    ASSERT_NEAR(CollapseIrregularity(mesh, h), eq11, 1e-12) << "half-edge " << h.idx();
    ++checked;
  }
  EXPECT_GT(checked, 0) << "the grid has border edges with inner opposite vertices";
}

TEST(HalfEdgeCollapseTest, BorderVerticesOnlySlideAlongTheBorder) {
  Mesh mesh = testing::MustToMesh(testing::GridPatch(4, 4));
  const Mesh::VertexHandle v(2);  // Border, valence 4.
  const auto h = BestCollapse(mesh, v, mesh.n_vertices());
  ASSERT_TRUE(h.is_valid());
  EXPECT_TRUE(mesh.is_boundary(mesh.edge_handle(h))) << "collapse must follow a border edge";
  mesh.collapse(h);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(HalfEdgeCollapseTest, TetrahedronCannotCollapse) {
  TriangleMesh tet;
  tet.positions = {Vec3f(1, 1, 1), Vec3f(1, -1, -1), Vec3f(-1, 1, -1), Vec3f(-1, -1, 1)};
  tet.faces = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  Mesh mesh = testing::MustToMesh(tet);
  for (auto v : mesh.vertices()) {
    EXPECT_FALSE(BestCollapse(mesh, v, 4).is_valid()) << "4 vertices is the minimum";
  }
}

}  // namespace
}  // namespace neuralmesh
