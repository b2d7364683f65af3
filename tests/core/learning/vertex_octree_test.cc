#include "core/learning/vertex_octree.h"

#include <limits>
#include <vector>

#include "core/random.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

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

TEST(VertexOctreeTest, EmptyTreeHasNoNearest) {
  BoundingBox box;
  box.Extend(Vec3(0, 0, 0));
  box.Extend(Vec3(1, 1, 1));
  VertexOctree tree(box);
  EXPECT_EQ(tree.Nearest(Vec3(0.5, 0.5, 0.5)), -1) << "an empty tree must answer -1";
}

// Random inserts, moves (small and large, inside and far outside the initial box), and
// removals; after every operation a random query must match brute force exactly.
TEST(VertexOctreeTest, MatchesBruteForceUnderInsertMoveRemove) {
  BoundingBox box;
  box.Extend(Vec3(-1, -1, -1));
  box.Extend(Vec3(1, 1, 1));
  VertexOctree tree(box, /*bucket_size=*/4);
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
  VertexOctree tree(box);
  Random rng(3);
  for (int i = 0; i < 100000; ++i) {
    tree.Insert(i, Vec3(rng.NextDouble(), rng.NextDouble(), rng.NextDouble()));
  }
  EXPECT_LE(tree.Depth(), 12) << "uniform points should give a shallow tree";
}

}  // namespace
}  // namespace neuralmesh
