#include "core/analysis/streaming_outlier_filter.h"

#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/analysis/statistical_outliers.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

absl::Span<const Vec3f> Range(const std::vector<Vec3f>& points, size_t begin, size_t end) {
  return absl::MakeConstSpan(points).subspan(begin, end - begin);
}

size_t Count(const std::vector<bool>& flags) {
  return static_cast<size_t>(std::count(flags.begin(), flags.end(), true));
}

// A whole cloud sent as one batch is judged exactly as FindStatisticalOutliers judges it.
TEST(StreamingOutlierFilterTest, OneBatchAgreesWithTheWholeCloudFilter) {
  for (const size_t n : {300u, 5000u}) {
    const PointCloud cloud = testing::UnitSpherePointsAndAStray(n, 3, Vec3f(0, 0, 40));
    const StreamingOutlierFilter filter(OutlierOptions{});
    const std::vector<bool> streamed = filter.FindOutliers(cloud.positions);
    const auto whole = FindStatisticalOutliers(cloud, OutlierOptions{});
    ASSERT_TRUE(whole.ok()) << whole.status();
    EXPECT_EQ(streamed, *whole) << n << " points";
    EXPECT_TRUE(streamed.back()) << "the stray";
  }
}

// The forest of seen points answers as one tree would: the same points added in one batch or
// in many batches of uneven sizes judge a new batch identically.
TEST(StreamingOutlierFilterTest, AddingInManyBatchesJudgesAsAddingInOne) {
  const PointCloud cloud = testing::UnitSpherePointsAndAStray(20000, 5, Vec3f(0, 3, 0));
  const PointCloud probe = testing::UnitSpherePointsAndAStray(700, 6, Vec3f(2, 0, 0));
  StreamingOutlierFilter at_once(OutlierOptions{});
  at_once.Add(cloud.positions);
  StreamingOutlierFilter piecewise(OutlierOptions{});
  Random rng(7);
  for (size_t begin = 0; begin < cloud.size();) {
    const size_t end = std::min(cloud.size(), begin + 1 + rng.NextIndex(1500));
    piecewise.Add(Range(cloud.positions, begin, end));
    begin = end;
  }
  ASSERT_EQ(piecewise.size(), cloud.size());
  const std::vector<bool> expected = at_once.FindOutliers(probe.positions);
  EXPECT_EQ(piecewise.FindOutliers(probe.positions), expected);
  EXPECT_TRUE(expected.back()) << "the probe's stray, at 2 radii";
  EXPECT_LE(Count(expected), 10u);
}

// Points streamed in small batches, strays among them and one alone in its batch: each stray
// is dropped, and about as many surface points as the whole-cloud filter drops (56 of these
// 20,000). Were the dropped points left out of the neighbours, the gaps they leave would stay
// sparse while the rest fills in: 289-367 dropped.
TEST(StreamingOutlierFilterTest, StraysAreFoundInBatchesOfAnySize) {
  PointCloud cloud = testing::UnitSpherePointsAndAStray(20000, 8, Vec3f(0, 0, 0));
  cloud.positions.pop_back();
  const std::vector<Vec3f> strays = {Vec3f(100, 0, 0), Vec3f(0, 1.6f, 0), Vec3f(0, 0, -5)};
  for (const size_t batch_size : {1u, 10u, 200u}) {
    StreamingOutlierFilter filter(OutlierOptions{});
    size_t surface_dropped = 0;
    size_t strays_dropped = 0;
    for (size_t begin = 0; begin < cloud.size(); begin += batch_size) {
      std::vector<Vec3f> batch(cloud.positions.begin() + begin,
                               cloud.positions.begin() + begin + batch_size);
      const size_t stray = begin / 6000;
      const bool with_stray = begin % 6000 == 0 && stray >= 1 && stray <= 2;
      if (with_stray) batch.push_back(strays[stray - 1]);
      std::vector<bool> drop = filter.FindOutliers(batch);
      ASSERT_EQ(drop.size(), batch.size());
      if (with_stray) {
        strays_dropped += drop.back() ? 1 : 0;
        drop.pop_back();
      }
      surface_dropped += Count(drop);
      filter.Add(batch);
      if (begin == 18000) {
        EXPECT_EQ(filter.FindOutliers({strays[2]}), std::vector<bool>{true})
            << "a stray alone in its batch";
        EXPECT_EQ(filter.FindOutliers({cloud.positions[19999]}), std::vector<bool>{false})
            << "a surface point alone in its batch";
      }
    }
    EXPECT_EQ(strays_dropped, 2u) << "batches of " << batch_size;
    EXPECT_LE(surface_dropped, 100u) << "batches of " << batch_size;
    EXPECT_EQ(filter.size(), 20002u);
  }
}

TEST(StreamingOutlierFilterTest, NothingIsAnOutlierWhileTheCloudHasAtMostKPoints) {
  OutlierOptions options;
  options.neighbours = 4;
  StreamingOutlierFilter filter(options);
  const std::vector<Vec3f> first = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1000, 0, 0)};
  EXPECT_EQ(Count(filter.FindOutliers(first)), 0u);
  filter.Add(first);
  EXPECT_EQ(Count(filter.FindOutliers({Vec3f(-1000, 0, 0)})), 0u) << "4 points in all";
  EXPECT_TRUE(filter.FindOutliers({}).empty());
  filter.Add({Vec3f(0, 1, 0), Vec3f(5, 5, 5)});
  EXPECT_EQ(filter.size(), 5u);
}

}  // namespace
}  // namespace neuralmesh
