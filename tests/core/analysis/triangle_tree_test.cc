#include "core/analysis/triangle_tree.h"

#include <cmath>
#include <limits>
#include <vector>

#include "core/analysis/closest_point_triangle.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using ::neuralmesh::testing::Icosphere;

Vec3 ToVec3(const Vec3f& v) { return Vec3(v[0], v[1], v[2]); }

double BruteForceDistance(const TriangleMesh& mesh, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& f : mesh.faces) {
    const Vec3 q =
        ClosestPointOnTriangle(p, ToVec3(mesh.positions[f[0]]), ToVec3(mesh.positions[f[1]]),
                               ToVec3(mesh.positions[f[2]]))
            .point;
    best = std::min(best, (p - q).norm());
  }
  return best;
}

// A jittered icosphere (5120 faces) plus 1000 random triangles floating around it.
TriangleMesh TestSoup(uint64_t seed) {
  Random rng(seed);
  auto uniform = [&](double lo, double hi) {
    return static_cast<float>(lo + (hi - lo) * rng.NextDouble());
  };
  TriangleMesh mesh = Icosphere(4);
  for (Vec3f& p : mesh.positions) p *= 1.f + uniform(-0.05, 0.05);
  for (int i = 0; i < 1000; ++i) {
    const Vec3f centre(uniform(-1.5, 1.5), uniform(-1.5, 1.5), uniform(-1.5, 1.5));
    const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    for (int k = 0; k < 3; ++k) {
      mesh.positions.push_back(centre +
                               Vec3f(uniform(-0.1, 0.1), uniform(-0.1, 0.1), uniform(-0.1, 0.1)));
    }
    mesh.faces.push_back({base, base + 1, base + 2});
  }
  return mesh;
}

// Copies of a face never prune each other (a box is nearer to a point than its triangle), so
// each query once tested all 5,000 copies: `eval` against such a reference took 85 s. The tree
// now holds each face once; the flipped copy stays, since its normal differs.
TEST(TriangleTreeTest, CopiesOfAFaceAreHeldOnce) {
  TriangleMesh mesh;
  mesh.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  for (int i = 0; i < 5000; ++i) {
    // The same face, written from each of its corners in turn.
    const uint32_t r = static_cast<uint32_t>(i % 3);
    mesh.faces.push_back({r, (r + 1) % 3, (r + 2) % 3});
  }
  mesh.faces.push_back({0, 2, 1});
  absl::StatusOr<TriangleTree> tree = TriangleTree::Build(mesh);
  ASSERT_TRUE(tree.ok()) << tree.status();
  EXPECT_EQ(tree->num_triangles(), 2u);
  const TriangleTree::ClosestPointResult result = tree->ClosestPoint(Vec3(0.25, 0.25, 1.0));
  EXPECT_DOUBLE_EQ(result.distance, 1.0);
  EXPECT_EQ(result.face, 0u) << "the first copy answers, as before";
}

TEST(TriangleTreeTest, MatchesBruteForceOnRandomQueries) {
  const TriangleMesh mesh = TestSoup(3);
  absl::StatusOr<TriangleTree> tree = TriangleTree::Build(mesh);
  ASSERT_TRUE(tree.ok()) << "building over a valid soup failed: " << tree.status();
  EXPECT_EQ(tree->num_triangles(), mesh.faces.size()) << "the tree must hold every face";
  Random rng(11);
  for (int i = 0; i < 1000; ++i) {
    // Half the queries near the surface, half anywhere in a larger box.
    const double scale = i % 2 == 0 ? 1.2 : 3.0;
    const Vec3 p(scale * (2 * rng.NextDouble() - 1), scale * (2 * rng.NextDouble() - 1),
                 scale * (2 * rng.NextDouble() - 1));
    const TriangleTree::ClosestPointResult result = tree->ClosestPoint(p);
    const double expected = BruteForceDistance(mesh, p);
    ASSERT_EQ(result.distance, expected)
        << "query " << i << ": tree distance differs from brute force";
    EXPECT_NEAR((p - result.point).norm(), result.distance, 1e-12)
        << "query " << i << ": reported point is not at the reported distance";
    ASSERT_LT(result.face, mesh.faces.size()) << "query " << i << ": face index out of range";
    const auto& f = mesh.faces[result.face];
    const Vec3 on_face =
        ClosestPointOnTriangle(p, ToVec3(mesh.positions[f[0]]), ToVec3(mesh.positions[f[1]]),
                               ToVec3(mesh.positions[f[2]]))
            .point;
    EXPECT_LT((on_face - result.point).norm(), 1e-12)
        << "query " << i << ": the reported point does not lie on the reported face";
  }
}

