#include "core/learning/learner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/learning/basic_step_lookahead.h"
#include "core/learning/boundary_merging.h"
#include "core/learning/half_edge_collapse.h"
#include "core/learning/inactive_face_removal.h"
#include "core/learning/initial_mesh.h"
#include "core/learning/morton_vertex_order.h"
#include "core/learning/signal_counters.h"
#include "core/learning/tangential_smoothing.h"
#include "core/learning/triangle_removal.h"
#include "core/learning/vertex_octree.h"
#include "core/learning/vertex_ring_cache.h"
#include "core/learning/vertex_split.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

using Clock = std::chrono::steady_clock;

// A prime, so that the timed Basic Steps do not beat with C_vs or the Step 3 interval.
constexpr int kTimingSamplePeriod = 17;

// The octree's leaf capacity for the learner. Its vertex indices are in Morton order (since the
// last Step 3), so a leaf's points lie close together in the positions array, and a larger
// leaf that contains the nearest vertex more often saves the search the leaves next to it:
// 64 against the octree's default of 32 took 0.95-0.97 of the time per Basic Step from 50K to
// 100K vertices and 0.97-0.98 below, on 5M and on 50K points (scripts/ab-bench.sh); 80 and 96
// measured even with 64, 128 2% slower. The meshes are the same: the search is exact.
constexpr int kOctreeBucketSize = 64;

absl::Duration Since(Clock::time_point start) { return absl::FromChrono(Clock::now() - start); }

// The mesh's positions as one vector (an OpenMesh property): the octree reads them by vertex
// index. The vector object lives as long as the mesh; its storage may move as vertices are
// added, which the octree allows.
const std::vector<Vec3>* MeshPoints(const Mesh& mesh) {
  return &mesh.property(mesh.points_pph()).data_vector();
}

// The samples the disc start fits its plane to, and the generator they are drawn with: its own,
// so that the learner's sequence is the same whichever initial mesh it starts from.
constexpr int kDiscPlaneSamples = 4096;
constexpr uint64_t kDiscPlaneSeedMix = 0x9e3779b97f4a7c15ull;

Mesh MakeInitialMesh(const LearnerOptions& options, const Sampler& target) {
  switch (options.initial_mesh) {
    case InitialMesh::kDisc: {
      Random rng(options.seed ^ kDiscPlaneSeedMix);
      return MakeInitialDisc(FitPlane(target, rng, kDiscPlaneSamples));
    }
    case InitialMesh::kTetrahedron:
      break;
  }
  return MakeInitialTetrahedron(target.Bounds());
}

}  // namespace

class Learner::Impl {
 public:
  // Learns from `initial`: the initial mesh of the options, or a start mesh (then call
  // PrepareStartMesh).
  Impl(const LearnerOptions& options, const Sampler* target, Mesh initial)
      : options_(options),
        target_(target),
        rng_(options.seed),
        mesh_(std::move(initial)),
        octree_(target->Bounds(), MeshPoints(mesh_), kOctreeBucketSize),
        counters_(options.alpha_sc) {
    mesh_.add_property(active_);
    mesh_.add_property(spared_until_);
    for (auto v : mesh_.vertices()) {
      octree_.Insert(v.idx());
      counters_.Add(v.idx(), 1.0, 0);
      mesh_.property(active_, v) = false;
      mesh_.property(spared_until_, v) = 0;
    }
    live_vertices_ = mesh_.n_vertices();
    early_phase_ = live_vertices_ < options_.early_phase_vertices;
    next_connectivity_step_ = ConnectivityInterval();
  }
  // A start mesh comes in any vertex order: renumbered as after every Step 3.
  void PrepareStartMesh() { CompactAndRefillRings(); }

