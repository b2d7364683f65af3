#include "core/sampling/growing_point_cloud.h"

#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "core/random.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

std::vector<Vec3f> LinePoints(int begin, int end) {
  std::vector<Vec3f> points;
  for (int i = begin; i < end; ++i) points.emplace_back(static_cast<float>(i), 2.f * i, -1.f * i);
  return points;
}

std::map<int, int> CountIndices(const Sampler& sampler, int draws, uint64_t seed) {
  Random rng(seed);
  std::map<int, int> counts;
  for (int i = 0; i < draws; ++i) ++counts[static_cast<int>(std::lround(sampler.Sample(rng)[0]))];
  return counts;
}

TEST(GrowingPointCloudTest, StartsEmpty) {
  GrowingPointCloud cloud;
  EXPECT_TRUE(cloud.empty()) << "a new cloud has nothing to sample";
  EXPECT_EQ(cloud.size(), 0u) << "a new cloud has no points";
  EXPECT_TRUE(cloud.Bounds().empty()) << "a new cloud has an empty box";
  EXPECT_EQ(cloud.max_points(), size_t{1} << 31) << "the default capacity";
  EXPECT_TRUE(cloud.Copy().empty()) << "a new cloud copies to nothing";
  EXPECT_TRUE(cloud.Append(absl::Span<const Vec3f>()).ok()) << "an empty batch is fine";
  EXPECT_TRUE(cloud.empty()) << "an empty batch appends nothing";
}

TEST(GrowingPointCloudTest, AppendsAcrossChunksAndCopiesBack) {
  GrowingPointCloud cloud;
  // 70000-point batches straddle the 65536-point chunks.
  ASSERT_TRUE(cloud.Append(LinePoints(0, 70000)).ok()) << "first batch";
  ASSERT_TRUE(cloud.Append(LinePoints(70000, 140000)).ok()) << "second batch";
  EXPECT_EQ(cloud.size(), 140000u) << "both batches are visible";
  const PointCloud copy = cloud.Copy();
  ASSERT_EQ(copy.size(), 140000u) << "Copy returns every point";
  EXPECT_TRUE(copy.weights.empty()) << "no batch had weights";
  EXPECT_TRUE(copy.normals.empty()) << "no batch had normals";
  for (int i = 0; i < 140000; ++i) {
    ASSERT_EQ(copy.positions[i], Vec3f(i, 2.f * i, -1.f * i)) << "point " << i;
  }
  const BoundingBox box = cloud.Bounds();
  EXPECT_EQ(box.min, Vec3(0, 0, -139999)) << "lower corner";
  EXPECT_EQ(box.max, Vec3(139999, 2 * 139999, 0)) << "upper corner";
}

TEST(GrowingPointCloudTest, UniformUntilWeightsArrive) {
  GrowingPointCloud cloud;
  ASSERT_TRUE(cloud.Append(LinePoints(0, 2)).ok()) << "unweighted batch";
  std::map<int, int> counts = CountIndices(cloud, 20000, 1);
  EXPECT_NEAR(counts[0] / 20000.0, 0.5, 0.02) << "two unweighted points are drawn equally";

  // Point 2 weighs 3, point 3 weighs 0; points 0 and 1 had no weights and weigh 1.
  const std::vector<float> weights = {3.0f, 0.0f};
  ASSERT_TRUE(cloud.Append(LinePoints(2, 4), weights).ok()) << "weighted batch";
  counts = CountIndices(cloud, 100000, 2);
  EXPECT_EQ(counts[3], 0) << "a point of weight zero was drawn";
  ASSERT_GT(counts[0], 0) << "point 0 (weight 1) was never drawn";
  EXPECT_NEAR(counts[2] / static_cast<double>(counts[0]), 3.0, 0.12)
      << "weight 3 should be drawn about 3 times as often as the weight-1 point";
  EXPECT_NEAR(counts[1] / static_cast<double>(counts[0]), 1.0, 0.06)
      << "the two points without weights weigh the same";

  ASSERT_TRUE(cloud.Append(LinePoints(4, 5)).ok()) << "unweighted batch after weights";
  const PointCloud copy = cloud.Copy();
  EXPECT_EQ(copy.weights, (std::vector<float>{1, 1, 3, 0, 1}))
      << "points from batches without weights weigh 1";
  EXPECT_TRUE(copy.normals.empty()) << "no batch had normals";
  EXPECT_TRUE(ValidatePointCloud(copy).ok()) << "Copy gives a valid cloud";
}

TEST(GrowingPointCloudTest, NormalsFilledWithZeroWhereMissing) {
  GrowingPointCloud cloud;
  ASSERT_TRUE(cloud.Append(LinePoints(0, 1)).ok()) << "batch without normals";
  const std::vector<Vec3f> normals = {Vec3f(0, 0, 1)};
  ASSERT_TRUE(cloud.Append(LinePoints(1, 2), {}, normals).ok()) << "batch with normals";
  ASSERT_TRUE(cloud.Append(LinePoints(2, 3)).ok()) << "batch without normals";
  const PointCloud copy = cloud.Copy();
  EXPECT_EQ(copy.normals, (std::vector<Vec3f>{Vec3f(0, 0, 0), Vec3f(0, 0, 1), Vec3f(0, 0, 0)}))
      << "missing normals are zero";
  EXPECT_TRUE(copy.weights.empty()) << "no batch had weights";
}