TEST(TriangleTreeTest, BatchQueriesDoNotDependOnThreadCount) {
  const TriangleMesh mesh = TestSoup(5);
  absl::StatusOr<TriangleTree> tree = TriangleTree::Build(mesh);
  ASSERT_TRUE(tree.ok()) << tree.status();
  Random rng(2);
  std::vector<Vec3> points(5000);
  for (Vec3& p : points) {
    p = Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()) * 3.0 - Vec3(1.5, 1.5, 1.5);
  }
  TriangleTree::BatchOptions options;
  options.threads = 1;
  const auto one = tree->ClosestPoints(points, options);
  options.threads = 2;
  const auto two = tree->ClosestPoints(points, options);
  const auto all = tree->ClosestPoints(points, TriangleTree::BatchOptions());
  ASSERT_EQ(one.size(), points.size()) << "one result per point expected";
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(one[i].distance, two[i].distance) << "point " << i << ": 1 vs 2 threads differ";
    ASSERT_EQ(one[i].face, two[i].face) << "point " << i << ": 1 vs 2 threads differ";
    ASSERT_EQ(one[i].distance, all[i].distance) << "point " << i << ": 1 vs auto differ";
    ASSERT_EQ(one[i].distance, tree->ClosestPoint(points[i]).distance)
        << "point " << i << ": batch differs from single query";
  }
}

TEST(TriangleTreeTest, EarlyExitIsExactBeyondTheRadius) {
  const TriangleMesh mesh = TestSoup(8);
  absl::StatusOr<TriangleTree> tree = TriangleTree::Build(mesh);
  ASSERT_TRUE(tree.ok()) << tree.status();
  Random rng(4);
  const double radius = 0.05;
  std::vector<Vec3> points(3000);
  for (Vec3& p : points) {
    p = Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()) * 4.0 - Vec3(2, 2, 2);
  }
  TriangleTree::BatchOptions options;
  options.radius = radius;
  const auto bounded = tree->ClosestPoints(points, options);
  size_t near = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double exact = tree->ClosestPoint(points[i]).distance;
    if (exact > radius) {
      ASSERT_EQ(bounded[i].distance, exact)
          << "point " << i << ": beyond the radius the result must be exact";
    } else {
      ++near;
      ASSERT_LE(bounded[i].distance, radius)
          << "point " << i << ": within the radius the result must stay within it";
      ASSERT_NEAR((points[i] - bounded[i].point).norm(), bounded[i].distance, 1e-12)
          << "point " << i << ": reported point is not at the reported distance";
    }
  }
  EXPECT_GT(near, 10u) << "test setup: some queries should fall within the radius";
}

TEST(TriangleTreeTest, HandlesDegenerateTrianglesAndTinyMeshes) {
  TriangleMesh mesh;
  mesh.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(2, 0, 0), Vec3f(0, 0, 5)};
  mesh.faces = {{0, 1, 2}, {3, 3, 3}};  // A segment and a point.
  absl::StatusOr<TriangleTree> tree = TriangleTree::Build(mesh);
  ASSERT_TRUE(tree.ok()) << "degenerate faces must be accepted: " << tree.status();
  const auto r = tree->ClosestPoint(Vec3(1.5, 2, 0));
  EXPECT_NEAR(r.distance, 2.0, 1e-15) << "distance to the collinear face";
  EXPECT_EQ(r.face, 0u) << "the segment face is nearest";
  const auto s = tree->ClosestPoint(Vec3(0, 0, 7));
  EXPECT_NEAR(s.distance, 2.0, 1e-15) << "distance to the point face";
  EXPECT_EQ(s.face, 1u) << "the point face is nearest";
  EXPECT_EQ(tree->bounds().max[2], 5.0) << "bounds must include every face";
}

TEST(TriangleTreeTest, NonFiniteQueryGivesInfiniteDistance) {
  absl::StatusOr<TriangleTree> tree = TriangleTree::Build(Icosphere(1));
  ASSERT_TRUE(tree.ok()) << tree.status();
  const auto r = tree->ClosestPoint(Vec3(std::nan(""), 0, 0));
  EXPECT_TRUE(std::isinf(r.distance)) << "a NaN query should report an infinite distance";
}

TEST(TriangleTreeTest, RejectsInvalidMeshes) {
  EXPECT_EQ(TriangleTree::Build(TriangleMesh()).status().code(), absl::StatusCode::kInvalidArgument)
      << "an empty mesh must be rejected";
  TriangleMesh no_faces = Icosphere(0);
  no_faces.faces.clear();
  EXPECT_EQ(TriangleTree::Build(no_faces).status().code(), absl::StatusCode::kInvalidArgument)
      << "a mesh without faces must be rejected";
  TriangleMesh out_of_range = Icosphere(0);
  out_of_range.faces[4][1] = 12;
  EXPECT_EQ(TriangleTree::Build(out_of_range).status().code(), absl::StatusCode::kInvalidArgument)
      << "an out-of-range index must be rejected";
  TriangleMesh not_finite = Icosphere(0);
  not_finite.positions[3][2] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(TriangleTree::Build(not_finite).status().code(), absl::StatusCode::kInvalidArgument)
      << "a non-finite position must be rejected";
}

}  // namespace
}  // namespace neuralmesh