  // The octree indexes mesh_'s own positions: a copy would index the original's.
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // Step 2 splits no further than `vertex_target` vertices (0: no limit), so that Run meets its
  // target exactly with splits_per_step > 1.
  void Step(size_t vertex_target = 0) {
    // With timings on, one Basic Step in kTimingSamplePeriod is timed and counted that many
    // times: a clock read costs about 50 ns here, as much as 3% of a Basic Step, and reading
    // it three times per step inflated the total that the timings are meant to break down.
    const bool timed = timings_on_ && step_ % kTimingSamplePeriod == 0;
    Clock::time_point t0;
    if (timed) t0 = Clock::now();

    // Basic Step (Section 2.1). On a large mesh its sample was drawn and its winner found a few
    // steps ago, and kept when nothing has moved near it since (basic_step_lookahead.h).
    if (!lookahead_ && live_vertices_ >= lookahead_from_vertices_) lookahead_.emplace(step_);
    Vec3 s;
    int winner;
    if (lookahead_) {
      lookahead_->StartStep(step_, *target_, rng_, octree_, rings_, mesh_);
      s = lookahead_->sample();
      winner = lookahead_->Winner(octree_, mesh_);
    } else {
      s = target_->Sample(rng_);
      target_->PrefetchSample(rng_);  // The next step's sample: a cache miss on large inputs.
      winner = octree_.Nearest(s);
    }
    const Mesh::VertexHandle w(winner);
    Clock::time_point t1;
    if (timed) {
      t1 = Clock::now();
      timings_.winner_search += kTimingSamplePeriod * absl::FromChrono(t1 - t0);
    }
    Vec3& pw = mesh_.point(w);
    pw = (1.0 - options_.alpha_w) * pw + options_.alpha_w * s;  // Eq. 1
    // The octree learns of the winner's and its neighbours' moves after the smoothing (which
    // does not search it): their locations in it load meanwhile (2-3% less time at 100K
    // vertices, the same meshes).
    octree_.PrefetchLocation(winner);
    {  // The view is valid only until the smoother reads rings.
      const VertexRingCache::RingView ring = rings_.Ring(mesh_, winner);
      for (int i = 0; i < ring.size; ++i) octree_.PrefetchLocation(ring.neighbours[i]);
    }
    smoother_.Smooth(mesh_, rings_, w, options_.alpha_l, options_.c_l);
    octree_.Move(winner);
    if (lookahead_) lookahead_->RecordMove(pw);
    for (const int q : smoother_.moved()) {
      octree_.Move(q);
      if (lookahead_) lookahead_->RecordMove(mesh_.point(Mesh::VertexHandle(q)));
    }
    if (lookahead_) lookahead_->ContinueStep(octree_, rings_, mesh_);
    if (timed) timings_.smoothing += kTimingSamplePeriod * Since(t1);

    ++step_;
    counters_.RecordWin(winner, step_);
    mesh_.property(active_, w) = true;

    if (step_ % static_cast<uint64_t>(SplitInterval()) == 0) {
      Clock::time_point t2;
      if (timings_on_) t2 = Clock::now();  // Every split is timed: they are rare.
      for (int i = 0; i < options_.splits_per_step; ++i) {
        if (vertex_target > 0 && live_vertices_ >= vertex_target) break;
        SplitMostActive();
      }
      if (timings_on_) timings_.split += Since(t2);
    }
    if (step_ >= next_connectivity_step_) ConnectivityAndTopology();
  }

  absl::StatusOr<StopReason> Run(const StopCriteria& stop) {
    if (stop.target_vertices == 0 && stop.max_basic_steps == 0 &&
        stop.time_budget == absl::InfiniteDuration() && stop.cancel == nullptr && !stop.observer) {
      return absl::InvalidArgumentError(
          "no stop criterion: set a target vertex count, a step or time budget, a cancel flag "
          "or an observer");
    }
    const uint64_t poll = std::max<uint64_t>(1, stop.poll_interval);
    const Clock::time_point start = Clock::now();
    const uint64_t first_step = step_;
    auto finish = [&](StopReason reason) -> absl::StatusOr<StopReason> {
      if (stop.observer) stop.observer(Progress());
      return reason;
    };
    if (stop.target_vertices > 0 && live_vertices_ >= stop.target_vertices) {
      return finish(StopReason::kTargetReached);
    }
    while (true) {
      for (uint64_t i = 0; i < poll; ++i) {
        if (target_->empty()) {
          return absl::FailedPreconditionError("the target space has no points to sample");
        }
        Step(stop.target_vertices);
        if (stop.target_vertices > 0 && live_vertices_ >= stop.target_vertices) {
          return finish(StopReason::kTargetReached);
        }
        if (stop.max_basic_steps > 0 && step_ - first_step >= stop.max_basic_steps) {
          return finish(StopReason::kStepBudget);
        }
      }
      if (stop.cancel != nullptr && stop.cancel->load(std::memory_order_relaxed)) {
        return finish(StopReason::kCancelled);
      }
      if (stop.time_budget != absl::InfiniteDuration() && Since(start) >= stop.time_budget) {
        return finish(StopReason::kTimeBudget);
      }
      if (stop.observer && !stop.observer(Progress())) return StopReason::kObserver;
    }
  }

