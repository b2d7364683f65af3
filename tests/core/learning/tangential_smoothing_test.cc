#include "core/learning/tangential_smoothing.h"

#include <cmath>
#include <vector>

#include "core/learning/vertex_ring_cache.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using testing::GridPatch;
using testing::Icosphere;
using testing::MustToMesh;

// The neighbours of v in rotation order, starting at the end of v's stored half-edge (for a
// border vertex, its outgoing border half-edge).
std::vector<Mesh::VertexHandle> RotationOrder(const Mesh& mesh, Mesh::VertexHandle v) {
  std::vector<Mesh::VertexHandle> out;
  const auto start = mesh.halfedge_handle(v);
  auto h = start;
  do {
    out.push_back(mesh.to_vertex_handle(h));
    h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
  } while (h != start);
  return out;
}

// The smoothing as the header states it, written plainly on OpenMesh's circulators and in
// place: each ring vertex in rotation order, C_L times, sees the ones updated before it.
void ReferenceSmooth(Mesh& mesh, Mesh::VertexHandle winner, double alpha_l, int iterations) {
  const std::vector<Mesh::VertexHandle> ring = RotationOrder(mesh, winner);
  std::vector<std::vector<Mesh::VertexHandle>> neighbours(ring.size());
  std::vector<Vec3> direction(ring.size());
  for (size_t i = 0; i < ring.size(); ++i) {
    const Mesh::VertexHandle q = ring[i];
    const std::vector<Mesh::VertexHandle> all = RotationOrder(mesh, q);
    if (mesh.is_boundary(q)) {
      neighbours[i] = {all.back(), all.front()};
      direction[i] = (mesh.point(all.front()) - mesh.point(all.back())).normalized();
      continue;
    }
    neighbours[i] = all;
    Vec3 n(0, 0, 0);
    for (size_t k = 0; k < all.size(); ++k) {
      n += OpenMesh::cross(mesh.point(all[k]) - mesh.point(q),
                           mesh.point(all[(k + 1) % all.size()]) - mesh.point(q));
    }
    direction[i] = n.normalized();
  }
  for (int it = 0; it < iterations; ++it) {
    for (size_t i = 0; i < ring.size(); ++i) {
      Vec3 centroid(0, 0, 0);
      for (auto u : neighbours[i]) centroid += mesh.point(u);
      centroid /= static_cast<double>(neighbours[i].size());
      const Vec3 l = centroid - mesh.point(ring[i]);
      const Vec3& d = direction[i];
      const Vec3 t =
          mesh.is_boundary(ring[i]) ? OpenMesh::dot(l, d) * d : l - OpenMesh::dot(l, d) * d;
      mesh.point(ring[i]) += alpha_l * t;
    }
  }
}

// Moves every vertex by up to `amount` in each coordinate, so that normals and centroids are
// not trivially aligned.
void Jitter(Mesh& mesh, double amount, uint64_t seed) {
  Random rng(seed);
  for (auto v : mesh.vertices()) {
    for (int c = 0; c < 3; ++c) {
      mesh.point(v)[c] +=
          amount *
          (2.0 * static_cast<double>(rng.NextIndex(1 << 20)) / static_cast<double>(1 << 20) - 1.0);
    }
  }
}

// Smooths around many winners with OneRingSmoother and with the reference, and compares every
// point after each call.
void ExpectSameAsReference(Mesh mesh, double alpha_l, int iterations, const char* shape,
                           bool allow_simd = true) {
  Mesh reference = mesh;
  OneRingSmoother smoother(allow_simd);
  VertexRingCache rings;
  Random rng(11);
  for (int call = 0; call < 300; ++call) {
    const Mesh::VertexHandle w(static_cast<int>(rng.NextIndex(mesh.n_vertices())));
    smoother.Smooth(mesh, rings, w, alpha_l, iterations);
    ReferenceSmooth(reference, w, alpha_l, iterations);
    std::vector<int> expected_moved;
    for (auto u : reference.vv_range(w)) expected_moved.push_back(u.idx());
    EXPECT_EQ(smoother.moved().size(), expected_moved.size())
        << shape << ": moved() is not the winner's ring at call " << call;
    for (auto v : mesh.vertices()) {
      ASSERT_LT((mesh.point(v) - reference.point(v)).norm(), 1e-12)
          << shape << ": vertex " << v.idx() << " differs from the reference after call " << call
          << " (winner " << w.idx() << ")";
    }
  }
}

