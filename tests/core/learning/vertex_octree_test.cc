#include "core/learning/vertex_octree.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/random.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

// A VertexOctree over points this test owns, used as the learner uses it: a point changes in
// the array first, then the tree is told (Insert, Move).
class Tree {
 public:
  explicit Tree(const BoundingBox& box, int bucket_size = 32)
      : tree_(box, &points_, bucket_size) {}
  Tree(const Tree&) = delete;
  Tree& operator=(const Tree&) = delete;

  void Insert(int id, const Vec3& p) {
    if (static_cast<size_t>(id) >= points_.size()) points_.resize(static_cast<size_t>(id) + 1);
    points_[id] = p;
    tree_.Insert(id);
  }
  void Move(int id, const Vec3& p) {
    points_[id] = p;
    tree_.Move(id);
  }
  void Remove(int id) { tree_.Remove(id); }
  bool Contains(int id) const { return tree_.Contains(id); }
  int Nearest(const Vec3& q, const OctreeDescent& descent = {}) const {
    return tree_.Nearest(q, nullptr, descent);
  }
  size_t size() const { return tree_.size(); }
  int Depth() const { return tree_.Depth(); }

  // For tests of the protocol itself.
  std::vector<Vec3>& points() { return points_; }
  VertexOctree& octree() { return tree_; }

 private:
  std::vector<Vec3> points_;  // Before tree_, which keeps its address.
  VertexOctree tree_;
};

int BruteForceNearest(const std::vector<Vec3>& points, const std::vector<bool>& present,
                      const Vec3& q, double* best_d2) {
  int best = -1;
  *best_d2 = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < points.size(); ++i) {
    if (!present[i]) continue;
    const double d2 = (points[i] - q).sqrnorm();
    if (d2 < *best_d2) {
      *best_d2 = d2;
      best = static_cast<int>(i);
    }
  }
  return best;
}

// Compares tree.Nearest(q, descent) with brute force; returns a failure message or "".
std::string CheckNearest(const Tree& tree, const std::vector<Vec3>& points,
                         const std::vector<bool>& present, const Vec3& q,
                         const OctreeDescent& descent = {}) {
  double best_d2;
  const int expected = BruteForceNearest(points, present, q, &best_d2);
  const int got = tree.Nearest(q, descent);
  if (expected < 0) return got == -1 ? "" : "the tree answers for an empty set";
  if (got < 0 || got >= static_cast<int>(points.size()) || !present[got]) {
    return "the tree answers " + std::to_string(got) + ", which is not a live id";
  }
  const double got_d2 = (points[got] - q).sqrnorm();
  // Exact up to the rounding of the distance itself (a few ulps, as ASSERT_DOUBLE_EQ).
  if (!(got_d2 <= best_d2 * (1 + 4 * std::numeric_limits<double>::epsilon()))) {
    return "the tree's answer " + std::to_string(got) + " is not the nearest (" +
           std::to_string(expected) + ")";
  }
  return "";
}

// Random inserts, moves and removals of `num_ids` ids, with new points from `new_point` and
// moves by `offset`; after every operation a query from `query` must match brute force.
void RunRandomOperations(Tree& tree, int num_ids, int num_ops, uint64_t seed,
                         const std::function<Vec3(Random&)>& new_point,
                         const std::function<Vec3(Random&)>& offset,
                         const std::function<Vec3(Random&)>& query) {
  Random rng(seed);
  std::vector<Vec3> points(num_ids);
  std::vector<bool> present(num_ids, false);
  for (int op = 0; op < num_ops; ++op) {
    const int id = static_cast<int>(rng.NextIndex(num_ids));
    const double r = rng.NextDouble();
    if (!present[id]) {
      points[id] = new_point(rng);
      tree.Insert(id, points[id]);
      present[id] = true;
    } else if (r < 0.6) {
      points[id] += offset(rng);
      tree.Move(id, points[id]);
    } else {
      tree.Remove(id);
      present[id] = false;
    }
    const std::string error = CheckNearest(tree, points, present, query(rng));
    ASSERT_EQ(error, "") << "op " << op;
    ASSERT_EQ(tree.Contains(id), present[id]) << "op " << op << ": Contains(" << id << ") is wrong";
  }
  size_t count = 0;
  for (bool p : present) count += p;
  EXPECT_EQ(tree.size(), count) << "size() disagrees with the number of live ids";
  // Finally every point must find itself (or a coincident one).
  for (int id = 0; id < num_ids; ++id) {
    if (!present[id]) continue;
    const int got = tree.Nearest(points[id]);
    ASSERT_GE(got, 0) << "point " << id << " is lost";
    EXPECT_EQ((points[got] - points[id]).sqrnorm(), 0.0)
        << "point " << id << " does not find itself";
  }
}