  LearnerProgress Progress() const {
    LearnerProgress p = progress_;
    p.basic_steps = step_;
    p.vertices = live_vertices_;
    p.faces = mesh_.n_faces() - deleted_faces_;
    return p;
  }

  const Mesh& mesh() const { return mesh_; }
  const LearnerOptions& options() const { return options_; }
  size_t num_vertices() const { return live_vertices_; }
  void EnableTimings(bool on) { timings_on_ = on; }
  void SetLookaheadFromVertices(size_t vertices) { lookahead_from_vertices_ = vertices; }
  LearnerTimings timings() const { return timings_; }

 private:
  // C_vs, or in the early phase its own (learner_options.h).
  int SplitInterval() const { return early_phase_ ? options_.early_c_vs : options_.c_vs; }

  // C_ec * v Basic Steps, with v at least C_vs, or in the early phase its own C_ec and C_vs
  // (learner_options.h).
  uint64_t ConnectivityInterval() const {
    const double c_ec = early_phase_ ? options_.early_c_ec : options_.c_ec;
    const double v =
        std::max(static_cast<double>(live_vertices_), static_cast<double>(SplitInterval()));
    return static_cast<uint64_t>(std::ceil(c_ec * v));
  }

  // Step 2: split the most active vertex, or the largest cell next to it (see
  // split_largest_cell_near_most_active); the split vertex's counter is shared in proportion
  // to F_v (Eq. 5-6).
  void SplitMostActive() {
    const Mesh::VertexHandle v =
        ChooseSplitVertex(mesh_, rings_, counters_, options_.split_largest_cell_near_most_active);
    if (!v.is_valid()) return;
    const double counter = counters_.Value(v.idx(), step_);
    const Mesh::VertexHandle v0 = SplitVertex(mesh_, rings_, v);
    if (!v0.is_valid()) return;
    ++live_vertices_;
    if (live_vertices_ >= options_.early_phase_vertices) early_phase_ = false;
    ++progress_.splits;
    // Every ring the split changed (v, v0, the two cut neighbours, the neighbours v0 took
    // over) belongs to v0 or one of its neighbours. Each is read again at once, while the
    // half-edges the split wrote are in cache: the Basic Steps would read nearly all of them
    // before the next Step 3, each walk then a chain of misses (0.97-0.98 of the time per
    // Basic Step from 20K to 100K vertices, the same meshes).
    rings_.Invalidate(v0.idx());
    changed_rings_.clear();
    rings_.AppendRing(mesh_, v0.idx(), changed_rings_);
    for (const int u : changed_rings_) {
      rings_.Invalidate(u);
      rings_.Ring(mesh_, u);
    }
    ShareSplitCounter(mesh_, rings_, counters_, v, v0, counter, step_);
    // The new vertex counts as active: it must get a chance to win before Step 3 judges it.
    mesh_.property(active_, v0) = true;
    mesh_.property(spared_until_, v0) = mesh_.property(spared_until_, v);  // Same strip.
    octree_.Insert(v0.idx());
    if (lookahead_) lookahead_->RecordMove(mesh_.point(v0));
  }

