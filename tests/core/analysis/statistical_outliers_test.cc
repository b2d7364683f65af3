#include "core/analysis/statistical_outliers.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/random.h"
#include "core/sampling/implicit_surfaces.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

PointCloud SpherePoints(size_t n, uint64_t seed) {
  auto sphere = MakeSphere(Vec3(0, 0, 0), 1.0).value();
  Random rng(seed);
  PointCloud cloud;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 p = sphere->Sample(rng);
    cloud.positions.emplace_back(p[0], p[1], p[2]);
  }
  return cloud;
}

// The definition, by brute force: mean distance to the k nearest other points, then the limit
// mean + ratio * sample standard deviation.
std::vector<bool> BruteForceOutliers(const PointCloud& cloud, int k, double ratio) {
  const size_t n = cloud.size();
  std::vector<double> mean_distance(n);
  for (size_t i = 0; i < n; ++i) {
    std::vector<float> d2;
    for (size_t j = 0; j < n; ++j) {
      if (j != i) d2.push_back((cloud.positions[j] - cloud.positions[i]).sqrnorm());
    }
    std::partial_sort(d2.begin(), d2.begin() + k, d2.end());
    double sum = 0;
    for (int j = 0; j < k; ++j) sum += std::sqrt(d2[j]);
    mean_distance[i] = sum / k;
  }
  double mean = 0;
  for (double d : mean_distance) mean += d / n;
  double squares = 0;
  for (double d : mean_distance) squares += (d - mean) * (d - mean);
  const double limit = mean + ratio * std::sqrt(squares / (n - 1));
  std::vector<bool> outlier(n);
  for (size_t i = 0; i < n; ++i) outlier[i] = mean_distance[i] > limit;
  return outlier;
}

// Strays from 1.5 to 1,000 radii from a unit sphere, in two clouds: the farthest widen the
// deviation enough to hide the nearest (one pass, as PCL and Open3D define it).
TEST(StatisticalOutliersTest, StrayPointsAreFoundAndTheSurfaceIsKept) {
  for (const std::vector<Vec3f>& strays :
       {std::vector<Vec3f>{Vec3f(30, 0, 0), Vec3f(0, -100, 0), Vec3f(0, 0, 1000)},
        std::vector<Vec3f>{Vec3f(2, 2, 2), Vec3f(-1.5f, 0.3f, 0.2f), Vec3f(0, 0, 3)}}) {
    PointCloud cloud = SpherePoints(20000, 1);
    for (const Vec3f& p : strays) cloud.positions.push_back(p);
    const auto outlier = FindStatisticalOutliers(cloud, OutlierOptions{});
    ASSERT_TRUE(outlier.ok()) << outlier.status();
    for (size_t i = 20000; i < cloud.size(); ++i) {
      EXPECT_TRUE((*outlier)[i]) << "stray at " << cloud.positions[i];
    }
    const size_t surface_flagged = std::count(outlier->begin(), outlier->begin() + 20000, true);
    EXPECT_LT(surface_flagged, 100u) << "more than 0.5% of the sphere's points taken for outliers";
  }
}

// Strays at 100 and 1,000 radii widen the deviation enough to hide one at 2 radii from the
// first pass; the second, over the points the first kept, finds it. A pass that finds nothing
// ends the removal.
TEST(StatisticalOutliersTest, ASecondPassFindsTheStraysTheFarthestHid) {
  PointCloud cloud = SpherePoints(20000, 1);
  cloud.weights.assign(cloud.size(), 1.0f);
  for (const Vec3f& p : {Vec3f(0, -100, 0), Vec3f(0, 0, 1000), Vec3f(2, 0, 0)}) {
    cloud.positions.push_back(p);
    cloud.weights.push_back(7.0f);
  }
  const auto one_pass = FindStatisticalOutliers(cloud, OutlierOptions{});
  ASSERT_TRUE(one_pass.ok()) << one_pass.status();
  EXPECT_TRUE((*one_pass)[20000] && (*one_pass)[20001]);
  EXPECT_FALSE((*one_pass)[20002]) << "the first pass found the mild stray: nothing to show";

  OutlierOptions options;
  options.passes = 2;
  PointCloud cleaned = cloud;
  const absl::StatusOr<size_t> removed = RemoveStatisticalOutliers(cleaned, options);
  ASSERT_TRUE(removed.ok()) << removed.status();
  EXPECT_EQ(*removed, cloud.size() - cleaned.size());
  // The three strays and no point of the sphere (a third pass would take its own far end: 55
  // points here, a fourth 53 more).
  EXPECT_EQ(*removed, 3u);
  ASSERT_EQ(cleaned.weights.size(), cleaned.size());
  for (size_t i = 0; i < cleaned.size(); ++i) {
    ASSERT_LT(cleaned.positions[i].norm(), 1.01f) << "a stray was kept";
    ASSERT_EQ(cleaned.weights[i], 1.0f) << "weights left their points";
  }
  // The flags over both passes, by index in the whole cloud: the three strays, the mild one
  // found by the second pass.
  const auto flagged = FindStatisticalOutliersInPasses(cloud, options);
  ASSERT_TRUE(flagged.ok()) << flagged.status();
  ASSERT_EQ(flagged->size(), cloud.size());
  EXPECT_EQ(std::count(flagged->begin(), flagged->end(), true), 3);
  EXPECT_TRUE((*flagged)[20000] && (*flagged)[20001] && (*flagged)[20002]);
  // A third pass judges the points the second kept (`cleaned`, in their order): its flags, by
  // index in the whole cloud, are the two passes' and those of one pass over `cleaned`.
  options.passes = 3;
  const auto thrice = FindStatisticalOutliersInPasses(cloud, options);
  ASSERT_TRUE(thrice.ok()) << thrice.status();
  const auto third = FindStatisticalOutliers(cleaned, OutlierOptions{});
  ASSERT_TRUE(third.ok()) << third.status();
  size_t kept = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_EQ((*thrice)[i], (*flagged)[i] || (*third)[kept]) << "point " << i;
    kept += !(*flagged)[i];
  }
  EXPECT_EQ(std::count(thrice->begin(), thrice->end(), true), 3 + 55);

  options.passes = 1;
  PointCloud once = cloud;
  ASSERT_TRUE(RemoveStatisticalOutliers(once, options).ok());
  EXPECT_EQ(once.positions.back(), Vec3f(2, 0, 0)) << "one pass is FindStatisticalOutliers";
  for (const int passes : {0, 17}) {
    options.passes = passes;
    const absl::Status status = RemoveStatisticalOutliers(once, options).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(status.message().find("passes"), absl::string_view::npos) << status;
  }
}

