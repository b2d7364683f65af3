#include "core/learning/vertex_ring_cache.h"

#include <cmath>
#include <vector>

#include "core/learning/half_edge_collapse.h"
#include "core/learning/vertex_split.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using testing::Icosphere;
using testing::MustToMesh;

// The ring read straight from the half-edges, in the order the cache promises.
std::vector<int> WalkRing(const Mesh& mesh, Mesh::VertexHandle v) {
  std::vector<int> ring;
  const auto start = mesh.halfedge_handle(v);
  auto h = start;
  do {
    ring.push_back(mesh.to_vertex_handle(h).idx());
    h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
  } while (h != start);
  return ring;
}

void ExpectEveryRingMatches(const Mesh& mesh, VertexRingCache& cache, int op) {
  for (auto v : mesh.vertices()) {
    std::vector<int> cached;
    const bool boundary = cache.AppendRing(mesh, v.idx(), cached);
    ASSERT_EQ(cached, WalkRing(mesh, v)) << "vertex " << v.idx() << " after operation " << op;
    ASSERT_EQ(boundary, mesh.is_boundary(v)) << "vertex " << v.idx() << " after operation " << op;
    // The view without a copy says the same.
    cache.Prefetch(v.idx());
    const VertexRingCache::RingView view = cache.Ring(mesh, v.idx());
    ASSERT_EQ(std::vector<int>(view.neighbours, view.neighbours + view.size), cached)
        << "Ring() of vertex " << v.idx() << " after operation " << op;
    ASSERT_EQ(view.boundary, boundary)
        << "Ring() of vertex " << v.idx() << " after operation " << op;
  }
}

TEST(VertexRingCacheTest, AppendsAfterWhatIsAlreadyThere) {
  Mesh mesh = MustToMesh(Icosphere(1));
  VertexRingCache cache;
  std::vector<int> out = {-7};
  cache.AppendRing(mesh, 0, out);  // Fills the line.
  cache.AppendRing(mesh, 0, out);  // Reads it back.
  const std::vector<int> ring = WalkRing(mesh, Mesh::VertexHandle(0));
  ASSERT_EQ(out.size(), 1 + 2 * ring.size());
  EXPECT_EQ(out[0], -7);
  EXPECT_EQ(std::vector<int>(out.begin() + 1, out.begin() + 1 + ring.size()), ring);
  EXPECT_EQ(std::vector<int>(out.begin() + 1 + ring.size(), out.end()), ring);
}

TEST(VertexRingCacheTest, StaysExactThroughSplitsWithTheLearnersInvalidation) {
  // The learner invalidates v0 and its neighbours after a split, and everything after a
  // collapse; every ring must then read exactly as the half-edges say, boundary rings and
  // rings longer than a cache line included.
  Mesh mesh = MustToMesh(Icosphere(2));
  VertexRingCache cache;
  Random rng(11);
  ExpectEveryRingMatches(mesh, cache, -1);
  for (int op = 0; op < 400; ++op) {
    const Mesh::VertexHandle v(static_cast<int>(rng.NextIndex(mesh.n_vertices())));
    if (mesh.status(v).deleted()) continue;
    if (op % 5 == 4) {
      const auto h = BestCollapse(mesh, v, mesh.n_vertices());
      if (!h.is_valid()) continue;
      mesh.collapse(h);
      cache.InvalidateAll();
    } else {
      const Mesh::VertexHandle v0 = SplitVertex(mesh, v);
      if (!v0.is_valid()) continue;
      cache.Invalidate(v0.idx());
      for (auto u : mesh.vv_range(v0)) cache.Invalidate(u.idx());
    }
    if (op % 20 == 0) ExpectEveryRingMatches(mesh, cache, op);
  }
  ExpectEveryRingMatches(mesh, cache, 400);
}

TEST(VertexRingCacheTest, ForgettingToInvalidateIsVisible) {
  // The converse: without invalidation the cache serves the old ring. This is what makes the
  // previous test meaningful.
  Mesh mesh = MustToMesh(Icosphere(1));
  VertexRingCache cache;
  const Mesh::VertexHandle v(3);
  std::vector<int> before;
  cache.AppendRing(mesh, v.idx(), before);
  ASSERT_TRUE(SplitVertex(mesh, v).is_valid());
  std::vector<int> stale;
  cache.AppendRing(mesh, v.idx(), stale);
  EXPECT_EQ(stale, before);
  EXPECT_NE(stale, WalkRing(mesh, v));
  cache.Invalidate(v.idx());
  std::vector<int> fresh;
  cache.AppendRing(mesh, v.idx(), fresh);
  EXPECT_EQ(fresh, WalkRing(mesh, v));
}