  // Step 3, then Steps 4 and 5, every C_ec v Basic Steps (Sections 2.2, 2.3).
  void ConnectivityAndTopology() {
    Clock::time_point t0 = Clock::now();
    counters_.Flush();
    CollapseInactive();
    timings_.collapse += Since(t0);
    ++progress_.connectivity_calls;
    std::vector<Mesh::VertexHandle> growing;  // Boundary vertices Step 4 has just cut to.
    if (options_.remove_triangles) {
      t0 = Clock::now();
      TriangleRemovalOptions removal;
      removal.alpha_r = options_.alpha_r;
      // Spared: the faces around a strip sewn in the last sewn_strip_grace_calls calls.
      const uint64_t call = progress_.connectivity_calls;
      const TriangleRemovalResult removed =
          RemoveLargeTriangles(mesh_, removal, [this, call](Mesh::FaceHandle f) {
            for (auto corner : mesh_.fv_range(f)) {
              if (mesh_.property(spared_until_, corner) >= call) return true;
            }
            return false;
          });
      for (auto v : removed.removed_vertices) ForgetVertex(v);
      progress_.removed_triangles += removed.removed_faces;
      if (options_.merge_only_settled_boundaries) growing = removed.touched_vertices;
      // Inactive: not a winner since the last call of Step 3 (inactive_face_removal.h).
      auto inactive = [this](Mesh::VertexHandle v) { return !mesh_.property(active_, v); };
      std::vector<Mesh::VertexHandle>* grown =
          options_.merge_only_settled_boundaries ? &growing : nullptr;
      if (options_.cut_inactive_faces) {
        const BridgeCuttingResult cut = CutInactiveBridges(mesh_, inactive);
        progress_.cut_bridges += cut.cut_bridges;
        if (grown) {
          grown->insert(grown->end(), cut.touched_vertices.begin(), cut.touched_vertices.end());
        }
        std::vector<Mesh::VertexHandle> gone;
        for (auto v : stuck_border_vertices_) {
          if (mesh_.status(v).deleted() || !inactive(v)) continue;
          if (CutOutBorderVertex(mesh_, v, &gone, grown)) ++progress_.cut_out_border_vertices;
        }
        for (auto v : gone) ForgetVertex(v);
      }
      timings_.removal += Since(t0);
    }
    if (options_.merge_boundaries) {
      t0 = Clock::now();
      BoundaryMergingOptions merging;
      merging.alpha_m = options_.alpha_m;
      merging.min_loop_vertices = static_cast<size_t>(options_.min_merged_loop_vertices);
      merging.close_small_holes = options_.close_small_holes;
      merging.zip_border_slits = options_.close_small_holes;
      merging.close_bridged_holes = options_.close_small_holes;
      merging.hole_closing.alpha_r = options_.alpha_r;
      merging.hole_closing.alpha_m = options_.alpha_m;
      merging.hole_closing.max_loop_vertices = options_.max_closed_hole_vertices;
      merging.hole_closing.keep_longest_loop_open = options_.initial_mesh == InitialMesh::kDisc;
      // E(Area) of Eq. 3 is that of the mesh Step 5 sees: after Step 4's removals (which take
      // the largest faces, so the mean before them is larger) and the cuts. 0: measured there.
      const BoundaryMergingResult merged =
          MergeCloseBoundaries(mesh_, merging, /*mean_area=*/0, growing);
      progress_.merged_boundaries += merged.merges;
      for (auto vh : merged.sewn_vertices) {
        mesh_.property(spared_until_, vh) =
            progress_.connectivity_calls + static_cast<uint64_t>(options_.sewn_strip_grace_calls);
      }
      timings_.merging += Since(t0);
    }
    RecountDeletedFaces();
    // Every vertex is inactive again until it wins (the property is a bit vector).
    auto& active = mesh_.property(active_).data_vector();
    std::fill(active.begin(), active.end(), false);
    next_connectivity_step_ = step_ + std::max<uint64_t>(1, ConnectivityInterval());
    t0 = Clock::now();
    CompactAndRefillRings();
    if (lookahead_) lookahead_->ForgetWinners();  // And vertex indices.
    timings_.compaction += Since(t0);
  }

  void CompactAndRefillRings() {
    Compact();
    rings_.InvalidateAll();  // Collapses, removals, merges and compaction changed rings.
    // Refilled at once, in vertex order: with the edges in vertex order too, the walks read the
    // half-edges nearly in sequence, where the Basic Steps' walks one at a time would miss
    // several lines each (5% less time per step from 20K to 100K vertices, with the sort).
    for (auto v : mesh_.vertices()) {
      if (!mesh_.is_isolated(v)) rings_.Ring(mesh_, v.idx());
    }
  }

  void CollapseInactive() {
    stuck_border_vertices_.clear();
    const size_t n = mesh_.n_vertices();
    for (size_t i = 0; i < n; ++i) {
      const Mesh::VertexHandle v(static_cast<int>(i));
      if (mesh_.status(v).deleted()) continue;
      if (mesh_.property(active_, v)) continue;
      const Mesh::HalfedgeHandle h = BestCollapse(mesh_, v, live_vertices_);
      if (!h.is_valid()) {
        if (mesh_.is_boundary(v)) stuck_border_vertices_.push_back(v);
        continue;
      }
      mesh_.collapse(h);
      ForgetVertex(v);
      ++progress_.collapses;
    }
  }

  void ForgetVertex(Mesh::VertexHandle v) {
    octree_.Remove(v.idx());
    counters_.Remove(v.idx());
    --live_vertices_;
  }

  void RecountDeletedFaces() {
    size_t deleted = 0;
    for (auto f : mesh_.all_faces()) deleted += mesh_.status(f).deleted() ? 1 : 0;
    deleted_faces_ = deleted;
  }

