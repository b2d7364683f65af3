#include "core/learning/basic_step_lookahead.h"

#include <cmath>
#include <vector>

#include "core/learning/vertex_octree.h"
#include "core/learning/vertex_ring_cache.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

// Points uniform in a cube a little larger than the unit sphere, and how many were drawn.
class CubeSampler : public Sampler {
 public:
  Vec3 Sample(Random& rng) const override {
    ++drawn_;
    const double x = rng.NextDouble(), y = rng.NextDouble(), z = rng.NextDouble();
    return Vec3(2.4 * x - 1.2, 2.4 * y - 1.2, 2.4 * z - 1.2);
  }
  bool empty() const override { return false; }
  BoundingBox Bounds() const override {
    BoundingBox box;
    box.Extend(Vec3(-1.2, -1.2, -1.2));
    box.Extend(Vec3(1.2, 1.2, 1.2));
    return box;
  }
  int drawn() const { return drawn_; }

 private:
  mutable int drawn_ = 0;
};

// Plays Basic Steps against the lookahead the way the learner does, with moves chosen to land
// near upcoming samples, vertices inserted and indices dropped, and checks every winner against
// a search of the octree at that moment.
TEST(BasicStepLookaheadTest, WinnersAreThoseOfASearchAtTheStepItself) {
  Mesh mesh = testing::MustToMesh(testing::Icosphere(3));  // 642 vertices.
  const CubeSampler target;
  VertexOctree octree(target.Bounds(), &mesh.property(mesh.points_pph()).data_vector());
  for (auto v : mesh.vertices()) octree.Insert(v.idx());
  VertexRingCache rings;
  // Taking over at step 7, as the learner does once the mesh is large enough.
  constexpr uint64_t kFirst = 7;
  BasicStepLookahead lookahead(kFirst);
  Random rng(11);
  const CubeSampler reference;  // Draws the same samples in order, without looking ahead.
  Random reference_rng(11);
  Random moves(5);           // Chooses the test's own moves.
  std::vector<Vec3> recent;  // Samples of the last few steps, targets for moves.
  for (uint64_t step = kFirst; step < kFirst + 20000; ++step) {
    lookahead.StartStep(step, target, rng, octree, rings, mesh);
    const Vec3 expected_sample = reference.Sample(reference_rng);
    ASSERT_EQ(lookahead.sample(), expected_sample) << "step " << step;
    const int expected = octree.Nearest(lookahead.sample());
    const int winner = lookahead.Winner(octree, mesh);
    // Ties apart (none here: the coordinates are random doubles).
    ASSERT_EQ(winner, expected) << "step " << step;

    // A Basic Step's moves: the winner toward the sample, its ring a little. Now and then a
    // vertex is thrown next to a recent sample, where the early winners of the steps after it
    // are likely to have been searched for.
    const Mesh::VertexHandle w(winner);
    Vec3& pw = mesh.point(w);
    pw = 0.7 * pw + 0.3 * lookahead.sample();
    octree.Move(winner);
    lookahead.RecordMove(pw);
    if (!mesh.is_isolated(w)) {
      const VertexRingCache::RingView ring = rings.Ring(mesh, winner);
      for (int i = 0; i < ring.size; ++i) {
        Vec3& q = mesh.point(Mesh::VertexHandle(ring.neighbours[i]));
        q += 0.01 * (pw - q);
        octree.Move(ring.neighbours[i]);
        lookahead.RecordMove(q);
      }
    }
    lookahead.ContinueStep(octree, rings, mesh);
    recent.push_back(lookahead.sample());
    if (recent.size() > 8) recent.erase(recent.begin());
    if (moves.NextIndex(5) == 0) {
      const int v = static_cast<int>(moves.NextIndex(mesh.n_vertices()));
      Vec3& p = mesh.point(Mesh::VertexHandle(v));
      p = recent[moves.NextIndex(recent.size())] + Vec3(1e-9, -2e-9, 3e-9);
      octree.Move(v);
      lookahead.RecordMove(p);
    }
    if (moves.NextIndex(50) == 0) {  // A split's new vertex (isolated here: only its position
                                     // matters to the search).
      const Mesh::VertexHandle added = mesh.add_vertex(recent.back() + Vec3(0, 1e-8, 0));
      octree.Insert(added.idx());
      lookahead.RecordMove(mesh.point(added));
    }
    if (moves.NextIndex(997) == 0) lookahead.ForgetWinners();  // As after Steps 3-5.
  }
  EXPECT_EQ(target.drawn(), 20000 + BasicStepLookahead::kDepth)
      << "each sample is drawn once, kDepth steps ahead";
  // Both ways of answering were taken often.
  const BasicStepLookahead::Counts counts = lookahead.counts();
  EXPECT_GT(counts.early_winners, 5000u);
  EXPECT_GT(counts.searched_again, 1000u);
}

}  // namespace
}  // namespace neuralmesh