// A closed fan: vertex 0 surrounded by `n` triangles (valence n; the rim vertices are on the
// boundary).
Mesh Fan(int n) {
  TriangleMesh fan;
  fan.positions.emplace_back(0, 0, 0);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    fan.positions.emplace_back(std::cos(a), std::sin(a), 0);
  }
  for (uint32_t i = 0; i < static_cast<uint32_t>(n); ++i) {
    fan.faces.push_back({0, 1 + i, 1 + (i + 1) % n});
  }
  return MustToMesh(fan);
}

TEST(VertexRingCacheTest, BoundaryAndHighValenceRings) {
  // A grid's border vertices and a fan of 20 triangles (valence above a line's slots).
  Mesh mesh = Fan(20);
  VertexRingCache cache;
  ExpectEveryRingMatches(mesh, cache, 0);
  ExpectEveryRingMatches(mesh, cache, 1);  // Served from the cache where it fits.

  Mesh grid = MustToMesh(testing::GridPatch(3, 3));
  VertexRingCache grid_cache;
  ExpectEveryRingMatches(grid, grid_cache, 0);
  ExpectEveryRingMatches(grid, grid_cache, 1);
}

TEST(VertexRingCacheTest, LongRingsAreCachedOutsideTheirLineUpTo255) {
  for (const int valence : {8, 20, 255}) {
    Mesh mesh = Fan(valence);
    VertexRingCache cache;
    EXPECT_EQ(cache.CachedRing(0).neighbours, nullptr) << "nothing is cached before the first use";
    cache.Ring(mesh, 0);
    cache.Ring(mesh, 1);
    const VertexRingCache::RingView ring = cache.CachedRing(0);
    ASSERT_NE(ring.neighbours, nullptr) << "a ring of " << valence << " is cached";
    EXPECT_EQ(std::vector<int>(ring.neighbours, ring.neighbours + ring.size),
              WalkRing(mesh, Mesh::VertexHandle(0)));
    EXPECT_FALSE(ring.boundary);
    cache.Invalidate(0);
    EXPECT_EQ(cache.CachedRing(0).neighbours, nullptr) << "invalidated";
    cache.Ring(mesh, 0);  // Stored a second time.
    const VertexRingCache::RingView again = cache.CachedRing(0);
    ASSERT_NE(again.neighbours, nullptr);
    EXPECT_EQ(std::vector<int>(again.neighbours, again.neighbours + again.size),
              WalkRing(mesh, Mesh::VertexHandle(0)));
    const VertexRingCache::RingView rim = cache.CachedRing(1);
    ASSERT_NE(rim.neighbours, nullptr) << "the short ring beside it stays cached";
    EXPECT_EQ(std::vector<int>(rim.neighbours, rim.neighbours + rim.size),
              WalkRing(mesh, Mesh::VertexHandle(1)));
    cache.InvalidateAll();
    EXPECT_EQ(cache.CachedRing(0).neighbours, nullptr) << "InvalidateAll drops long rings too";
    ExpectEveryRingMatches(mesh, cache, valence);
  }
  Mesh wide = Fan(256);
  VertexRingCache cache;
  ExpectEveryRingMatches(wide, cache, 0);
  EXPECT_EQ(cache.CachedRing(0).neighbours, nullptr) << "a ring of 256 is walked every time";
}

TEST(VertexRingCacheTest, EpochsWrapWithoutReviving) {
  Mesh mesh = Fan(6);
  VertexRingCache cache;
  cache.Ring(mesh, 0);
  // Lines keep 16-bit epochs: after 2^16 InvalidateAll calls the epoch a line was stored in
  // comes round again, and must not make it current.
  for (int i = 0; i < (1 << 16); ++i) {
    cache.InvalidateAll();
    ASSERT_EQ(cache.CachedRing(0).neighbours, nullptr) << "after " << i + 1 << " InvalidateAll";
  }
  cache.Ring(mesh, 0);
  EXPECT_NE(cache.CachedRing(0).neighbours, nullptr) << "cached again";
}

}  // namespace
}  // namespace neuralmesh