TEST(VertexOctreeTest, EmptyTreeHasNoNearest) {
  BoundingBox box;
  box.Extend(Vec3(0, 0, 0));
  box.Extend(Vec3(1, 1, 1));
  Tree tree(box);
  EXPECT_EQ(tree.Nearest(Vec3(0.5, 0.5, 0.5)), -1) << "an empty tree must answer -1";
}

// Random inserts, moves (small and large, inside and far outside the initial box), and
// removals; after every operation a random query must match brute force exactly.
TEST(VertexOctreeTest, MatchesBruteForceUnderInsertMoveRemove) {
  BoundingBox box;
  box.Extend(Vec3(-1, -1, -1));
  box.Extend(Vec3(1, 1, 1));
  Tree tree(box, /*bucket_size=*/4);
  Random rng(7);
  auto random_point = [&](double scale) {
    return Vec3(rng.NextDouble() - 0.5, rng.NextDouble() - 0.5, rng.NextDouble() - 0.5) *
           (2 * scale);
  };
  const int kIds = 400;
  std::vector<Vec3> points(kIds);
  std::vector<bool> present(kIds, false);
  for (int op = 0; op < 30000; ++op) {
    const int id = static_cast<int>(rng.NextIndex(kIds));
    const double r = rng.NextDouble();
    if (!present[id]) {
      points[id] = random_point(r < 0.05 ? 20.0 : 1.0);
      tree.Insert(id, points[id]);
      present[id] = true;
    } else if (r < 0.6) {
      points[id] += random_point(r < 0.1 ? 3.0 : 0.01);
      tree.Move(id, points[id]);
    } else {
      tree.Remove(id);
      present[id] = false;
    }
    const Vec3 q = random_point(rng.NextDouble() < 0.1 ? 30.0 : 1.5);
    double best_d2;
    const int expected = BruteForceNearest(points, present, q, &best_d2);
    const int got = tree.Nearest(q);
    if (expected < 0) {
      ASSERT_EQ(got, -1) << "op " << op;
      continue;
    }
    ASSERT_GE(got, 0) << "op " << op << ": tree lost its points";
    ASSERT_DOUBLE_EQ((points[got] - q).sqrnorm(), best_d2)
        << "op " << op << ": the tree's answer " << got << " is not the nearest (" << expected
        << ")";
  }
  size_t count = 0;
  for (bool p : present) count += p;
  EXPECT_EQ(tree.size(), count) << "size() disagrees with the number of live ids";
}

TEST(VertexOctreeTest, DepthStaysLogarithmic) {
  BoundingBox box;
  box.Extend(Vec3(0, 0, 0));
  box.Extend(Vec3(1, 1, 1));
  Tree tree(box);
  Random rng(3);
  for (int i = 0; i < 100000; ++i) {
    tree.Insert(i, Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()));
  }
  EXPECT_LE(tree.Depth(), 12) << "uniform points should give a shallow tree";
}