TEST(GrowingPointCloudTest, AppendsAPointCloud) {
  GrowingPointCloud cloud;
  PointCloud batch;
  batch.positions = LinePoints(0, 3);
  batch.weights = {1.0f, 2.0f, 3.0f};
  batch.normals = {Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 0, 1)};
  ASSERT_TRUE(cloud.Append(batch).ok()) << "a valid PointCloud batch";
  const PointCloud copy = cloud.Copy();
  EXPECT_EQ(copy.positions, batch.positions) << "positions round-trip";
  EXPECT_EQ(copy.weights, batch.weights) << "weights round-trip";
  EXPECT_EQ(copy.normals, batch.normals) << "normals round-trip";
}

TEST(GrowingPointCloudTest, DeterministicForSeed) {
  GrowingPointCloud cloud;
  std::vector<float> weights(1000);
  for (int i = 0; i < 1000; ++i) weights[i] = static_cast<float>(i % 5);
  ASSERT_TRUE(cloud.Append(LinePoints(0, 1000), weights).ok()) << "weighted batch";
  Random a(8);
  Random b(8);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(cloud.Sample(a), cloud.Sample(b)) << "same seed, different sample " << i;
  }
}

TEST(GrowingPointCloudTest, RejectsInvalidBatchesAndAppendsNothing) {
  GrowingPointCloud cloud;
  ASSERT_TRUE(cloud.Append(LinePoints(0, 3)).ok()) << "initial batch";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<Vec3f> two = LinePoints(3, 5);
  const std::vector<Vec3f> with_nan = {Vec3f(1, 1, 1), Vec3f(0, nan, 0)};
  const std::vector<Vec3f> with_inf = {Vec3f(inf, 1, 1)};

  EXPECT_EQ(cloud.Append(with_nan).code(), absl::StatusCode::kInvalidArgument) << "NaN position";
  EXPECT_EQ(cloud.Append(with_inf).code(), absl::StatusCode::kInvalidArgument) << "inf position";
  EXPECT_EQ(cloud.Append(two, std::vector<float>{1.0f}).code(), absl::StatusCode::kInvalidArgument)
      << "one weight for two points";
  EXPECT_EQ(cloud.Append(two, std::vector<float>{1.0f, nan}).code(),
            absl::StatusCode::kInvalidArgument)
      << "NaN weight";
  EXPECT_EQ(cloud.Append(two, std::vector<float>{1.0f, -2.0f}).code(),
            absl::StatusCode::kInvalidArgument)
      << "negative weight";
  EXPECT_EQ(cloud.Append(two, {}, std::vector<Vec3f>{Vec3f(0, 0, 1)}).code(),
            absl::StatusCode::kInvalidArgument)
      << "one normal for two points";
  EXPECT_EQ(cloud.Append(two, {}, std::vector<Vec3f>{Vec3f(0, 0, 1), Vec3f(nan, 0, 0)}).code(),
            absl::StatusCode::kInvalidArgument)
      << "NaN normal";
  EXPECT_EQ(cloud.Append({}, std::vector<float>{1.0f}).code(), absl::StatusCode::kInvalidArgument)
      << "a weight without a point";
  EXPECT_EQ(cloud.size(), 3u) << "rejected batches must append nothing";
  const PointCloud copy = cloud.Copy();
  EXPECT_TRUE(copy.weights.empty()) << "rejected batches must not switch weights on";
  EXPECT_TRUE(copy.normals.empty()) << "rejected batches must not switch normals on";
}

TEST(GrowingPointCloudTest, OverCapacityIsResourceExhausted) {
  GrowingPointCloud cloud(5);
  EXPECT_EQ(cloud.max_points(), 5u) << "the capacity asked for";
  ASSERT_TRUE(cloud.Append(LinePoints(0, 3)).ok()) << "3 of 5";
  EXPECT_EQ(cloud.Append(LinePoints(3, 6), std::vector<float>{1, 1, 1}).code(),
            absl::StatusCode::kResourceExhausted)
      << "3 more would make 6 > 5";
  EXPECT_EQ(cloud.size(), 3u) << "the batch over capacity must append nothing";
  EXPECT_TRUE(cloud.Copy().weights.empty()) << "the rejected batch must not switch weights on";
  EXPECT_EQ(cloud.Bounds().max, Vec3(2, 4, 0)) << "the rejected batch must not grow the box";
  EXPECT_TRUE(cloud.Append(LinePoints(3, 5)).ok()) << "exactly up to capacity is fine";
  EXPECT_EQ(cloud.Append(LinePoints(5, 6)).code(), absl::StatusCode::kResourceExhausted)
      << "a full cloud takes nothing more";
  EXPECT_EQ(cloud.size(), 5u) << "the cloud is full";
}

TEST(GrowingPointCloudTest, CapacityIsClampedTo2To34) {
  GrowingPointCloud cloud(std::numeric_limits<size_t>::max());
  EXPECT_EQ(cloud.max_points(), size_t{1} << 34) << "huge capacities are lowered to 2^34";
}

TEST(GrowingPointCloudTest, AllZeroWeightsOnlyRejectedWhenNothingCouldBeSampled) {
  GrowingPointCloud cloud;
  EXPECT_EQ(cloud.Append(LinePoints(0, 2), std::vector<float>{0, 0}).code(),
            absl::StatusCode::kInvalidArgument)
      << "a first batch of zero weights leaves nothing to sample";
  EXPECT_TRUE(cloud.empty()) << "the rejected batch appended nothing";
  ASSERT_TRUE(cloud.Append(LinePoints(0, 1), std::vector<float>{2}).ok()) << "positive weight";
  EXPECT_TRUE(cloud.Append(LinePoints(1, 3), std::vector<float>{0, 0}).ok())
      << "zero weights are fine once something can be sampled";
  const std::map<int, int> counts = CountIndices(cloud, 1000, 4);
  EXPECT_EQ(counts.size(), 1u) << "only the point of positive weight may be drawn";
}

}  // namespace
}  // namespace neuralmesh
