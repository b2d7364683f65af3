#include "core/sampling/growing_point_cloud.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
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

TEST(GrowingPointCloudTest, PrefetchingLeavesTheSequenceAlone) {
  GrowingPointCloud cloud;
  Random unused(1);
  cloud.PrefetchSample(unused);  // Nothing to load on an empty cloud.
  ASSERT_TRUE(cloud.Append(LinePoints(0, 100)).ok()) << "batch without weights";
  for (bool weighted : {false, true}) {
    if (weighted) {
      std::vector<float> weights(100);
      for (int i = 0; i < 100; ++i) weights[i] = i % 4 == 0 ? 0.0f : 0.1f * i;
      ASSERT_TRUE(cloud.Append(LinePoints(100, 200), weights).ok()) << "weighted batch";
    }
    Random plain(7);
    Random prefetching(7);
    for (int i = 0; i < 1000; ++i) {
      cloud.PrefetchSample(prefetching);
      ASSERT_EQ(cloud.Sample(plain), cloud.Sample(prefetching))
          << "prefetching changed sample " << i << " (weighted: " << weighted << ")";
    }
  }
}

// How many NextU64 calls took `before` to `after`, if at most `limit`; -1 otherwise. Two states
// are taken as equal when their next two outputs are (a false match has probability 2^-128).
int DrawsBetween(Random before, const Random& after, int limit) {
  for (int k = 0; k <= limit; ++k) {
    Random a = before;
    Random b = after;
    if (a.NextU64() == b.NextU64() && a.NextU64() == b.NextU64()) return k;
    before.NextU64();
  }
  return -1;
}

// Samples `cloud` `draws` times and expects every sample to be point `heavy`, counting the tries
// each sample takes: a rejection against the largest weight takes about size() of them on a
// skewed cloud, the weight classes at most 2 in expectation whatever the weights. Every
// weighted sample takes exactly one draw of the caller's generator (PrefetchSample relies on it).
void ExpectHeavyPointDrawnCheaply(const GrowingPointCloud& cloud, int heavy, int draws,
                                  const std::string& what) {
  constexpr int kMaxTriesPerSample = 60;  // Each try fails with probability below 1/2.
  constexpr double kMaxMeanTries = 2.0;
  Random rng(42);
  long total_tries = 0;
  int others = 0;
  for (int s = 0; s < draws; ++s) {
    const Random before = rng;
    int tries = 0;
    const Vec3 p = cloud.Sample(rng, &tries);
    ASSERT_EQ(DrawsBetween(before, rng, 3), 1) << what << ": sample " << s;
    ASSERT_LE(tries, kMaxTriesPerSample) << what << ": sample " << s;
    total_tries += tries;
    if (std::lround(p[0]) != heavy) ++others;
  }
  EXPECT_EQ(others, 0) << what << ": points other than the heavy one were drawn";
  EXPECT_LE(total_tries / static_cast<double>(draws), kMaxMeanTries)
      << what << ": too many tries per sample";
}

// One point of weight 1 among a million of weight 0, and one of 1e30 among a million of 1e-30:
// a sample must not cost a million draws (a client could hold the learner for seconds).
TEST(GrowingPointCloudTest, SkewedWeightsSampleInConstantTime) {
  constexpr int kPoints = 1000000;
  constexpr int kHeavy = 123457;
  const std::vector<Vec3f> positions = LinePoints(0, kPoints);
  {
    GrowingPointCloud cloud;
    std::vector<float> weights(kPoints, 0.0f);
    weights[kHeavy] = 1.0f;
    ASSERT_TRUE(cloud.Append(positions, weights).ok()) << "one point of weight 1";
    ExpectHeavyPointDrawnCheaply(cloud, kHeavy, 10000, "weights 1 and 0");
  }
  {
    GrowingPointCloud cloud;
    std::vector<float> weights(kPoints, 1e-30f);
    weights[kHeavy] = 1e30f;
    ASSERT_TRUE(cloud.Append(positions, weights).ok()) << "one point of weight 1e30";
    ExpectHeavyPointDrawnCheaply(cloud, kHeavy, 10000, "weights 1e30 and 1e-30");
  }
  {
    // The heavy point comes last, in a batch of its own, after the light ones.
    GrowingPointCloud cloud;
    ASSERT_TRUE(cloud.Append(positions, std::vector<float>(kPoints, std::ldexp(1.0f, -100))).ok())
        << "a million points of weight 2^-100";
    ASSERT_TRUE(cloud.Append(LinePoints(kPoints, kPoints + 1), std::vector<float>{3e38f}).ok())
        << "one point of weight 3e38";
    ExpectHeavyPointDrawnCheaply(cloud, kPoints, 10000, "weights 3e38 and 2^-100");
  }
}

// Weights spread log-uniformly over six decades: a rejection against the largest weight would
// take about 14 tries per sample (the largest weight over the mean), the weight classes fewer
// than 2 (each try is kept with probability w / U > 1/2; here about 0.72 on average).
TEST(GrowingPointCloudTest, SpreadWeightsTakeFewTries) {
  constexpr int kPoints = 100000;
  constexpr int kDraws = 100000;
  std::vector<float> weights;
  Random weight_rng(3);
  for (int i = 0; i < kPoints; ++i) {
    weights.push_back(static_cast<float>(std::pow(10.0, -6.0 * weight_rng.NextDouble())));
  }
  GrowingPointCloud cloud;
  ASSERT_TRUE(cloud.Append(LinePoints(0, kPoints), weights).ok()) << "weighted batch";
  Random rng(11);
  long total_tries = 0;
  for (int s = 0; s < kDraws; ++s) {
    int tries = 0;
    cloud.Sample(rng, &tries);
    total_tries += tries;
  }
  const double mean_tries = total_tries / static_cast<double>(kDraws);
  EXPECT_GE(mean_tries, 1.0);
  EXPECT_LT(mean_tries, 1.6) << "each try is kept with probability above 1/2, about 0.72 here";
}