// The learner's kind of data: points on a surface (a sphere) that move by small steps, at
// several leaf sizes, including the smallest.
TEST(VertexOctreeTest, MatchesBruteForceOnASurfaceForEveryBucketSize) {
  for (int bucket_size : {2, 3, 8, 32, 64}) {
    SCOPED_TRACE("bucket_size " + std::to_string(bucket_size));
    BoundingBox box;
    box.Extend(Vec3(-1, -1, -1));
    box.Extend(Vec3(1, 1, 1));
    Tree tree(box, bucket_size);
    auto on_sphere = [](Random& rng) {
      const double z = 2 * rng.NextDouble() - 1;
      const double phi = 2 * M_PI * rng.NextDouble();
      const double s = std::sqrt(1 - z * z);
      return Vec3(s * std::cos(phi), s * std::sin(phi), z);
    };
    RunRandomOperations(
        tree, /*num_ids=*/600, /*num_ops=*/20000, /*seed=*/11, on_sphere,
        [](Random& rng) {
          return Vec3(rng.NextDouble() - 0.5, rng.NextDouble() - 0.5, rng.NextDouble() - 0.5) *
                 0.02;
        },
        on_sphere);
  }
}

// Many points at identical coordinates: no amount of splitting separates them, so the leaf
// at the maximum depth has to hold more than a bucket.
TEST(VertexOctreeTest, HandlesManyCoincidentPoints) {
  BoundingBox box;
  box.Extend(Vec3(0, 0, 0));
  box.Extend(Vec3(1, 1, 1));
  Tree tree(box, /*bucket_size=*/2);
  const Vec3 spot(0.3, 0.6, 0.2);
  const int kCoincident = 100;
  for (int id = 0; id < kCoincident; ++id) tree.Insert(id, spot);
  tree.Insert(kCoincident, Vec3(0.9, 0.9, 0.9));
  tree.Insert(kCoincident + 1, Vec3(0.3, 0.6, 0.2 + 1e-9));
  EXPECT_EQ(tree.size(), static_cast<size_t>(kCoincident + 2));
  EXPECT_GE(tree.Depth(), 30) << "coincident points should drive a leaf to the maximum depth";
  // Remove them in a scrambled order; the rest must still be found exactly.
  Random rng(5);
  std::vector<int> order;
  for (int id = 0; id < kCoincident; ++id) order.push_back(id);
  for (int i = kCoincident - 1; i > 0; --i) std::swap(order[i], order[rng.NextIndex(i + 1)]);
  std::vector<bool> present(kCoincident, true);
  for (int k = 0; k < kCoincident; ++k) {
    const int got = tree.Nearest(spot);
    ASSERT_TRUE(got >= 0 && got < kCoincident && present[got])
        << "after " << k << " removals the tree answers " << got
        << " instead of a remaining coincident point";
    // Move one of them away and back: it leaves the deep leaf and returns to it.
    const int moving = order[kCoincident - 1];
    tree.Move(moving, Vec3(0.8, 0.1, 0.1));
    ASSERT_EQ(tree.Nearest(Vec3(0.8, 0.1, 0.1)), moving) << "a point moved out is lost";
    tree.Move(moving, spot);
    tree.Remove(order[k]);
    present[order[k]] = false;
    ASSERT_FALSE(tree.Contains(order[k]));
    ASSERT_EQ(tree.size(), static_cast<size_t>(kCoincident + 1 - k));
  }
  EXPECT_EQ(tree.Nearest(spot), kCoincident + 1) << "the nearly coincident point should win";
  EXPECT_LE(tree.Depth(), 2) << "the deep subtree should have merged back";
}

// Clusters of points closer than 1e-9 (trees near the maximum depth, coincident points mixed
// with distinct ones) under random operations.
TEST(VertexOctreeTest, MatchesBruteForceOnTinyClusters) {
  BoundingBox box;
  box.Extend(Vec3(-1, -1, -1));
  box.Extend(Vec3(1, 1, 1));
  Tree tree(box, /*bucket_size=*/3);
  const std::vector<Vec3> centers = {Vec3(0.1, 0.2, 0.3), Vec3(-0.5, 0.25, 0.125),
                                     Vec3(0.1, 0.2, 0.3 + 1e-6)};
  auto near_a_center = [&](Random& rng) {
    const Vec3& c = centers[rng.NextIndex(centers.size())];
    const double scale = std::pow(10.0, -9.0 - 6.0 * rng.NextDouble());
    if (rng.NextDouble() < 0.3) return c;  // Exactly coincident.
    return c + Vec3(rng.NextDouble() - 0.5, rng.NextDouble() - 0.5, rng.NextDouble() - 0.5) * scale;
  };
  RunRandomOperations(
      tree, /*num_ids=*/200, /*num_ops=*/10000, /*seed=*/17, near_a_center,
      [](Random& rng) {
        const double scale = std::pow(10.0, -8.0 - 6.0 * rng.NextDouble());
        return Vec3(rng.NextDouble() - 0.5, rng.NextDouble() - 0.5, rng.NextDouble() - 0.5) * scale;
      },
      near_a_center);
}

