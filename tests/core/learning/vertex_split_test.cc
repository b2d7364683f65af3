#include "core/learning/vertex_split.h"

#include <algorithm>
#include <cmath>

#include "core/mesh_validation.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

// GridPatch(4, 4): vertex (i, j) has index j * 5 + i; (2, 2) is interior with valence 6,
// (2, 0) is on the border with valence 4, (1, 0) on the border with valence 3, and the
// corners have valence 2 or 3.
TEST(VertexSplitTest, InteriorSplitHalvesTheStarAroundTheLongestEdge) {
  Mesh mesh = testing::MustToMesh(testing::GridPatch(4, 4));
  const Mesh::VertexHandle v(12);
  // Make the edge to (3, 2) (index 13) clearly the longest.
  mesh.point(Mesh::VertexHandle(13)) += Vec3(0.2, 0, 0);
  const Vec3 expected_position = (mesh.point(v) + mesh.point(Mesh::VertexHandle(13))) * 0.5;
  const size_t vertices = mesh.n_vertices();
  const Mesh::VertexHandle v0 = SplitVertex(mesh, v);
  ASSERT_TRUE(v0.is_valid()) << "an interior vertex must split";
  EXPECT_EQ(mesh.n_vertices(), vertices + 1);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  EXPECT_NEAR((mesh.point(v0) - expected_position).norm(), 0, 1e-12)
      << "the new vertex sits at the midpoint of the longest edge";
  EXPECT_TRUE(mesh.find_halfedge(v0, Mesh::VertexHandle(13)).is_valid())
      << "the new vertex takes the half of the star around the longest edge";
  EXPECT_EQ(mesh.valence(v) + mesh.valence(v0), 10u) << "valences n+4 shared";
  EXPECT_EQ(mesh.valence(v), 5u) << "a valence-6 star is halved into 5 and 5";
  EXPECT_EQ(mesh.valence(v0), 5u);
}

TEST(VertexSplitTest, BorderVerticesOfValenceFourOrLessAreNotSplit) {
  Mesh mesh = testing::MustToMesh(testing::GridPatch(4, 4));
  EXPECT_FALSE(CanSplitVertex(mesh, Mesh::VertexHandle(2))) << "border vertex of valence 4";
  EXPECT_FALSE(SplitVertex(mesh, Mesh::VertexHandle(2)).is_valid());
  EXPECT_TRUE(CanSplitVertex(mesh, Mesh::VertexHandle(12))) << "interior vertex";
}

TEST(VertexSplitTest, BorderSplitKeepsOneBorderThroughBothVertices) {
  // A half-disc fan: border vertex 0 with neighbours 1..5 at 0, 45, ..., 180 degrees.
  TriangleMesh fan;
  fan.positions.emplace_back(0.f, 0.f, 0.f);
  for (int k = 0; k <= 4; ++k) {
    const double a = k * M_PI / 4;
    fan.positions.emplace_back(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.f);
  }
  for (uint32_t k = 1; k <= 4; ++k) fan.faces.push_back({0, k, k + 1});
  Mesh mesh = testing::MustToMesh(fan);
  const Mesh::VertexHandle v(0);
  ASSERT_EQ(mesh.valence(v), 5u);
  const Mesh::VertexHandle v0 = SplitVertex(mesh, v);
  ASSERT_TRUE(v0.is_valid()) << "a border vertex of valence 5 may split";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  EXPECT_TRUE(mesh.is_boundary(v0)) << "the new vertex lies on the border";
  EXPECT_TRUE(mesh.is_boundary(v));
  EXPECT_EQ(mesh.valence(v), 4u) << "valence 5 on the border splits into 4 and 4";
  EXPECT_EQ(mesh.valence(v0), 4u);
  EXPECT_EQ(mesh.n_faces(), 5u) << "one new face; the new edge lies on the border";
}

TEST(VertexSplitTest, InteriorSplitsDoNotPileEdgesOntoTheBorder) {
  // Split the inner vertices next to the border over and over, as the learner does where a
  // border meets the data. A cut neighbour on the border may gain edges up to valence 5 for
  // free (so that it can split itself), but not beyond: border vertices that are never split
  // must not grow into hubs.
  Mesh mesh = testing::MustToMesh(testing::GridPatch(6, 6));
  for (int round = 0; round < 300; ++round) {
    Mesh::VertexHandle next;
    for (auto v : mesh.vertices()) {
      if (mesh.is_boundary(v)) continue;
      bool next_to_border = false;
      for (auto u : mesh.vv_range(v)) next_to_border = next_to_border || mesh.is_boundary(u);
      if (next_to_border && (!next.is_valid() || mesh.valence(v) > mesh.valence(next))) next = v;
    }
    ASSERT_TRUE(next.is_valid());
    ASSERT_TRUE(SplitVertex(mesh, next).is_valid());
  }
  ASSERT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  size_t max_border_valence = 0;
  for (auto v : mesh.vertices()) {
    if (mesh.is_boundary(v)) max_border_valence = std::max<size_t>(max_border_valence, mesh.valence(v));
  }
  EXPECT_LE(max_border_valence, 8u) << "with border neighbours free at any valence it reaches 12";
}

TEST(VertexSplitTest, VoronoiAreaEstimateIsSquaredMeanEdgeLength) {
  Mesh mesh = testing::MustToMesh(testing::GridPatch(4, 4));
  // Interior vertex: 4 edges of length 1/4 and 2 diagonals of length sqrt(2)/4.
  const double l = (4 * 0.25 + 2 * std::sqrt(2.0) * 0.25) / 6;
  EXPECT_NEAR(VoronoiAreaEstimate(mesh, Mesh::VertexHandle(12)), l * l, 1e-12) << "Eq. 5-6";
}

}  // namespace
}  // namespace neuralmesh