// Draws `draws` samples and compares each point's count with its share of the total weight by
// a chi-square test (the 99.9% quantile, fixed seed: the test is deterministic).
void ExpectProportionalToWeight(const GrowingPointCloud& cloud, const std::vector<double>& weights,
                                int draws, uint64_t seed, const std::string& what) {
  const std::map<int, int> counts = CountIndices(cloud, draws, seed);
  double total_weight = 0;
  for (double w : weights) total_weight += w;
  double chi_square = 0;
  int cells = 0;
  for (size_t i = 0; i < weights.size(); ++i) {
    const auto it = counts.find(static_cast<int>(i));
    const int observed = it == counts.end() ? 0 : it->second;
    if (weights[i] == 0) {
      EXPECT_EQ(observed, 0) << what << ": point " << i << " of weight 0 was drawn";
      continue;
    }
    const double expected = draws * weights[i] / total_weight;
    chi_square += (observed - expected) * (observed - expected) / expected;
    ++cells;
    // A gross error (a wrong class bound halves or doubles a point's share) shows on its own.
    EXPECT_NEAR(observed / expected, 1.0, 5.0 / std::sqrt(expected))
        << what << ": point " << i << " of weight " << weights[i] << " drawn " << observed
        << " times, expected " << expected;
  }
  // 99.9% quantiles of the chi-square distribution by degrees of freedom (cells - 1).
  const std::map<int, double> kQuantile999 = {{2, 13.82}, {5, 20.52}, {20, 45.31}};
  ASSERT_EQ(kQuantile999.count(cells - 1), 1u) << what << ": no quantile for " << cells << " cells";
  EXPECT_LT(chi_square, kQuantile999.at(cells - 1))
      << what << ": the counts do not follow the weights";
}

TEST(GrowingPointCloudTest, DrawsInProportionToWeightAcrossClasses) {
  // Exact powers of two (drawn without an acceptance test), weights just above them (accepted
  // about half the time), just below them, and weights spread over several classes; one batch
  // without weights (weight 1) in the middle and a point of weight 0.
  const float above_one = std::nextafter(1.0f, 2.0f);
  const float above_four = std::nextafter(4.0f, 8.0f);
  const std::vector<float> first = {1.0f,  above_one, 2.0f, 0.75f,      0.5f, 0.0f,
                                    0.26f, 3.0f,      4.0f, above_four, 7.9f};
  const std::vector<float> last = {
      std::nextafter(2.0f, 0.0f), 0.125f, 0.1875f, 6.0f, 8.0f, 1.5f, 5.0f};
  GrowingPointCloud cloud;
  ASSERT_TRUE(cloud.Append(LinePoints(0, 11), first).ok()) << "first weighted batch";
  ASSERT_TRUE(cloud.Append(LinePoints(11, 15)).ok()) << "batch without weights";
  ASSERT_TRUE(cloud.Append(LinePoints(15, 22), last).ok()) << "second weighted batch";
  std::vector<double> weights(first.begin(), first.end());
  weights.insert(weights.end(), 4, 1.0);
  weights.insert(weights.end(), last.begin(), last.end());
  ExpectProportionalToWeight(cloud, weights, 1000000, 5, "several classes");

  // Points without weights before the first weighted batch weigh 1.
  GrowingPointCloud late;
  ASSERT_TRUE(late.Append(LinePoints(0, 3)).ok()) << "batch without weights";
  ASSERT_TRUE(late.Append(LinePoints(3, 6), std::vector<float>{0.5f, 2.0f, 3.0f}).ok())
      << "weighted batch";
  ExpectProportionalToWeight(late, {1, 1, 1, 0.5, 2, 3}, 300000, 6, "weights arriving late");
}

TEST(GrowingPointCloudTest, DrawsInProportionToExtremeWeights) {
  // The smallest denormals and the largest floats have classes of their own like any weight.
  const float tiny = std::numeric_limits<float>::denorm_min();
  GrowingPointCloud small;
  ASSERT_TRUE(small.Append(LinePoints(0, 4), std::vector<float>{tiny, 2 * tiny, 3 * tiny, 0}).ok())
      << "denormal weights";
  ExpectProportionalToWeight(small, {1, 2, 3, 0}, 300000, 7, "denormal weights");

  const float huge = std::numeric_limits<float>::max();
  GrowingPointCloud large;
  ASSERT_TRUE(large.Append(LinePoints(0, 3), std::vector<float>{huge, huge / 2, huge / 4}).ok())
      << "the largest weights";
  ExpectProportionalToWeight(large, {4, 2, 1}, 300000, 8, "the largest weights");
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

TEST(GrowingPointCloudTest, CapacityIsClampedTo2To32) {
  GrowingPointCloud cloud(std::numeric_limits<size_t>::max());
  EXPECT_EQ(cloud.max_points(), size_t{1} << 32) << "huge capacities are lowered to 2^32";
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
