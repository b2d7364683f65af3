#include "core/analysis/closest_point_triangle.h"

#include <cmath>
#include <string>

#include "core/random.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

std::string Str(const Vec3& v) {
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) +
         ")";
}

const char* Name(TriangleFeature f) {
  switch (f) {
    case TriangleFeature::kVertexA:
      return "vertex A";
    case TriangleFeature::kVertexB:
      return "vertex B";
    case TriangleFeature::kVertexC:
      return "vertex C";
    case TriangleFeature::kEdgeAB:
      return "edge AB";
    case TriangleFeature::kEdgeBC:
      return "edge BC";
    case TriangleFeature::kEdgeCA:
      return "edge CA";
    case TriangleFeature::kFace:
      return "face";
  }
  return "?";
}

struct RegionCase {
  Vec3 query;
  Vec3 expected;
  TriangleFeature feature;
};

TEST(ClosestPointTriangleTest, EachVoronoiRegionOfARightTriangle) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const RegionCase cases[] = {
      {Vec3(0.2, 0.2, 0.5), Vec3(0.2, 0.2, 0), TriangleFeature::kFace},
      {Vec3(0.1, 0.3, -2.0), Vec3(0.1, 0.3, 0), TriangleFeature::kFace},
      {Vec3(-1, -1, 0.3), a, TriangleFeature::kVertexA},
      {Vec3(2, -0.5, 1), b, TriangleFeature::kVertexB},
      {Vec3(-0.5, 2, -1), c, TriangleFeature::kVertexC},
      {Vec3(0.5, -1, 0.7), Vec3(0.5, 0, 0), TriangleFeature::kEdgeAB},
      {Vec3(1, 1, 0.3), Vec3(0.5, 0.5, 0), TriangleFeature::kEdgeBC},
      {Vec3(-1, 0.5, 0.2), Vec3(0, 0.5, 0), TriangleFeature::kEdgeCA},
  };
  for (const RegionCase& test : cases) {
    const TriangleClosestPoint result = ClosestPointOnTriangle(test.query, a, b, c);
    EXPECT_LT((result.point - test.expected).norm(), 1e-15)
        << "query " << Str(test.query) << ": got " << Str(result.point) << ", expected "
        << Str(test.expected);
    EXPECT_EQ(result.feature, test.feature)
        << "query " << Str(test.query) << ": region " << Name(result.feature) << ", expected "
        << Name(test.feature);
  }
}

TEST(ClosestPointTriangleTest, DistanceMatchesAnalyticValuesInEachRegion) {
  // An obtuse triangle in a tilted plane: checks the distances, not just the features.
  const Vec3 a(1, 2, 3), b(4, 2.5, 3.5), c(0.5, 3, 5);
  const Vec3 n = ((b - a) % (c - a)).normalized();
  const Vec3 centroid = (a + b + c) / 3.0;
  EXPECT_NEAR((ClosestPointOnTriangle(centroid + n * 0.7, a, b, c).point - centroid).norm(), 0.0,
              1e-12)
      << "a point above the centroid must project onto it";
  // Beyond vertex b along the bisector of its outside angle.
  const Vec3 out_b = b + ((b - a).normalized() + (b - c).normalized()) * 0.8;
  const TriangleClosestPoint at_b = ClosestPointOnTriangle(out_b, a, b, c);
  EXPECT_EQ(at_b.feature, TriangleFeature::kVertexB) << "beyond b along its bisector";
  EXPECT_NEAR((out_b - at_b.point).norm(), (out_b - b).norm(), 1e-12) << "distance to b";
  // Straight out from the middle of edge ca, in the plane.
  const Vec3 mid_ca = (a + c) * 0.5;
  // In the plane, perpendicular to ca, away from b.
  const Vec3 ca_dir = (c - a).normalized();
  const Vec3 away = mid_ca - b;
  const Vec3 outward = (away - ca_dir * away.dot(ca_dir)).normalized();
  const TriangleClosestPoint at_ca = ClosestPointOnTriangle(mid_ca + outward * 0.3, a, b, c);
  EXPECT_EQ(at_ca.feature, TriangleFeature::kEdgeCA) << "outside edge ca";
  EXPECT_NEAR((at_ca.point - mid_ca).norm(), 0.0, 1e-12) << "projection onto edge ca";
}

TEST(ClosestPointTriangleTest, RandomQueriesAreNeverBeatenByPointsOfTheTriangle) {
  Random rng(7);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.NextDouble(); };
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 a(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    const Vec3 b(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    const Vec3 c(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    const Vec3 p(uniform(-2, 2), uniform(-2, 2), uniform(-2, 2));
    const TriangleClosestPoint result = ClosestPointOnTriangle(p, a, b, c);
    const double d = (p - result.point).norm();
    // The result lies on the triangle: its barycentric coordinates are in [0, 1].
    const Vec3 n = (b - a) % (c - a);
    const double area2 = n.sqrnorm();
    const double u = ((c - b) % (result.point - b)).dot(n) / area2;
    const double v = ((a - c) % (result.point - c)).dot(n) / area2;
    const double w = 1.0 - u - v;
    EXPECT_GT(std::min({u, v, w}), -1e-9) << "trial " << trial << ": result off the triangle";
    EXPECT_LT(std::abs((result.point - (a * u + b * v + c * w)).norm()), 1e-9)
        << "trial " << trial << ": result off the triangle's plane";
    // No point of a dense barycentric grid is closer.
    const int k = 60;
    for (int i = 0; i <= k; ++i) {
      for (int j = 0; i + j <= k; ++j) {
        const Vec3 q =
            a + (b - a) * (static_cast<double>(i) / k) + (c - a) * (static_cast<double>(j) / k);
        ASSERT_GE((p - q).norm(), d - 1e-12)
            << "trial " << trial << ": grid point " << Str(q) << " beats the result "
            << Str(result.point) << " in region " << Name(result.feature);
      }
    }
  }
}

TEST(ClosestPointTriangleTest, DegenerateTrianglesBehaveAsSegmentsOrPoints) {
  {
    // Collinear corners: the triangle is the segment from (0,0,0) to (2,0,0).
    const TriangleClosestPoint r =
        ClosestPointOnTriangle(Vec3(1.5, 1, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0));
    EXPECT_LT((r.point - Vec3(1.5, 0, 0)).norm(), 1e-15)
        << "collinear triangle: got " << Str(r.point);
    EXPECT_TRUE(std::isfinite(r.point[0])) << "collinear triangle gave a non-finite point";
  }
  {
    // Two coincident corners: the segment from a to c.
    const TriangleClosestPoint r =
        ClosestPointOnTriangle(Vec3(-1, 3, 0), Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 2, 0));
    EXPECT_LT((r.point - Vec3(0, 2, 0)).norm(), 1e-15)
        << "two coincident corners: got " << Str(r.point);
  }
  {
    // All corners coincide: a point.
    const TriangleClosestPoint r = ClosestPointOnTriangle(Vec3(1, 1, 1), Vec3(0.5, 0.5, 0.5),
                                                          Vec3(0.5, 0.5, 0.5), Vec3(0.5, 0.5, 0.5));
    EXPECT_LT((r.point - Vec3(0.5, 0.5, 0.5)).norm(), 1e-15)
        << "point triangle: got " << Str(r.point);
  }
}

}  // namespace
}  // namespace neuralmesh
