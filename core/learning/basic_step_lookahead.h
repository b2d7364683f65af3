// The samples of the next Basic Steps drawn a few steps ahead, their winners found early, and
// what each of those steps will read loaded while the steps before it run.
//
// Once the mesh outgrows the caches, a Basic Step (Section 2.1) waits on a chain of loads from
// memory: the octree leaf around the sample, the winner's ring, the rings and positions of its
// neighbours, the positions of theirs (tangential_smoothing.h). Each link needs the one before
// it, so one step cannot overlap them; but two steps' chains are independent unless their
// neighbourhoods meet. So the sample of step t is drawn at step t - 4 and one link of its chain
// starts loading at the start and midway through each step in between:
//
//   step t-4: draw the sample s and descend the octree's upper levels toward it (in cache),
//             loading the block of the level below; midway, one level down, loading the next
//   step t-3: on down to the leaf on s's side (mostly one level), loading its ids; midway,
//             their points
//   step t-2: w <- the vertex nearest to s (its leaf is in cache now); load w's ring,
//             position and octree location; midway, the rings and positions of w's
//             neighbours
//   step t:   the Basic Step, with winner w unless steps t-2 and t-1 moved w, or moved or
//             inserted a vertex to within w's distance of s (tested against the bounding box
//             of each step's moves); then the octree is searched again
//
// The descent is spread so because the octree's lower levels do not stay in cache on a large
// mesh: taken at once, it waited on two or three of their blocks in a row. The rest of the
// chain is left to the step itself: the positions of the neighbours' neighbours lie mostly in
// the leaf the search read, and the octree locations of w's neighbours load just before the
// smoothing (learner.cc). Loading them here too, at step t-1 and midway through step t-2,
// took 1.04-1.07 and 1.01-1.02 of the time per Basic Step from 50K to 100K vertices.
//
// That is exactly the winner of a search at step t (ties apart: when two vertices are at the
// same distance from s, either is nearest, and which one the octree returns depends on its
// shape at the time of the search). The samples are drawn in the same order from the same
// generator, so a seed still gives one mesh. After Steps 3-5 (vertices removed, renumbered)
// the early winners are dropped and searched for again. The learner looks ahead only on large
// meshes, where it pays (Learner::SetLookaheadFromVertices).
#ifndef NEURALMESH_CORE_LEARNING_BASIC_STEP_LOOKAHEAD_H_
#define NEURALMESH_CORE_LEARNING_BASIC_STEP_LOOKAHEAD_H_

#include <array>
#include <cstdint>

#include "core/bounding_box.h"
#include "core/learning/vertex_octree.h"
#include "core/learning/vertex_ring_cache.h"
#include "core/mesh.h"
#include "core/random.h"
#include "core/sampling/sampler.h"

namespace neuralmesh {

class BasicStepLookahead {
 public:
  // Basic Steps between drawing a sample and learning from it.
  static constexpr int kDepth = 4;
  // Octree levels descended when a sample is drawn: the upper ones, which stay in cache (a
  // 100K-vertex mesh's leaves are mostly five levels down).
  static constexpr int kUpperLevels = 3;

  // Takes over the drawing of samples from Basic Step `first_step` on.
  explicit BasicStepLookahead(uint64_t first_step) : step_(first_step), drawn_(first_step) {}

  // Starts Basic Step `step` (first_step, then each next one, none skipped): draws the
  // samples up to step + kDepth from `target` with `rng`, searches the winner of step + 2 and
  // starts the loads of steps step + 2, step + 3 and step + kDepth. `octree`, `rings` and
  // `mesh` must agree (the octree indexes the mesh's positions and has had every Move).
  void StartStep(uint64_t step, const Sampler& target, Random& rng, const VertexOctree& octree,
                 const VertexRingCache& rings, const Mesh& mesh);
  // Starts the loads of steps step + 2, step + 3 and step + kDepth; called midway through the
  // step (after the smoothing and its octree moves), so that the processor's few buffers for
  // outstanding misses are not all asked for at once: prefetches beyond them are dropped.
  void ContinueStep(const VertexOctree& octree, const VertexRingCache& rings, const Mesh& mesh);

  // The sample of the step started last.
  const Vec3& sample() const { return Slot(step_).sample; }
  // The vertex nearest to sample(): the early winner when nothing moved near it since, else
  // the result of a new search of `octree`. -1 only when the octree is empty.
  int Winner(const VertexOctree& octree, const Mesh& mesh);

  // How Winner answered, since construction.
  struct Counts {
    uint64_t early_winners = 0;   // The winner found two steps before.
    uint64_t searched_again = 0;  // A new search: something moved near, or none was found.
  };
  const Counts& counts() const { return counts_; }

  // Records that the step started last moved (or inserted) a vertex to `p`.
  void RecordMove(const Vec3& p) { Slot(step_).moved.Extend(p); }
  // Drops every early winner: vertices were removed or renumbered (Steps 3-5).
  void ForgetWinners() { ++generation_; }

 private:
  struct Upcoming {
    Vec3 sample;
    OctreeDescent descent;     // Toward the leaf on the sample's side.
    int winner = -1;           // Found at the start of step `searched_at`, of generation
    uint64_t searched_at = 0;  // `generation`; -1: not searched.
    uint64_t generation = 0;
    double distance2 = 0;  // |winner - sample|^2 then, as the octree computed it.
    BoundingBox moved;     // Where this step, once run, moved or inserted vertices.
  };
  // Steps step_ - 3 to step_ + kDepth, by step modulo the size.
  static constexpr size_t kSlots = 8;
  static_assert(kSlots >= 2 * kDepth, "the moves since a search and the drawn steps must fit");
  Upcoming& Slot(uint64_t step) { return slots_[step % kSlots]; }
  const Upcoming& Slot(uint64_t step) const { return slots_[step % kSlots]; }
  bool HasWinner(const Upcoming& u) const { return u.winner >= 0 && u.generation == generation_; }

  std::array<Upcoming, kSlots> slots_;
  uint64_t step_;   // The step started last.
  uint64_t drawn_;  // Samples drawn: those of steps first_step .. drawn_ - 1.
  uint64_t generation_ = 1;
  Counts counts_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_BASIC_STEP_LOOKAHEAD_H_
