#include "core/sampling/point_cloud_sampler.h"

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <utility>

#include "core/random.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

// Points on the x axis at x = 0, 1, ..., n - 1, so a sample names its index.
std::shared_ptr<const PointCloud> Line(int n, std::vector<float> weights = {}) {
  PointCloud cloud;
  for (int i = 0; i < n; ++i) cloud.positions.emplace_back(static_cast<float>(i), 0.f, 0.f);
  cloud.weights = std::move(weights);
  return std::make_shared<const PointCloud>(std::move(cloud));
}

// A sampler over Line(100), with equal weights when `weighted` (the weighted sampler's path).
std::unique_ptr<Sampler> LineSampler(bool weighted) {
  absl::StatusOr<std::unique_ptr<Sampler>> sampler =
      MakePointCloudSampler(weighted ? Line(100, std::vector<float>(100, 2.0f)) : Line(100));
  EXPECT_TRUE(sampler.ok()) << sampler.status();
  return sampler.ok() ? std::move(sampler).value() : nullptr;
}

std::map<int, int> CountIndices(const Sampler& sampler, int draws, uint64_t seed) {
  Random rng(seed);
  std::map<int, int> counts;
  for (int i = 0; i < draws; ++i) ++counts[static_cast<int>(std::lround(sampler.Sample(rng)[0]))];
  return counts;
}

TEST(PointCloudSamplerTest, UniformDrawsEveryPointEqually) {
  absl::StatusOr<std::unique_ptr<Sampler>> sampler = UniformPointCloudSampler::Create(Line(4));
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  const int n = 100000;
  const std::map<int, int> counts = CountIndices(**sampler, n, 5);
  ASSERT_EQ(counts.size(), 4u) << "every point should be drawn";
  for (const auto& [index, count] : counts) {
    EXPECT_NEAR(count / static_cast<double>(n), 0.25, 0.006) << "point " << index;
  }
}

TEST(PointCloudSamplerTest, UniformIgnoresWeights) {
  absl::StatusOr<std::unique_ptr<Sampler>> sampler =
      UniformPointCloudSampler::Create(Line(2, {0.0f, 1.0f}));
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  const std::map<int, int> counts = CountIndices(**sampler, 10000, 5);
  EXPECT_GT(counts.count(0), 0u) << "the uniform sampler must not look at weights";
}

TEST(PointCloudSamplerTest, WeightThreeDrawnThreeTimesAsOften) {
  absl::StatusOr<std::unique_ptr<Sampler>> sampler =
      WeightedPointCloudSampler::Create(Line(3, {1.0f, 3.0f, 0.0f}));
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  std::map<int, int> counts = CountIndices(**sampler, 100000, 11);
  EXPECT_EQ(counts[2], 0) << "a point of weight zero was drawn";
  ASSERT_GT(counts[0], 0) << "the point of weight 1 was never drawn";
  EXPECT_NEAR(counts[1] / static_cast<double>(counts[0]), 3.0, 0.1)
      << "weight 3 should be drawn about 3 times as often as weight 1 (Section 4.1)";
}

TEST(PointCloudSamplerTest, MakePointCloudSamplerPicksWeightedWhenWeightsExist) {
  absl::StatusOr<std::unique_ptr<Sampler>> weighted = MakePointCloudSampler(Line(2, {0.0f, 1.0f}));
  ASSERT_TRUE(weighted.ok()) << weighted.status();
  std::map<int, int> counts = CountIndices(**weighted, 10000, 2);
  EXPECT_EQ(counts[0], 0) << "with weights, the point of weight zero must never be drawn";

  absl::StatusOr<std::unique_ptr<Sampler>> uniform = MakePointCloudSampler(Line(2));
  ASSERT_TRUE(uniform.ok()) << uniform.status();
  counts = CountIndices(**uniform, 10000, 2);
  EXPECT_GT(counts[0], 4000) << "without weights, both points should be drawn about equally";
}