// The root doubles toward points far outside it, many times over, in every direction; points
// near the initial box must still be found exactly, and removing the far points must work.
TEST(VertexOctreeTest, RootGrowsTowardFarPoints) {
  BoundingBox box;
  box.Extend(Vec3(0.1, 0.1, 0.1));
  box.Extend(Vec3(0.3, 0.7, 0.2));
  Tree tree(box, /*bucket_size=*/4);
  std::vector<Vec3> points;
  Random rng(23);
  for (int i = 0; i < 300; ++i) {
    points.push_back(Vec3(0.1 + 0.2 * rng.NextDouble(), 0.1 + 0.6 * rng.NextDouble(),
                          0.1 + 0.1 * rng.NextDouble()));
  }
  const std::vector<Vec3> far = {Vec3(1e3, 0, 0),         Vec3(0, -1e9, 0),
                                 Vec3(0, 0, 1e15),        Vec3(-3e15, 2e15, 7),
                                 Vec3(1e-3, 1e-3, -1e12), Vec3(1e15, 1e15, 1e15)};
  const int first_far = static_cast<int>(points.size());
  points.insert(points.end(), far.begin(), far.end());
  std::vector<bool> present(points.size(), false);
  // Interleave: some near points, then each far point, then more near points.
  for (int id = 0; id < first_far / 2; ++id) {
    tree.Insert(id, points[id]);
    present[id] = true;
  }
  for (int id = first_far; id < static_cast<int>(points.size()); ++id) {
    tree.Insert(id, points[id]);
    present[id] = true;
  }
  for (int id = first_far / 2; id < first_far; ++id) {
    tree.Insert(id, points[id]);
    present[id] = true;
  }
  auto check_queries = [&](const char* stage) {
    for (int k = 0; k < 500; ++k) {
      Vec3 q(0.4 * rng.NextDouble(), 0.8 * rng.NextDouble(), 0.3 * rng.NextDouble());
      if (k % 10 == 0) q = far[k / 10 % far.size()] * (0.5 + rng.NextDouble());
      const std::string error = CheckNearest(tree, points, present, q);
      ASSERT_EQ(error, "") << stage << ", query " << k;
    }
  };
  check_queries("after inserting");
  // Small moves of the near points and a far point moved next to them.
  for (int id = 0; id < first_far; id += 3) {
    points[id] += Vec3(1e-3, -1e-3, 5e-4);
    tree.Move(id, points[id]);
  }
  points[first_far] = Vec3(0.2, 0.2, 0.15);
  tree.Move(first_far, points[first_far]);
  check_queries("after moving");
  for (int id = first_far + 1; id < static_cast<int>(points.size()); ++id) {
    tree.Remove(id);
    present[id] = false;
  }
  check_queries("after removing the far points");
  EXPECT_EQ(tree.size(), static_cast<size_t>(first_far + 1));
}

