#include "core/learning/basic_step_lookahead.h"

#include <algorithm>

namespace neuralmesh {
namespace {

// Relative slack on the early winner's squared distance: the bound below is computed as the
// octree computes distances, but a build that contracts them into fused multiply-adds, in one
// file and not the other, could differ in the last bits. Too wide a bound costs only a search.
constexpr double kDistanceSlack = 1e-9;

// A lower bound of |p - q|^2 over the points p of `box`, computed as the octree computes the
// squared distance of a point (VertexOctree::Nearest), where every step rounds in the same
// direction for a p inside the box, so that no such p computes to less.
double Distance2ToBox(const BoundingBox& box, const Vec3& q) {
  double gap[3];
  for (int i = 0; i < 3; ++i) gap[i] = std::max({box.min[i] - q[i], 0.0, q[i] - box.max[i]});
  return gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2];
}

const double* PointData(const Mesh& mesh, int v) {
  return mesh.point(Mesh::VertexHandle(v)).data();
}

}  // namespace

void BasicStepLookahead::StartStep(uint64_t step, const Sampler& target, Random& rng,
                                   const VertexOctree& octree, const VertexRingCache& rings,
                                   const Mesh& mesh) {
  step_ = step;
  while (drawn_ <= step + kDepth) {
    Upcoming& u = Slot(drawn_++);
    u.sample = target.Sample(rng);
    u.winner = -1;
    u.moved = BoundingBox();
  }
  target.PrefetchSample(rng);  // The next draw's point: a cache miss on large inputs.
  // Step + kDepth, just drawn: the octree's upper levels toward its sample (usually in cache).
  Upcoming& drawn = Slot(step + kDepth);
  drawn.descent = OctreeDescent{};
  octree.Descend(drawn.sample, kUpperLevels, &drawn.descent);
  // Step + 3: on down to the leaf on its sample's side, whose ids start loading.
  Upcoming& descending = Slot(step + 3);
  octree.Descend(descending.sample, VertexOctree::kToLeaf, &descending.descent);

  // Step + 2: the search, on the leaf loaded during the last step.
  Upcoming& searched = Slot(step + 2);
  searched.winner = octree.Nearest(searched.sample, &searched.distance2, searched.descent);
  if (searched.winner >= 0) {
    searched.searched_at = step;
    searched.generation = generation_;
    rings.Prefetch(searched.winner);
    octree.PrefetchLocation(searched.winner);
    __builtin_prefetch(PointData(mesh, searched.winner));
  }
}

void BasicStepLookahead::ContinueStep(const VertexOctree& octree, const VertexRingCache& rings,
                                      const Mesh& mesh) {
  // Step + kDepth: one level further down, whose block has loaded since the start of the step.
  Upcoming& drawn = Slot(step_ + kDepth);
  octree.Descend(drawn.sample, 1, &drawn.descent);
  // Step + 3: the points of the leaf it reached, whose ids have loaded since.
  octree.PrefetchNearestPoints(Slot(step_ + 3).descent);
  // Step + 2: the rings and positions of the neighbours of the winner found at the start of
  // the step (their octree locations load at their own step, learner.cc).
  if (const Upcoming& u = Slot(step_ + 2); HasWinner(u)) {
    const VertexRingCache::RingView ring = rings.CachedRing(u.winner);
    for (int i = 0; i < ring.size; ++i) {
      rings.Prefetch(ring.neighbours[i]);
      __builtin_prefetch(PointData(mesh, ring.neighbours[i]));
    }
  }
}

int BasicStepLookahead::Winner(const VertexOctree& octree, const Mesh& mesh) {
  const Upcoming& u = Slot(step_);
  if (!HasWinner(u)) {
    ++counts_.searched_again;
    return octree.Nearest(u.sample);
  }
  // Nothing nearer than the early winner can have appeared unless a step since the search
  // moved or inserted a vertex into the ball of its distance around the sample (a vertex
  // that moved away cannot get nearer), and the early winner is still at that distance unless
  // it moved itself: then its position now is in the box of the last step that moved it.
  const Vec3& winner_now = mesh.point(Mesh::VertexHandle(u.winner));
  for (uint64_t k = u.searched_at; k < step_; ++k) {
    const BoundingBox& moved = Slot(k).moved;
    if (moved.empty()) continue;
    if (Distance2ToBox(moved, u.sample) <= u.distance2 * (1 + kDistanceSlack) ||
        moved.Contains(winner_now)) {
      ++counts_.searched_again;
      return octree.Nearest(u.sample);
    }
  }
  ++counts_.early_winners;
  return u.winner;
}

}  // namespace neuralmesh
