#include "core/sampling/marching_tetrahedra.h"

#include <cmath>
#include <limits>

#include "gtest/gtest.h"
#include "tests/core/sampling/surface_topology.h"

namespace neuralmesh {
namespace {

BoundingBox Cube(double half) {
  BoundingBox box;
  box.Extend(Vec3(-half));
  box.Extend(Vec3(half));
  return box;
}

TEST(MarchingTetrahedraTest, SphereIsAClosedOutwardGenusZeroSurface) {
  const double radius = 0.8;
  auto f = [radius](const Vec3& p) { return p.norm() - radius; };
  absl::StatusOr<TriangleMesh> mesh = MarchingTetrahedra(f, Cube(1.0), {12, 13, 14});
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const testing::SurfaceTopology topology = testing::MeasureTopology(*mesh);
  ASSERT_TRUE(topology.problem.empty()) << "not a closed manifold: " << topology.problem;
  EXPECT_EQ(topology.euler, 2) << "a sphere has Euler characteristic 2";
  EXPECT_EQ(topology.components, 1) << "one sphere, one component";
  EXPECT_NEAR(topology.volume, 4.0 / 3.0 * M_PI * radius * radius * radius, 0.1)
      << "faces should face outward and enclose about the ball's volume";
  // Linear interpolation along edges of length <= sqrt(3) h stays within that of the surface.
  const double h = 2.0 / 12 * std::sqrt(3.0);
  for (const Vec3f& p : mesh->positions) {
    ASSERT_LT(std::abs(f(Vec3(p))), 0.1 * h) << "vertex " << p << " is far from the sphere";
  }
}

TEST(MarchingTetrahedraTest, TwoBallsGiveTwoComponents) {
  auto f = [](const Vec3& p) {
    return std::min((p - Vec3(-0.5, 0, 0)).norm(), (p - Vec3(0.5, 0, 0)).norm()) - 0.3;
  };
  absl::StatusOr<TriangleMesh> mesh = MarchingTetrahedra(f, Cube(1.0), {20, 20, 20});
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const testing::SurfaceTopology topology = testing::MeasureTopology(*mesh);
  ASSERT_TRUE(topology.problem.empty()) << "not a closed manifold: " << topology.problem;
  EXPECT_EQ(topology.components, 2) << "two separate balls";
  EXPECT_EQ(topology.euler, 4) << "two spheres";
}

TEST(MarchingTetrahedraTest, TorusHasGenusOne) {
  auto f = [](const Vec3& p) { return std::hypot(std::hypot(p[0], p[1]) - 0.6, p[2]) - 0.25; };
  absl::StatusOr<TriangleMesh> mesh = MarchingTetrahedra(f, Cube(1.0), {24, 24, 24});
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const testing::SurfaceTopology topology = testing::MeasureTopology(*mesh);
  ASSERT_TRUE(topology.problem.empty()) << "not a closed manifold: " << topology.problem;
  EXPECT_EQ(topology.euler, 0) << "a torus has Euler characteristic 0";
  EXPECT_GT(topology.volume, 0) << "faces should face outward";
}

TEST(MarchingTetrahedraTest, NothingInsideGivesAnEmptyMesh) {
  absl::StatusOr<TriangleMesh> mesh =
      MarchingTetrahedra([](const Vec3&) { return 1.0; }, Cube(1.0), {3, 3, 3});
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_TRUE(mesh->faces.empty()) << "a function without a zero has no surface";
}

TEST(MarchingTetrahedraTest, RejectsInvalidInput) {
  auto sphere = [](const Vec3& p) { return p.norm() - 0.5; };
  EXPECT_EQ(MarchingTetrahedra(sphere, Cube(1.0), {0, 4, 4}).status().code(),
            absl::StatusCode::kInvalidArgument)
      << "zero cells";
  EXPECT_EQ(MarchingTetrahedra(sphere, BoundingBox(), {4, 4, 4}).status().code(),
            absl::StatusCode::kInvalidArgument)
      << "empty box";
  BoundingBox flat;
  flat.Extend(Vec3(0, 0, 0));
  flat.Extend(Vec3(1, 1, 0));
  EXPECT_EQ(MarchingTetrahedra(sphere, flat, {4, 4, 4}).status().code(),
            absl::StatusCode::kInvalidArgument)
      << "flat box";
  EXPECT_EQ(MarchingTetrahedra(sphere, Cube(0.4), {4, 4, 4}).status().code(),
            absl::StatusCode::kInvalidArgument)
      << "the sphere leaves the box";
  auto nan = [](const Vec3&) { return std::numeric_limits<double>::quiet_NaN(); };
  EXPECT_EQ(MarchingTetrahedra(nan, Cube(1.0), {4, 4, 4}).status().code(),
            absl::StatusCode::kInvalidArgument)
      << "a NaN value";
  EXPECT_EQ(MarchingTetrahedra(sphere, Cube(1.0), {2000, 2000, 2000}).status().code(),
            absl::StatusCode::kInvalidArgument)
      << "more than 2^31 grid points";
}

}  // namespace
}  // namespace neuralmesh
