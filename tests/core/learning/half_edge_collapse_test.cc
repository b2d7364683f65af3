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

// A bipyramid: apexes 0 and 1 over a ring 2 .. n+1; each apex has valence n, each ring
// vertex 4.
Mesh Bipyramid(int n) {
  TriangleMesh shape;
  shape.positions = {Vec3f(0, 0, 1), Vec3f(0, 0, -1)};
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    shape.positions.emplace_back(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)),
                                 0.f);
  }
  for (uint32_t k = 0; k < static_cast<uint32_t>(n); ++k) {
    const uint32_t r = 2 + k, next = 2 + (k + 1) % n;
    shape.faces.push_back({0, r, next});
    shape.faces.push_back({1, next, r});
  }
  return testing::MustToMesh(shape);
}

// A disc: inner vertex 0 (valence n) and its rim 1 .. n (border, valence 3).
Mesh Disc(int n) {
  TriangleMesh shape;
  shape.positions = {Vec3f(0, 0, 0)};
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    shape.positions.emplace_back(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)),
                                 0.f);
  }
  for (uint32_t k = 0; k < static_cast<uint32_t>(n); ++k) {
    shape.faces.push_back({0, 1 + k, 1 + (k + 1) % n});
  }
  return testing::MustToMesh(shape);
}

TEST(HalfEdgeCollapseTest, NoCollapseLeavesMoreThanTwiceTheIdealValence) {
  // Inside: collapsing a ring vertex into an apex leaves the apex at valence n (it loses the
  // ring vertex and gains the other apex), allowed up to 12 and not beyond.
  for (const int n : {12, 13}) {
    Mesh mesh = Bipyramid(n);
    const Mesh::VertexHandle ring(2), apex(0);
    const Mesh::HalfedgeHandle into_apex = mesh.find_halfedge(ring, apex);
    ASSERT_TRUE(into_apex.is_valid());
    EXPECT_EQ(IsCollapseLegal(mesh, into_apex, mesh.n_vertices()), n <= 12) << "n = " << n;
    const Mesh::HalfedgeHandle best = BestCollapse(mesh, ring, mesh.n_vertices());
    ASSERT_TRUE(best.is_valid()) << "the ring vertex can still collapse along the ring";
    if (n > 12) {
      EXPECT_NE(mesh.to_vertex_handle(best), apex);
    }
  }
  // On a border: collapsing the centre of a disc into a rim vertex leaves that vertex at
  // valence n - 1, allowed up to 8.
  for (const int n : {9, 10}) {
    Mesh mesh = Disc(n);
    const Mesh::HalfedgeHandle into_rim = mesh.find_halfedge(Mesh::VertexHandle(0),
                                                             Mesh::VertexHandle(1));
    ASSERT_TRUE(into_rim.is_valid());
    EXPECT_EQ(IsCollapseLegal(mesh, into_rim, mesh.n_vertices()), n - 1 <= 8) << "n = " << n;
  }
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
