#include "core/learning/vertex_split.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/learning/vertex_ring_cache.h"
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

TEST(VertexSplitTest, TheCounterIsSharedInProportionToTheCellEstimates) {
  Mesh mesh = testing::MustToMesh(testing::GridPatch(4, 4));
  const Mesh::VertexHandle v(12);
  mesh.point(Mesh::VertexHandle(13)) += Vec3(0.2, 0, 0);  // v0 takes the longer edges.
  VertexRingCache rings;
  SignalCounters counters(0.95);
  counters.Add(v.idx(), 3.0, 7);
  const Mesh::VertexHandle v0 = SplitVertex(mesh, rings, v);
  ASSERT_TRUE(v0.is_valid());
  rings.Invalidate(v.idx());
  rings.Invalidate(v0.idx());
  for (auto u : mesh.vv_range(v0)) rings.Invalidate(u.idx());
  ShareSplitCounter(mesh, rings, counters, v, v0, 3.0, 7);
  const double f = VoronoiAreaEstimate(mesh, v), f0 = VoronoiAreaEstimate(mesh, v0);
  ASSERT_GT(f0, f * 1.01) << "the two cells must differ for the test to tell shares apart";
  EXPECT_NEAR(counters.Value(v0.idx(), 7), 3.0 * f0 / (f + f0), 1e-12) << "Eq. 5-6";
  EXPECT_NEAR(counters.Value(v.idx(), 7), 3.0 * f / (f + f0), 1e-12);
  EXPECT_TRUE(counters.Contains(v0.idx()));
}

TEST(VertexSplitTest, AnUnsplittableMostActiveVertexStillPlacesTheSplitNextToIt) {
  // The most active vertex (1, 0) is on the border with valence 3; (2, 2) is interior and less
  // active. By default the split goes to the largest cell next to the most active vertex;
  // the paper's rule splits the most active splittable vertex.
  Mesh mesh = testing::MustToMesh(testing::GridPatch(4, 4));
  const Mesh::VertexHandle most_active(1), interior(12);
  ASSERT_FALSE(CanSplitVertex(mesh, most_active));
  VertexRingCache rings;
  SignalCounters counters(0.95);
  counters.Add(most_active.idx(), 5.0, 0);
  counters.Add(interior.idx(), 1.0, 0);

  const Mesh::VertexHandle chosen = ChooseSplitVertex(mesh, rings, counters, true);
  ASSERT_TRUE(chosen.is_valid());
  EXPECT_TRUE(CanSplitVertex(mesh, chosen));
  EXPECT_TRUE(mesh.find_halfedge(most_active, chosen).is_valid())
      << "chose " << chosen.idx() << ", not a neighbour of the most active vertex";
  EXPECT_EQ(chosen, LargestCellNear(mesh, rings, most_active));

  EXPECT_EQ(ChooseSplitVertex(mesh, rings, counters, false), interior) << "the paper's rule";

  SignalCounters only_border(0.95);
  only_border.Add(most_active.idx(), 5.0, 0);
  EXPECT_FALSE(ChooseSplitVertex(mesh, rings, only_border, false).is_valid());
  EXPECT_EQ(ChooseSplitVertex(mesh, rings, only_border, true), chosen);
  SignalCounters none(0.95);
  EXPECT_FALSE(ChooseSplitVertex(mesh, rings, none, true).is_valid());
}

// A grid patch made irregular by splits, inside and on the border.
Mesh IrregularPatch() {
  Mesh mesh = testing::MustToMesh(testing::GridPatch(6, 6));
  for (const int v : {14, 15, 22, 3, 29, 14, 8, 36, 2}) SplitVertex(mesh, Mesh::VertexHandle(v));
  return mesh;
}

// Every face's corners (vertex indices) and every position, in handle order.
std::vector<double> Contents(const Mesh& mesh) {
  std::vector<double> out;
  for (auto v : mesh.vertices()) {
    out.insert(out.end(), mesh.point(v).data(), mesh.point(v).data() + 3);
  }
  for (auto f : mesh.faces()) {
    for (auto v : mesh.fv_range(f)) out.push_back(v.idx());
  }
  return out;
}

TEST(VertexSplitTest, RingCacheOverloadsGiveWhatHalfEdgeWalksGive) {
  Mesh mesh = IrregularPatch();
  ASSERT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  mesh.add_vertex(Vec3(2, 2, 0));  // Isolated: never split, no area.
  VertexRingCache rings;
  std::array<int, 16> valences{};
  for (auto v : mesh.vertices()) {
    valences[std::min<size_t>(mesh.valence(v), 15)]++;
    EXPECT_EQ(CanSplitVertex(mesh, rings, v), CanSplitVertex(mesh, v)) << v.idx();
    // Bitwise: the rings list the neighbours in the order vv_range visits them.
    EXPECT_EQ(VoronoiAreaEstimate(mesh, rings, v), VoronoiAreaEstimate(mesh, v)) << v.idx();
    // LargestCellNear by its definition, from the half-edge walks.
    Mesh::VertexHandle expected = v;
    double best = CanSplitVertex(mesh, v) ? VoronoiAreaEstimate(mesh, v) : -1;
    for (auto u : mesh.vv_range(v)) {
      if (CanSplitVertex(mesh, u) && VoronoiAreaEstimate(mesh, u) > best) {
        best = VoronoiAreaEstimate(mesh, u);
        expected = u;
      }
    }
    EXPECT_EQ(LargestCellNear(mesh, rings, v), expected) << v.idx();
  }
  EXPECT_GT(valences[3] + valences[4], 0);
  EXPECT_GT(valences[7] + valences[8] + valences[9], 0) << "the splits made the patch irregular";

  // The split itself: the same mesh whichever way it reads the stars.
  int splits = 0, splittable = 0;
  for (auto v : mesh.vertices()) {
    splittable += CanSplitVertex(mesh, v) ? 1 : 0;
    Mesh walked = mesh;
    Mesh cached = mesh;
    VertexRingCache cached_rings;
    const Mesh::VertexHandle a = SplitVertex(walked, v);
    const Mesh::VertexHandle b = SplitVertex(cached, cached_rings, v);
    ASSERT_EQ(a, b) << v.idx();
    EXPECT_EQ(Contents(walked), Contents(cached)) << v.idx();
    splits += a.is_valid() ? 1 : 0;
  }
  EXPECT_EQ(splits, splittable);
  EXPECT_GT(splits, 30);
  EXPECT_LT(splits, static_cast<int>(mesh.n_vertices())) << "some border vertices are not split";
}

}  // namespace
}  // namespace neuralmesh
