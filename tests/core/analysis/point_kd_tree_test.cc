#include "core/analysis/point_kd_tree.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/random.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

using Entry = NeighbourHeap::Entry;

std::vector<Vec3f> RandomPoints(size_t n, uint64_t seed) {
  Random rng(seed);
  std::vector<Vec3f> points(n);
  for (Vec3f& p : points) {
    p = Vec3f(static_cast<float>(rng.NextDouble()), static_cast<float>(rng.NextDouble()),
              static_cast<float>(rng.NextDouble()));
  }
  return points;
}

// Points on an integer grid, each twice: many points at equal distances from a grid query.
std::vector<Vec3f> GridPoints(int side) {
  std::vector<Vec3f> points;
  for (int copy = 0; copy < 2; ++copy) {
    for (int x = 0; x < side; ++x) {
      for (int y = 0; y < side; ++y) {
        for (int z = 0; z < side; ++z) points.emplace_back(x, y, z);
      }
    }
  }
  return points;
}

// The heap's entries in the order it pops them, which empties it.
std::vector<Entry> Drain(NeighbourHeap& heap) {
  std::vector<Entry> popped;
  for (; !heap.empty(); heap.pop()) popped.push_back(heap.top());
  return popped;
}

// The k smallest squared distances from `query` to points[begin, end) but `skip`, descending.
std::vector<float> BruteForceDistances(const std::vector<Vec3f>& points, size_t begin, size_t end,
                                       const Vec3f& query, uint32_t skip, size_t k) {
  std::vector<float> d2;
  for (size_t i = begin; i < end; ++i) {
    if (i != skip) d2.push_back((points[i] - query).sqrnorm());
  }
  std::sort(d2.begin(), d2.end());
  d2.resize(std::min(k, d2.size()));
  std::reverse(d2.begin(), d2.end());
  return d2;
}

// Checks a search over `trees` (one heap shared by all) against brute force over the union of
// their ranges: the same distances, each that of the point the entry names.
void ExpectNearest(const std::vector<Vec3f>& points, const std::vector<const PointKdTree*>& trees,
                   const Vec3f& query, uint32_t skip, size_t k) {
  NeighbourHeap heap;
  for (const PointKdTree* tree : trees) tree->Search(query, skip, k, &heap);
  const std::vector<Entry> found = Drain(heap);
  std::vector<float> expected;
  for (const PointKdTree* tree : trees) {
    const std::vector<float> part =
        BruteForceDistances(points, tree->begin(), tree->end(), query, skip, k);
    expected.insert(expected.end(), part.begin(), part.end());
  }
  std::sort(expected.begin(), expected.end());
  expected.resize(std::min(k, expected.size()));
  std::reverse(expected.begin(), expected.end());
  ASSERT_EQ(found.size(), expected.size());
  for (size_t i = 0; i < found.size(); ++i) {
    EXPECT_EQ(found[i].first, expected[i]) << "neighbour " << i;
    ASSERT_LT(found[i].second, points.size());
    EXPECT_NE(found[i].second, skip);
    EXPECT_EQ(found[i].first, (points[found[i].second] - query).sqrnorm());
    if (i > 0) {
      EXPECT_LT(found[i], found[i - 1]) << "popped out of order";
    }
  }
}

TEST(NeighbourHeapTest, KeepsTheKNearestAndPopsTheFarthestFirst) {
  NeighbourHeap heap;
  const std::vector<Entry> offered = {{5, 0}, {1, 1}, {9, 2}, {1, 3}, {4, 4}, {0.5f, 5}, {9, 6}};
  for (const auto& [d2, index] : offered) heap.Offer(d2, index, 4);
  // A point as far as the farthest kept is refused: only a nearer one takes its place.
  heap.Offer(4, 7, 4);
  EXPECT_EQ(Drain(heap), (std::vector<Entry>{{4, 4}, {1, 3}, {1, 1}, {0.5f, 5}}));
}

TEST(PointKdTreeTest, FindsTheKNearestOfRandomPoints) {
  const std::vector<Vec3f> points = RandomPoints(5000, 1);
  const PointKdTree tree(points, 0, static_cast<uint32_t>(points.size()));
  const std::vector<Vec3f> queries = RandomPoints(200, 2);
  for (const size_t k : {1, 8, 16, 100}) {
    for (size_t q = 0; q < queries.size(); ++q) {
      SCOPED_TRACE(testing::Message() << "k " << k << ", query " << q);
      ExpectNearest(points, {&tree}, queries[q], UINT32_MAX, k);
      ExpectNearest(points, {&tree}, points[q * 7], static_cast<uint32_t>(q * 7), k);
    }
  }
}

TEST(PointKdTreeTest, FindsTheKNearestAmongEqualDistancesAndDuplicates) {
  const std::vector<Vec3f> points = GridPoints(6);
  const PointKdTree tree(points, 0, static_cast<uint32_t>(points.size()));
  for (const size_t k : {1, 6, 7, 13, 27, 40}) {
    for (const Vec3f& query : {Vec3f(2, 3, 1), Vec3f(0, 0, 0), Vec3f(2.5f, 2.5f, 2.5f),
                               Vec3f(-3, 2, 8), Vec3f(5, 5, 5)}) {
      SCOPED_TRACE(testing::Message() << "k " << k << ", query " << query);
      ExpectNearest(points, {&tree}, query, UINT32_MAX, k);
      ExpectNearest(points, {&tree}, query, 43, k);
    }
  }
}