// A point near the largest doubles makes the root grow about a thousand times, so the points
// near the initial box sit a thousand levels deep: deeper than the search's inline stack.
TEST(VertexOctreeTest, SearchesVeryDeepTrees) {
  BoundingBox box;
  box.Extend(Vec3(0, 0, 0));
  box.Extend(Vec3(1, 1, 1));
  Tree tree(box, /*bucket_size=*/2);
  std::vector<Vec3> points;
  Random rng(31);
  for (int i = 0; i < 60; ++i) {
    points.push_back(Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()));
  }
  points.push_back(Vec3(1e300, -1e300, 1e300));
  points.push_back(Vec3(-1e299, 0.5, 0.5));
  std::vector<bool> present(points.size(), true);
  for (size_t id = 0; id < points.size(); ++id) tree.Insert(static_cast<int>(id), points[id]);
  EXPECT_GT(tree.Depth(), 900) << "the root should have grown about a thousand times";
  for (int k = 0; k < 200; ++k) {
    Vec3 q(rng.NextDouble(), rng.NextDouble(), rng.NextDouble());
    if (k % 20 == 0) q = Vec3(-3e298, 1e10, 0);
    if (k % 20 == 1) q = Vec3(1e299, 1e299, 1e299);
    ASSERT_EQ(CheckNearest(tree, points, present, q), "") << "query " << k;
  }
  for (int id = 0; id < 60; id += 2) {
    points[id] += Vec3(0.01, 0.02, -0.01);
    tree.Move(id, points[id]);
  }
  for (int k = 0; k < 200; ++k) {
    const Vec3 q(rng.NextDouble(), rng.NextDouble(), rng.NextDouble());
    ASSERT_EQ(CheckNearest(tree, points, present, q), "") << "after moves, query " << k;
  }
}

// A tree built without a box (empty) starts from a unit cube and grows.
TEST(VertexOctreeTest, EmptyInitialBoxGrows) {
  Tree tree{BoundingBox()};
  std::vector<Vec3> points;
  std::vector<bool> present;
  Random rng(29);
  for (int id = 0; id < 2000; ++id) {
    points.push_back(Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()) * 100.0 -
                     Vec3(30, 30, 30));
    present.push_back(true);
    tree.Insert(id, points[id]);
  }
  for (int k = 0; k < 500; ++k) {
    const Vec3 q =
        Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()) * 120.0 - Vec3(40, 40, 40);
    ASSERT_EQ(CheckNearest(tree, points, present, q), "") << "query " << k;
  }
}

// The learner's protocol: several points change in the array (the winner's ring after the
// smoothing) before the tree hears of any; the Move of one may split or merge a leaf that holds
// another whose Move is still to come (the split routes it by where it is now). Once every
// changed point has had its Move, queries must be exact again.
TEST(VertexOctreeTest, ExactAfterSeveralPointsChangeBeforeTheirMoves) {
  for (int bucket_size : {2, 4, 32}) {
    SCOPED_TRACE("bucket_size " + std::to_string(bucket_size));
    BoundingBox box;
    box.Extend(Vec3(-1, -1, -1));
    box.Extend(Vec3(1, 1, 1));
    Tree tree(box, bucket_size);
    Random rng(41);
    const int kIds = 500;
    for (int id = 0; id < kIds; ++id) {
      tree.Insert(id, Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()) * 2.0 -
                          Vec3(1, 1, 1));
    }
    const std::vector<bool> present(kIds, true);
    std::vector<Vec3>& points = tree.points();
    for (int round = 0; round < 3000; ++round) {
      // Seven ids near one another in index, changed together, some across leaves.
      const int first = static_cast<int>(rng.NextIndex(kIds - 7));
      const double scale = rng.NextDouble() < 0.2 ? 0.5 : 0.02;
      for (int k = 0; k < 7; ++k) {
        points[first + k] +=
            Vec3(rng.NextDouble() - 0.5, rng.NextDouble() - 0.5, rng.NextDouble() - 0.5) * scale;
      }
      for (int k = 6; k >= 0; --k) tree.octree().Move(first + k);
      const Vec3 q(2 * rng.NextDouble() - 1, 2 * rng.NextDouble() - 1, 2 * rng.NextDouble() - 1);
      ASSERT_EQ(CheckNearest(tree, points, present, q), "") << "round " << round;
    }
    for (int id = 0; id < kIds; ++id) {
      ASSERT_EQ((points[tree.Nearest(points[id])] - points[id]).sqrnorm(), 0.0) << "id " << id;
    }
  }
}

