// The Neural Mesh learner (Ivrissimtzis, Jeong, Seidel, "Neural Meshes: Statistical Learning
// Methods in Surface Reconstruction"), one instance per reconstruction.
//
//   M <- tetrahedron around the data
//   repeat until a stop criterion holds:
//     s <- Sample(P); w <- nearest vertex of M to s             (octree, exact)
//     w <- (1 - alpha_w) w + alpha_w s                          (Eq. 1)
//     C_L times: tangential Laplacian smoothing of 1-ring(w)     (alpha_L)
//     every C_vs steps: split the vertex with the highest signal counter, or by default
//                       the one of its closed 1-ring with the largest F_v (Eq. 4-6)
//     every C_ec max(v, C_vs) steps: collapse every vertex that has not won since the last
//                         call (Eq. 10-11), then remove triangles (Eq. 2), then merge
//                         boundaries (Eq. 3)
// The departures from the paper are documented in learner_options.h.
//
// Costs: a Basic Step is O(log v); a split O(log v) (lazy counters, Section 3.3); Steps 3-5
// are O(v) and run every C_ec v steps, so a whole run to v vertices is O(v log v).
//
// Thread-safety: a Learner is used by one thread at a time. The target sampler may grow
// concurrently (GrowingPointCloud). Snapshots are consistent when taken on the learning thread,
// for example from the observer, or while Run is not executing.
#ifndef NEURALMESH_CORE_LEARNING_LEARNER_H_
#define NEURALMESH_CORE_LEARNING_LEARNER_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/learning/learner_options.h"
#include "core/mesh.h"
#include "core/sampling/sampler.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

// Counters of what the learner has done, cumulative since creation.
struct LearnerProgress {
  uint64_t basic_steps = 0;
  size_t vertices = 0;
  size_t faces = 0;
  uint64_t splits = 0;
  uint64_t collapses = 0;
  uint64_t removed_triangles = 0;
  uint64_t merged_boundaries = 0;
  // Right after Step 4 (inactive_face_removal.h): bridges cut between two holes, and border
  // vertices that Step 3 could not collapse cut out with their faces.
  uint64_t cut_bridges = 0;
  uint64_t cut_out_border_vertices = 0;
  uint64_t connectivity_calls = 0;  // Calls of Step 3 (each followed by Steps 4 and 5).
};

// Wall time spent per kind of step, filled only when timing is enabled. Steps 2-5 are timed
// every time; the Basic Step (winner_search, smoothing) is sampled: one in 17 is timed and
// counted 17 times, which keeps the clock reads to about one per six Basic Steps.
struct LearnerTimings {
  absl::Duration winner_search;  // Sampling and the octree query.
  absl::Duration smoothing;      // Eq. 1, C_L smoothing passes, octree updates of moved vertices.
  absl::Duration split;          // Step 2 including the signal counters.
  absl::Duration collapse;       // Step 3.
  absl::Duration removal;        // Step 4.
  absl::Duration merging;        // Step 5.
  // After Steps 3-5: deleted elements dropped, vertices renumbered in Morton order, the
  // octree, the counters and the ring cache rebuilt.
  absl::Duration compaction;
};

// When Run stops; the first criterion that holds wins. Zero means "no limit".
struct StopCriteria {
  size_t target_vertices = 0;
  uint64_t max_basic_steps = 0;  // Counted within this Run call.
  absl::Duration time_budget = absl::InfiniteDuration();
  const std::atomic<bool>* cancel = nullptr;  // Polled every `poll_interval` steps.
  // How often (in Basic Steps) cancel, the clock and the observer are consulted.
  uint64_t poll_interval = 1024;
  // Called every poll_interval steps at a consistent state (between two Basic Steps) and once
  // when Run returns. Returning false stops Run.
  std::function<bool(const LearnerProgress&)> observer;
};

enum class StopReason { kTargetReached, kStepBudget, kTimeBudget, kCancelled, kObserver };

class Learner {
 public:
  // Returns INVALID_ARGUMENT for invalid options and FAILED_PRECONDITION when `target` is
  // empty. `target` must outlive the learner.
  static absl::StatusOr<std::unique_ptr<Learner>> Create(const LearnerOptions& options,
                                                         const Sampler* target);
  // Learns on from `start` (a Snapshot of a learner, a mesh read from a file) instead of
  // options.initial_mesh's mesh, as the paper's learner goes on from any mesh: the vertices
  // are renumbered (Morton order), every signal counter starts at 1 as on the initial mesh,
  // no vertex counts as a winner yet, and the first Step 3 comes after C_ec v Basic Steps.
  // options.initial_mesh still says whether the longest border is the sheet's own (kDisc).
  // Returns what Create returns, and INVALID_ARGUMENT when `start` is not a mesh learning can
  // go on from (MakeStartMesh, initial_mesh.h). O(v log v).
  static absl::StatusOr<std::unique_ptr<Learner>> CreateFrom(const LearnerOptions& options,
                                                             const Sampler* target,
                                                             const TriangleMesh& start);
  ~Learner();

  // Learns until one of `stop`'s criteria holds (at least one must be set).
  // Returns INVALID_ARGUMENT when no criterion is set; FAILED_PRECONDITION when the target
  // became empty. Vertex targets are met exactly: Run returns right after the split that
  // reaches them.
  absl::StatusOr<StopReason> Run(const StopCriteria& stop);

  // One Basic Step followed by whatever Steps 2-5 are due.
  void Step();

  const Mesh& mesh() const;
  const LearnerOptions& options() const;
  LearnerProgress progress() const;
  size_t num_vertices() const;

  void EnableTimings(bool on);
  LearnerTimings timings() const;

  // From the first Basic Step with at least this many vertices on, samples are drawn a few
  // steps ahead and what their steps read is loaded meanwhile (basic_step_lookahead.h): the
  // same mesh, faster once the mesh outgrows the caches, slower while it fits. Default
  // kLookaheadFromVertices; 0: from the start. A change after that step has no effect.
  // Measured on this project's machine (learner-bench --ab_lookahead_from=0, session 13, on
  // 100,000 and 5,000,000 points): 4-12% more time per Basic Step below 20,000 vertices,
  // 2% less to 3% more from 20,000 to 25,000, 6% less to 4% more from 25,000 to 30,000, 4-10%
  // less from 30,000 to 45,000 and 12-18% less above.
  static constexpr size_t kLookaheadFromVertices = 30000;
  void SetLookaheadFromVertices(size_t vertices);

  // A compact copy of the current mesh (live vertices and faces only). O(v).
  TriangleMesh Snapshot() const;

 private:
  class Impl;
  explicit Learner(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_LEARNER_H_