TEST(StatisticalOutliersTest, AgreesWithTheDefinitionComputedByBruteForce) {
  Random rng(5);
  PointCloud cloud = SpherePoints(1500, 2);
  for (int i = 0; i < 15; ++i) {  // Points scattered in the box around the sphere.
    cloud.positions.emplace_back(4 * rng.NextDouble() - 2, 4 * rng.NextDouble() - 2,
                                 4 * rng.NextDouble() - 2);
  }
  for (int k : {1, 4, 16}) {
    for (double ratio : {1.0, 3.0}) {
      OutlierOptions options;
      options.neighbours = k;
      options.std_ratio = ratio;
      const auto outlier = FindStatisticalOutliers(cloud, options);
      ASSERT_TRUE(outlier.ok()) << outlier.status();
      EXPECT_EQ(*outlier, BruteForceOutliers(cloud, k, ratio)) << "k " << k << ", ratio " << ratio;
    }
  }
}

TEST(StatisticalOutliersTest, ThreadsDoNotChangeTheResult) {
  PointCloud cloud = SpherePoints(30000, 3);
  cloud.positions.emplace_back(5.f, 5.f, 5.f);
  OutlierOptions one;
  one.threads = 1;
  OutlierOptions four;
  four.threads = 4;
  EXPECT_EQ(FindStatisticalOutliers(cloud, one).value(),
            FindStatisticalOutliers(cloud, four).value());
}

TEST(StatisticalOutliersTest, ACloudOfAtMostKPointsHasNoOutliers) {
  PointCloud cloud;
  for (int i = 0; i < 16; ++i) cloud.positions.emplace_back(i == 0 ? 1000.f : 0.f, i, 0.f);
  const auto outlier = FindStatisticalOutliers(cloud, OutlierOptions{});
  ASSERT_TRUE(outlier.ok());
  EXPECT_EQ(*outlier, std::vector<bool>(16, false));
  EXPECT_TRUE(FindStatisticalOutliers(PointCloud{}, OutlierOptions{})->empty());
}

TEST(StatisticalOutliersTest, InvalidOptionsAreRejectedNamingTheField) {
  OutlierOptions options;
  options.neighbours = 0;
  absl::Status status = FindStatisticalOutliers(SpherePoints(100, 1), options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("neighbours"), absl::string_view::npos) << status;
  options = {};
  options.std_ratio = 0;
  status = FindStatisticalOutliers(SpherePoints(100, 1), options).status();
  EXPECT_NE(status.message().find("std_ratio"), absl::string_view::npos) << status;
}

TEST(StatisticalOutliersTest, WithoutPointsKeepsWeightsAndNormalsWithTheirPoints) {
  PointCloud cloud;
  for (int i = 0; i < 4; ++i) {
    cloud.positions.emplace_back(i, 0.f, 0.f);
    cloud.weights.push_back(10.f * i);
    cloud.normals.emplace_back(0.f, 0.f, i);
  }
  const PointCloud kept = WithoutPoints(cloud, {false, true, false, true});
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept.positions[1], Vec3f(2, 0, 0));
  EXPECT_EQ(kept.weights, std::vector<float>({0.f, 20.f}));
  EXPECT_EQ(kept.normals[1], Vec3f(0, 0, 2));
}

}  // namespace
}  // namespace neuralmesh
