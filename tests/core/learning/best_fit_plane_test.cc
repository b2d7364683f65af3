#include "core/learning/best_fit_plane.h"

#include <cmath>
#include <memory>
#include <utility>

#include "core/point_cloud.h"
#include "core/sampling/point_cloud_sampler.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

std::unique_ptr<Sampler> SamplerOf(PointCloud cloud) {
  auto sampler = MakePointCloudSampler(std::make_shared<const PointCloud>(std::move(cloud)));
  EXPECT_TRUE(sampler.ok()) << sampler.status();
  return std::move(sampler).value();
}

void ExpectRightHandedOrthonormal(const BestFitPlane& plane) {
  EXPECT_NEAR(plane.u.norm(), 1, 1e-12);
  EXPECT_NEAR(plane.v.norm(), 1, 1e-12);
  EXPECT_NEAR(plane.normal.norm(), 1, 1e-12);
  EXPECT_NEAR(OpenMesh::dot(plane.u, plane.v), 0, 1e-12);
  EXPECT_NEAR(OpenMesh::dot(plane.u, plane.normal), 0, 1e-12);
  EXPECT_NEAR(OpenMesh::dot(OpenMesh::cross(plane.u, plane.v), plane.normal), 1, 1e-12);
}

// A 2 x 1 rectangle with noise of 0.1% of its length across it, in a tilted frame.
TEST(BestFitPlaneTest, FindsTheFrameAndExtentOfANoisyTiltedRectangle) {
  const Vec3 length_axis = Vec3(1, 2, 2) / 3.0;
  const Vec3 width_axis = Vec3(2, 1, -2) / 3.0;
  const Vec3 normal = OpenMesh::cross(length_axis, width_axis);
  const Vec3 centre(5, -1, 2);
  Random data_rng(7);
  PointCloud cloud;
  for (int i = 0; i < 20000; ++i) {
    const double x = 2 * data_rng.NextDouble() - 1;
    const double y = data_rng.NextDouble() - 0.5;
    const double z = 0.002 * (data_rng.NextDouble() - 0.5);
    const Vec3 p = centre + x * length_axis + y * width_axis + z * normal;
    cloud.positions.emplace_back(p[0], p[1], p[2]);
  }
  const std::unique_ptr<Sampler> sampler = SamplerOf(std::move(cloud));
  Random rng(1);
  const BestFitPlane plane = FitPlane(*sampler, rng, 4096);
  ExpectRightHandedOrthonormal(plane);
  EXPECT_GT(std::abs(OpenMesh::dot(plane.normal, normal)), 0.9999);
  EXPECT_GT(std::abs(OpenMesh::dot(plane.u, length_axis)), 0.99) << "u along the long side";
  EXPECT_LT((plane.center - centre).norm(), 0.03);
  // The farthest samples are near the corners, sqrt(1 + 0.25) from the centre.
  EXPECT_NEAR(plane.radius, std::sqrt(1.25), 0.03);
  EXPECT_LE(plane.radius, std::sqrt(1.25) + 0.03);
}

TEST(BestFitPlaneTest, TheSameGeneratorStateGivesTheSamePlane) {
  PointCloud cloud;
  Random data_rng(3);
  for (int i = 0; i < 1000; ++i) {
    cloud.positions.emplace_back(data_rng.NextDouble(), data_rng.NextDouble(),
                                 0.1 * data_rng.NextDouble());
  }
  const std::unique_ptr<Sampler> sampler = SamplerOf(std::move(cloud));
  Random a(42);
  Random b(42);
  const BestFitPlane first = FitPlane(*sampler, a, 500);
  const BestFitPlane second = FitPlane(*sampler, b, 500);
  EXPECT_EQ(first.center, second.center);
  EXPECT_EQ(first.normal, second.normal);
  EXPECT_EQ(first.u, second.u);
  EXPECT_EQ(first.radius, second.radius);
}

TEST(BestFitPlaneTest, PointsOnALineGiveAFrameAlongIt) {
  PointCloud cloud;
  for (int i = 0; i <= 100; ++i) cloud.positions.emplace_back(i * 0.01f, i * 0.01f, 0.f);
  const std::unique_ptr<Sampler> sampler = SamplerOf(std::move(cloud));
  Random rng(1);
  const BestFitPlane plane = FitPlane(*sampler, rng, 2000);
  ExpectRightHandedOrthonormal(plane);
  EXPECT_NEAR(std::abs(OpenMesh::dot(plane.u, Vec3(1, 1, 0).normalized())), 1, 1e-9);
  EXPECT_NEAR(plane.radius, std::sqrt(2.0) / 2, 0.02);
}

TEST(BestFitPlaneTest, OnePointGivesTheCoordinateAxesAndRadiusZero) {
  PointCloud cloud;
  cloud.positions.emplace_back(1.f, 2.f, 3.f);
  const std::unique_ptr<Sampler> sampler = SamplerOf(std::move(cloud));
  Random rng(1);
  const BestFitPlane plane = FitPlane(*sampler, rng, 16);
  ExpectRightHandedOrthonormal(plane);
  EXPECT_EQ(plane.center, Vec3(1, 2, 3));
  EXPECT_EQ(plane.radius, 0);
}

}  // namespace
}  // namespace neuralmesh