  // Deleted elements are only marked until here. Compacting and renumbering the vertices in
  // Morton order, then the edges by their vertices (morton_vertex_order.h), keeps the data a
  // Basic Step touches close together; handles change, so the octree and the counters are
  // rebuilt: O(v log v) every C_ec v steps.
  void Compact() {
    OpenMesh::VPropHandleT<double> counter;
    mesh_.add_property(counter);
    for (auto v : mesh_.vertices()) mesh_.property(counter, v) = counters_.Value(v.idx(), step_);
    CompactInMortonOrder(mesh_);
    counters_.Clear();
    octree_ = VertexOctree(target_->Bounds(), MeshPoints(mesh_), kOctreeBucketSize);
    for (auto v : mesh_.vertices()) {
      octree_.Insert(v.idx());
      counters_.Add(v.idx(), mesh_.property(counter, v), step_);
    }
    mesh_.remove_property(counter);
    deleted_faces_ = 0;
  }

  LearnerOptions options_;
  const Sampler* target_;
  Random rng_;
  Mesh mesh_;
  VertexOctree octree_;
  SignalCounters counters_;
  OneRingSmoother smoother_;
  VertexRingCache rings_;
  // Made at the first Basic Step with at least lookahead_from_vertices_ vertices; kept since.
  std::optional<BasicStepLookahead> lookahead_;
  size_t lookahead_from_vertices_ = kLookaheadFromVertices;
  // Won, or made by a split, since the last call of Step 3 (Steps 3 and 4 act on the others).
  // One bit per vertex, so that the Basic Step's write stays in cache on any mesh.
  OpenMesh::VPropHandleT<bool> active_;
  // The last call of Step 4 that spares this vertex's faces (sewn_strip_grace_calls).
  OpenMesh::VPropHandleT<uint64_t> spared_until_;
  // Inactive boundary vertices that Step 3 could not collapse in this call.
  std::vector<Mesh::VertexHandle> stuck_border_vertices_;
  std::vector<int> changed_rings_;  // SplitMostActive's scratch.
  uint64_t step_ = 0;
  uint64_t next_connectivity_step_ = 0;
  size_t live_vertices_ = 0;
  // Until the mesh first has early_phase_vertices vertices (learner_options.h).
  bool early_phase_ = false;
  size_t deleted_faces_ = 0;
  LearnerProgress progress_;
  bool timings_on_ = false;
  LearnerTimings timings_;
};

namespace {

absl::Status CheckCreateArguments(const LearnerOptions& options, const Sampler* target) {
  NM_RETURN_IF_ERROR(options.Validate());
  if (target == nullptr) return absl::InvalidArgumentError("no target sampler given");
  if (target->empty()) {
    return absl::FailedPreconditionError("the target space is empty: there is nothing to learn");
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::unique_ptr<Learner>> Learner::Create(const LearnerOptions& options,
                                                         const Sampler* target) {
  NM_RETURN_IF_ERROR(CheckCreateArguments(options, target));
  return std::unique_ptr<Learner>(
      new Learner(std::make_unique<Impl>(options, target, MakeInitialMesh(options, *target))));
}

absl::StatusOr<std::unique_ptr<Learner>> Learner::CreateFrom(const LearnerOptions& options,
                                                             const Sampler* target,
                                                             const TriangleMesh& start) {
  NM_RETURN_IF_ERROR(CheckCreateArguments(options, target));
  NM_ASSIGN_OR_RETURN(Mesh mesh, MakeStartMesh(start));
  auto impl = std::make_unique<Impl>(options, target, std::move(mesh));
  impl->PrepareStartMesh();
  return std::unique_ptr<Learner>(new Learner(std::move(impl)));
}

Learner::Learner(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Learner::~Learner() = default;

absl::StatusOr<StopReason> Learner::Run(const StopCriteria& stop) { return impl_->Run(stop); }
void Learner::Step() { impl_->Step(); }
const Mesh& Learner::mesh() const { return impl_->mesh(); }
const LearnerOptions& Learner::options() const { return impl_->options(); }
LearnerProgress Learner::progress() const { return impl_->Progress(); }
size_t Learner::num_vertices() const { return impl_->num_vertices(); }
void Learner::EnableTimings(bool on) { impl_->EnableTimings(on); }
void Learner::SetLookaheadFromVertices(size_t vertices) {
  impl_->SetLookaheadFromVertices(vertices);
}
LearnerTimings Learner::timings() const { return impl_->timings(); }
TriangleMesh Learner::Snapshot() const { return ToTriangleMesh(impl_->mesh()); }

}  // namespace neuralmesh