TEST(PointKdTreeTest, HeapsSharedBetweenTreesOfRangesFindTheNearestOfTheirUnion) {
  const std::vector<Vec3f> points = RandomPoints(3000, 3);
  const PointKdTree low(points, 0, 1000);
  const PointKdTree high(points, 1000, 2995);
  const PointKdTree few(points, 2995, 3000);  // Fewer points than k.
  EXPECT_EQ(high.begin(), 1000u);
  EXPECT_EQ(high.end(), 2995u);
  EXPECT_EQ(high.size(), 1995u);
  const std::vector<Vec3f> queries = RandomPoints(100, 4);
  for (size_t q = 0; q < queries.size(); ++q) {
    SCOPED_TRACE(testing::Message() << "query " << q);
    ExpectNearest(points, {&few, &low, &high}, queries[q], UINT32_MAX, 16);
    ExpectNearest(points, {&few}, queries[q], UINT32_MAX, 16);
    ExpectNearest(points, {&few, &high, &low}, points[1500 + q], static_cast<uint32_t>(1500 + q),
                  16);
  }
}

TEST(PointKdTreeTest, LeafOrderHoldsEveryPointOfTheRangeOnce) {
  const std::vector<Vec3f> points = RandomPoints(777, 5);
  const PointKdTree tree(points, 100, 700);
  std::vector<bool> seen(points.size(), false);
  for (const PointKdTree::LeafPoint& leaf : tree.leaf_order()) {
    ASSERT_GE(leaf.index, 100u);
    ASSERT_LT(leaf.index, 700u);
    EXPECT_FALSE(seen[leaf.index]);
    seen[leaf.index] = true;
    EXPECT_EQ(leaf.position, points[leaf.index]);
  }
  EXPECT_EQ(tree.leaf_order().size(), 600u);
}

// The points of two trees, put back in the order of their indices, make the tree the array
// makes: the same leaves, the same answers.
TEST(PointKdTreeTest, ATreeFromOtherTreesPointsIsTheTreeOfTheirArray) {
  const std::vector<Vec3f> points = RandomPoints(5000, 8);
  const PointKdTree low(points, 1000, 3000);
  const PointKdTree high(points, 3000, 4500);
  std::vector<PointKdTree::LeafPoint> merged(3500);
  for (const PointKdTree* tree : {&low, &high}) {
    for (const PointKdTree::LeafPoint& point : tree->leaf_order()) {
      merged[point.index - 1000] = point;
    }
  }
  const PointKdTree rebuilt = PointKdTree::FromLeafPoints(std::move(merged));
  const PointKdTree direct(points, 1000, 4500);
  EXPECT_EQ(rebuilt.begin(), 1000u);
  EXPECT_EQ(rebuilt.end(), 4500u);
  ASSERT_EQ(rebuilt.leaf_order().size(), direct.leaf_order().size());
  for (size_t i = 0; i < direct.leaf_order().size(); ++i) {
    ASSERT_EQ(rebuilt.leaf_order()[i].index, direct.leaf_order()[i].index) << i;
    ASSERT_EQ(rebuilt.leaf_order()[i].position, direct.leaf_order()[i].position) << i;
  }
  for (size_t q = 0; q < 50; ++q) {
    ExpectNearest(points, {&rebuilt}, points[q * 97], static_cast<uint32_t>(q * 97), 16);
  }
  EXPECT_EQ(PointKdTree::FromLeafPoints({}).size(), 0u);
}

TEST(PointKdTreeTest, TheTreeDoesNotDependOnTheThreadsThatBuildIt) {
  const std::vector<Vec3f> points = RandomPoints(300000, 6);
  const PointKdTree one(points, 0, static_cast<uint32_t>(points.size()), 1);
  for (const int threads : {2, 3, 8}) {
    const PointKdTree several(points, 0, static_cast<uint32_t>(points.size()), threads);
    const auto a = one.leaf_order();
    const auto b = several.leaf_order();
    ASSERT_EQ(a.size(), b.size());
    size_t differing = 0;
    for (size_t i = 0; i < a.size(); ++i) differing += a[i].index != b[i].index;
    EXPECT_EQ(differing, 0u) << threads << " threads";
    ExpectNearest(points, {&several}, Vec3f(0.5f, 0.5f, 0.5f), UINT32_MAX, 16);
  }
}

TEST(PointKdTreeTest, EmptyAndTinyRangesFindWhatTheyHold) {
  const std::vector<Vec3f> points = RandomPoints(10, 7);
  const PointKdTree empty(points, 4, 4);
  NeighbourHeap heap;
  empty.Search(Vec3f(0, 0, 0), UINT32_MAX, 3, &heap);
  EXPECT_TRUE(heap.empty());
  const PointKdTree one(points, 4, 5);
  one.Search(Vec3f(0, 0, 0), UINT32_MAX, 3, &heap);
  EXPECT_EQ(Drain(heap), (std::vector<Entry>{{points[4].sqrnorm(), 4}}));
  one.Search(Vec3f(0, 0, 0), 4, 3, &heap);  // Its only point skipped.
  EXPECT_TRUE(heap.empty());
  const PointKdTree all(points, 0, 10);
  all.Search(Vec3f(0, 0, 0), UINT32_MAX, 0, &heap);
  EXPECT_TRUE(heap.empty());
  ExpectNearest(points, {&all}, Vec3f(0.2f, 0.9f, 0.1f), UINT32_MAX, 20);
}

}  // namespace
}  // namespace neuralmesh
