#include "core/sampling/sample_points.h"

#include <memory>

#include "core/random.h"
#include "core/sampling/growing_point_cloud.h"
#include "core/sampling/implicit_surfaces.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

TEST(SamplePointsTest, DrawsNPointsReproduciblyFromTheSeed) {
  absl::StatusOr<std::unique_ptr<ImplicitSurface>> sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  ASSERT_TRUE(sphere.ok()) << sphere.status();
  const PointCloud a = SamplePoints(**sphere, 500, 10);
  const PointCloud b = SamplePoints(**sphere, 500, 10);
  const PointCloud c = SamplePoints(**sphere, 500, 11);
  ASSERT_EQ(a.size(), 500u) << "n points";
  EXPECT_TRUE(a.weights.empty()) << "positions only";
  EXPECT_TRUE(a.normals.empty()) << "positions only";
  EXPECT_EQ(a.positions, b.positions) << "the same seed gives the same cloud";
  EXPECT_NE(a.positions, c.positions) << "another seed gives another cloud";
  // The cloud is the sampler's sequence for a Random with that seed.
  Random rng(10);
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.positions[i], Vec3f((*sphere)->Sample(rng))) << "point " << i;
  }
  EXPECT_TRUE(ValidatePointCloud(a).ok()) << "a valid cloud";
}

TEST(SamplePointsTest, EmptySamplerGivesEmptyCloud) {
  GrowingPointCloud empty;
  EXPECT_TRUE(SamplePoints(empty, 100, 1).empty()) << "nothing to sample, nothing drawn";
}

}  // namespace
}  // namespace neuralmesh