TEST(OneRingSmootherTest, MatchesThePlainInPlaceSmoothingOnAClosedSurface) {
  Mesh mesh = MustToMesh(Icosphere(2));
  Jitter(mesh, 0.05, 1);
  ExpectSameAsReference(mesh, 0.06, 5, "icosphere");
  ExpectSameAsReference(mesh, 0.5, 3, "icosphere, large alpha_L");
}

TEST(OneRingSmootherTest, MatchesThePlainInPlaceSmoothingAlongBorders) {
  Mesh mesh = MustToMesh(GridPatch(7, 6));
  Jitter(mesh, 0.1, 2);
  ExpectSameAsReference(mesh, 0.06, 5, "grid patch");
}

TEST(OneRingSmootherTest, ScalarPathMatchesThePlainInPlaceSmoothing) {
  Mesh sphere = MustToMesh(Icosphere(2));
  Jitter(sphere, 0.05, 1);
  ExpectSameAsReference(sphere, 0.06, 5, "icosphere, scalar", /*allow_simd=*/false);
  Mesh patch = MustToMesh(GridPatch(7, 6));
  Jitter(patch, 0.1, 2);
  ExpectSameAsReference(patch, 0.06, 5, "grid patch, scalar", /*allow_simd=*/false);
}

// A seed must give the same mesh whichever path the CPU takes: the SIMD and the scalar passes
// agree to the last bit, over a long run in which their results feed back into later calls.
TEST(OneRingSmootherTest, SimdAndScalarPathsGiveBitwiseTheSamePositions) {
  OneRingSmoother simd(/*allow_simd=*/true);
  OneRingSmoother scalar(/*allow_simd=*/false);
  ASSERT_FALSE(scalar.simd()) << "allow_simd = false must select the scalar path";
  if (!simd.simd()) GTEST_SKIP() << "this CPU has no AVX2: only the scalar path runs";
  struct Case {
    Mesh mesh;
    const char* shape;
  };
  Case cases[] = {{MustToMesh(Icosphere(3)), "icosphere"}, {MustToMesh(GridPatch(9, 8)), "grid"}};
  Jitter(cases[0].mesh, 0.05, 4);
  Jitter(cases[1].mesh, 0.1, 5);
  for (Case& c : cases) {
    Mesh a = c.mesh;
    Mesh b = c.mesh;
    VertexRingCache rings_a;
    VertexRingCache rings_b;
    Random rng(12);
    for (int call = 0; call < 2000; ++call) {
      const Mesh::VertexHandle w(static_cast<int>(rng.NextIndex(a.n_vertices())));
      simd.Smooth(a, rings_a, w, 0.06, 5);
      scalar.Smooth(b, rings_b, w, 0.06, 5);
    }
    for (auto v : a.vertices()) {
      for (int k = 0; k < 3; ++k) {
        ASSERT_EQ(a.point(v)[k], b.point(v)[k])
            << c.shape << ": vertex " << v.idx() << " coordinate " << k
            << " differs between the SIMD and the scalar path";
      }
    }
  }
}

TEST(OneRingSmootherTest, LeavesTheWinnerAndEverythingOutsideItsRingAlone) {
  Mesh mesh = MustToMesh(Icosphere(2));
  Jitter(mesh, 0.05, 3);
  const Mesh before = mesh;
  const Mesh::VertexHandle w(17);
  OneRingSmoother smoother;
  VertexRingCache rings;
  smoother.Smooth(mesh, rings, w, 0.06, 5);
  std::vector<bool> in_ring(mesh.n_vertices(), false);
  for (auto u : mesh.vv_range(w)) in_ring[u.idx()] = true;
  int moved = 0;
  for (auto v : mesh.vertices()) {
    if (in_ring[v.idx()]) {
      moved += mesh.point(v) != before.point(v) ? 1 : 0;
      continue;
    }
    EXPECT_EQ(mesh.point(v), before.point(v)) << "vertex " << v.idx() << " is not in the ring";
  }
  EXPECT_GT(moved, 0) << "nothing in the ring moved";
  smoother.Smooth(mesh, rings, w, 0.0, 5);
  smoother.Smooth(mesh, rings, w, 0.06, 0);
  EXPECT_EQ(smoother.moved().size(), mesh.valence(w)) << "moved() is the ring even when idle";
}

}  // namespace
}  // namespace neuralmesh