// The learner's lookahead descends toward a sample's leaf a few levels at a time over two
// steps and searches from that leaf a step later, moving, inserting and removing points in
// between: a search given such a descent must be exact whatever changed since, leaves split
// and merged included, and give the id a search without it gives while nothing changed.
TEST(VertexOctreeTest, SearchesAfterAStagedDescentAreExact) {
  BoundingBox box;
  box.Extend(Vec3(0, 0, 0));
  box.Extend(Vec3(1, 1, 1));
  Tree tree(box, /*bucket_size=*/4);
  Random rng(41);
  std::vector<Vec3> points;
  std::vector<bool> present;
  for (int id = 0; id < 3000; ++id) {
    points.push_back(Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()));
    present.push_back(true);
    tree.Insert(id, points[id]);
  }
  auto change_some = [&](const Vec3& q, int changes) {
    for (int k = 0; k < changes; ++k) {
      const int id = static_cast<int>(rng.NextDouble() * static_cast<double>(points.size()));
      const double kind = rng.NextDouble();
      if (!present[id]) {
        points[id] = Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble());
        tree.Insert(id, points[id]);
        present[id] = true;
      } else if (kind < 0.2) {
        tree.Remove(id);
        present[id] = false;
      } else if (kind < 0.6) {  // Next to q: into its leaf or the ones around it.
        points[id] = q + Vec3(0.02 * rng.NextDouble() - 0.01, 0.02 * rng.NextDouble() - 0.01,
                              0.02 * rng.NextDouble() - 0.01);
        tree.Move(id, points[id]);
      } else {
        points[id] = Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble());
        tree.Move(id, points[id]);
      }
    }
  };
  for (int round = 0; round < 3000; ++round) {
    const Vec3 q(rng.NextDouble(), rng.NextDouble(), rng.NextDouble());
    const bool keep = round % 3 == 0;  // No change between the stages nor before the search.
    OctreeDescent descent;
    for (const int levels : {2, 1, VertexOctree::kToLeaf}) {
      tree.octree().Descend(q, levels, &descent);
      if (!keep) change_some(q, static_cast<int>(rng.NextDouble() * 15));
    }
    tree.octree().PrefetchNearestPoints(descent);
    if (!keep) change_some(q, static_cast<int>(rng.NextDouble() * 15));
    ASSERT_EQ(CheckNearest(tree, points, present, q, descent), "") << "round " << round;
    if (keep) {
      ASSERT_EQ(tree.Nearest(q, descent), tree.Nearest(q)) << "round " << round;
    }
  }
}

// A descent taken in another octree (the learner builds a new one at every Step 3) names a
// node of that tree, maybe past the end of this one's: it must be ignored.
TEST(VertexOctreeTest, IgnoresADescentTakenInAnotherTree) {
  BoundingBox box;
  box.Extend(Vec3(0, 0, 0));
  box.Extend(Vec3(1, 1, 1));
  Tree large(box, /*bucket_size=*/2);
  Tree small(box, /*bucket_size=*/2);
  Random rng(43);
  std::vector<Vec3> points;
  for (int id = 0; id < 5000; ++id) {
    points.push_back(Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()));
    large.Insert(id, points[id]);
    if (id < 5) small.Insert(id, points[id]);
  }
  std::vector<bool> present(points.size(), false);
  std::fill(present.begin(), present.begin() + 5, true);
  for (int k = 0; k < 200; ++k) {
    const Vec3 q(rng.NextDouble(), rng.NextDouble(), rng.NextDouble());
    OctreeDescent descent;
    large.octree().Descend(q, VertexOctree::kToLeaf, &descent);
    small.octree().PrefetchNearestPoints(descent);
    ASSERT_EQ(CheckNearest(small, points, present, q, descent), "") << "query " << k;
    // Continued in the small tree, it starts again from that tree's root.
    small.octree().Descend(q, VertexOctree::kToLeaf, &descent);
    ASSERT_EQ(CheckNearest(small, points, present, q, descent), "") << "query " << k;
  }
}

}  // namespace
}  // namespace neuralmesh