TEST(PointCloudSamplerTest, DeterministicForSeed) {
  for (bool weighted : {false, true}) {
    const std::unique_ptr<Sampler> sampler = LineSampler(weighted);
    ASSERT_NE(sampler, nullptr);
    Random a(123);
    Random b(123);
    for (int i = 0; i < 1000; ++i) {
      ASSERT_EQ(sampler->Sample(a), sampler->Sample(b))
          << "same seed, different sample " << i << " (weighted: " << weighted << ")";
    }
  }
}

TEST(PointCloudSamplerTest, PrefetchingLeavesTheSequenceAlone) {
  for (bool weighted : {false, true}) {
    const std::unique_ptr<Sampler> sampler = LineSampler(weighted);
    ASSERT_NE(sampler, nullptr);
    Random plain(7);
    Random prefetching(7);
    for (int i = 0; i < 1000; ++i) {
      sampler->PrefetchSample(prefetching);
      ASSERT_EQ(sampler->Sample(plain), sampler->Sample(prefetching))
          << "prefetching changed sample " << i << " (weighted: " << weighted << ")";
    }
  }
}

TEST(PointCloudSamplerTest, BoundsCoverAllPoints) {
  absl::StatusOr<std::unique_ptr<Sampler>> sampler = MakePointCloudSampler(Line(10));
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  const BoundingBox box = (*sampler)->Bounds();
  EXPECT_EQ(box.min, Vec3(0, 0, 0)) << "lower corner";
  EXPECT_EQ(box.max, Vec3(9, 0, 0)) << "upper corner";
  EXPECT_FALSE((*sampler)->empty()) << "a sampler over 10 points is not empty";
}

TEST(PointCloudSamplerTest, SharesTheCloudInsteadOfCopying) {
  const std::shared_ptr<const PointCloud> cloud = Line(5);
  absl::StatusOr<std::unique_ptr<Sampler>> sampler = UniformPointCloudSampler::Create(cloud);
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  EXPECT_EQ(&static_cast<const UniformPointCloudSampler&>(**sampler).cloud(), cloud.get())
      << "the sampler should hold the caller's cloud";
}

TEST(PointCloudSamplerTest, RejectsInvalidClouds) {
  PointCloud nan_point;
  nan_point.positions = {Vec3f(0, 0, 0), Vec3f(std::numeric_limits<float>::quiet_NaN(), 0, 0)};
  PointCloud wrong_weights;
  wrong_weights.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
  wrong_weights.weights = {1.0f};
  PointCloud zero_weights;
  zero_weights.positions = {Vec3f(0, 0, 0)};
  zero_weights.weights = {0.0f};
  PointCloud negative_weight;
  negative_weight.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
  negative_weight.weights = {1.0f, -1.0f};
  const std::vector<std::pair<std::string, std::shared_ptr<const PointCloud>>> cases = {
      {"null", nullptr},
      {"empty", std::make_shared<const PointCloud>()},
      {"NaN position", std::make_shared<const PointCloud>(nan_point)},
      {"weight count", std::make_shared<const PointCloud>(wrong_weights)},
      {"all-zero weights", std::make_shared<const PointCloud>(zero_weights)},
      {"negative weight", std::make_shared<const PointCloud>(negative_weight)},
  };
  for (const auto& [name, cloud] : cases) {
    EXPECT_EQ(MakePointCloudSampler(cloud).status().code(), absl::StatusCode::kInvalidArgument)
        << "MakePointCloudSampler should reject: " << name;
    EXPECT_EQ(UniformPointCloudSampler::Create(cloud).status().code(),
              absl::StatusCode::kInvalidArgument)
        << "UniformPointCloudSampler should reject: " << name;
    EXPECT_EQ(WeightedPointCloudSampler::Create(cloud).status().code(),
              absl::StatusCode::kInvalidArgument)
        << "WeightedPointCloudSampler should reject: " << name;
  }
  EXPECT_EQ(WeightedPointCloudSampler::Create(Line(3)).status().code(),
            absl::StatusCode::kInvalidArgument)
      << "a weighted sampler needs weights";
}

}  // namespace
}  // namespace neuralmesh
