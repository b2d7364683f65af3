#include "server/session.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/analysis/mesh_report.h"
#include "core/analysis/statistical_outliers.h"
#include "core/status_macros.h"
#include "server/proto_conversion.h"
#include "server/quantization_cube.h"

namespace neuralmesh::server {
namespace {

// How often (in Basic Steps) the learner looks at the clock and the cancel flag: about a
// tenth of a millisecond of learning, small against the slice.
constexpr uint64_t kPollInterval = 128;
// The arrival sample keeps at most this many points (thinned 2x whenever it overflows).
constexpr size_t kMaxArrivalSample = size_t{1} << 16;
constexpr int kCoverageGrid = 8;
constexpr double kCoverageThreshold = 0.9;
constexpr size_t kMinCoverageSample = 256;

BoundingBox BoundsOf(absl::Span<const Vec3f> positions) {
  BoundingBox box;
  for (const Vec3f& p : positions) box.Extend(Vec3(p[0], p[1], p[2]));
  return box;
}

}  // namespace

bool IsSpatiallyBiased(absl::Span<const Vec3f> arrival_sample) {
  if (arrival_sample.size() < kMinCoverageSample) return true;
  const BoundingBox bounds = BoundsOf(arrival_sample);
  std::array<double, 3> inverse_cell;
  for (int c = 0; c < 3; ++c) {
    const double extent = bounds.max[c] - bounds.min[c];
    inverse_cell[c] = extent > 0 ? kCoverageGrid / extent : 0.0;
  }
  auto cell_of = [&](const Vec3f& p) {
    int index = 0;
    for (int c = 0; c < 3; ++c) {
      const int i = std::clamp(static_cast<int>((p[c] - bounds.min[c]) * inverse_cell[c]), 0,
                               kCoverageGrid - 1);
      index = index * kCoverageGrid + i;
    }
    return index;
  };
  std::vector<bool> reached(kCoverageGrid * kCoverageGrid * kCoverageGrid, false);
  const size_t half = arrival_sample.size() / 2;
  for (size_t i = 0; i < half; ++i) reached[cell_of(arrival_sample[i])] = true;
  size_t covered = 0;
  for (const Vec3f& p : arrival_sample) covered += reached[cell_of(p)] ? 1 : 0;
  return static_cast<double>(covered) < kCoverageThreshold * arrival_sample.size();
}

Session::Session(std::string id, std::string name, SessionConfig config, size_t max_points,
                 WorkerPool* pool, Executor* encoder, std::shared_ptr<EventLog> log,
                 std::string owner, absl::Time create_time)
    : id_(std::move(id)),
      name_(std::move(name)),
      owner_(std::move(owner)),
      config_(std::move(config)),
      create_time_(create_time),
      pool_(pool),
      encoder_(encoder),
      log_(std::move(log)),
      points_(max_points),
      point_colors_(config_.colors) {
  if (config_.outlier_removal.has_value()) {
    absl::MutexLock ingest(&ingest_mu_);
    outlier_filter_ = std::make_unique<StreamingOutlierFilter>(*config_.outlier_removal);
  }
  absl::MutexLock lock(&mu_);
  last_activity_ = absl::Now();  // Not create_time_: a restored session starts its idle time now.
  learning_.set_allowed_vertices(0);
}

Session::~Session() = default;

bool Session::AcceptsPointsLocked() const {
  return state_ == v1::SESSION_STATE_COLLECTING || state_ == v1::SESSION_STATE_LEARNING;
}

absl::Status Session::AcceptingPointsLocked() const {
  if (AcceptsPointsLocked()) return absl::OkStatus();
  return absl::FailedPreconditionError(absl::StrCat(
      "session ", id_, " is ", v1::SessionState_Name(state_), " and accepts no more points"));
}

size_t Session::AllowedVerticesLocked() const {
  if (final_vertices_ > 0) return final_vertices_;
  const double bound = std::floor(static_cast<double>(points_.size()) / config_.points_per_vertex);
  // Compared in double: a tiny points_per_vertex makes `bound` too large for a size_t.
  if (bound >= static_cast<double>(config_.target_vertices)) return config_.target_vertices;
  return static_cast<size_t>(bound);
}

absl::StatusOr<QuantizationBox> Session::CubeWithLocked(const BoundingBox& batch_bounds,
                                                        bool* grown) const {
  const int bits = config_.draco.position_quantization_bits;
  QuantizationBox box = box_;
  if (!has_box_) {
    NM_ASSIGN_OR_RETURN(box,
                        config_.bounds.has_value()
                            ? QuantizationCube(*config_.bounds, kDeclaredBoundsEnlargement, bits)
                            : QuantizationCube(batch_bounds, kFirstBatchEnlargement, bits));
  }
  *grown = !CubeContains(box, batch_bounds);
  if (!*grown) return box;
  return GrowQuantizationCube(box, batch_bounds, bits);
}

absl::StatusOr<size_t> Session::AddPoints(const PointCloud& sent, size_t* held_back,
                                          std::optional<uint64_t> first_point, size_t* skipped) {
  return AddPointsAndMaybeWake(sent, held_back, first_point, skipped, /*wake=*/true);
}

absl::Status Session::ReplayBatch(const PointCloud& batch) {
  return AddPointsAndMaybeWake(batch, nullptr, std::nullopt, nullptr, /*wake=*/false).status();
}

absl::StatusOr<size_t> Session::AddPointsAndMaybeWake(const PointCloud& sent, size_t* held_back,
                                                      std::optional<uint64_t> first_point,
                                                      size_t* skipped, bool wake) {
  if (held_back != nullptr) *held_back = 0;
  if (skipped != nullptr) *skipped = 0;
  size_t total = 0;
  {
    absl::MutexLock ingest(&ingest_mu_);
    uint64_t taken = 0;  // Only ingestion changes it, and ingest_mu_ is held.
    {
      absl::MutexLock lock(&mu_);  // Checked again below; here to spare the filter's work.
      NM_RETURN_IF_ERROR(AcceptingPointsLocked());
      taken = points_taken_;
    }
    // A batch resent after a lost connection: what the session has already is skipped.
    PointCloud unseen;
    const PointCloud* new_points = &sent;
    if (first_point.has_value()) {
      if (*first_point > taken) {
        return absl::OutOfRangeError(absl::StrCat(
            "the batch starts at point ", *first_point, " of the upload, but the session has ",
            "taken ", taken, " points: send from point ", taken, " (Session.points_taken)"));
      }
      const uint64_t already = taken - *first_point;
      if (already >= sent.positions.size()) {
        if (skipped != nullptr) *skipped = sent.positions.size();
        return points_.size();
      }
      if (already > 0) {
        unseen = PointRange(sent, static_cast<size_t>(already), sent.positions.size());
        new_points = &unseen;
        if (skipped != nullptr) *skipped = static_cast<size_t>(already);
      }
    }
    const PointCloud& batch = *new_points;
    NM_RETURN_IF_ERROR(
        GrowingPointCloud::ValidateBatch(batch.positions, batch.weights, batch.normals));
    if (!batch.colors.empty() && batch.colors.size() != batch.positions.size()) {
      return absl::InvalidArgumentError(absl::StrCat("the batch has ", batch.colors.size(),
                                                     " colours for ", batch.positions.size(),
                                                     " points"));
    }
    // The filter keeps every point received, outliers too: they count toward the limit.
    if (outlier_filter_ != nullptr &&
        batch.positions.size() >
            points_.max_points() - std::min(points_.max_points(), outlier_filter_->size())) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "receiving ", batch.positions.size(), " more points would exceed the session's limit of ",
          points_.max_points(), " points received, outliers included (", outlier_filter_->size(),
          " so far)"));
    }
    // Outliers go before anything else sees the batch: a stray point would grow the
    // quantization cube. Points held back before that pass now join the batch.
    OutlierJudgement judgement;
    size_t held_count = 0;
    size_t released = 0;  // Points held back before that pass now.
    size_t dropped = 0;   // Points held back before that are outliers for good.
    PointCloud filtered;
    const PointCloud* appended = &batch;
    if (outlier_filter_ != nullptr) {
      judgement = outlier_filter_->Judge(batch.positions);
      held_count =
          static_cast<size_t>(std::count(judgement.held.begin(), judgement.held.end(), true));
      if (held_count > 0 || !judgement.released.empty()) {
        filtered = held_count > 0 ? WithoutPoints(batch, judgement.held) : batch;
        held_outliers_.AppendTo(judgement.released, &filtered);
        appended = &filtered;
      }
    }
    // Quantization: the first data fixes the cube; later data outside it grows the cube. A
    // batch that no cube Draco can use would hold is refused before anything changes.
    std::optional<QuantizationBox> box;
    bool grown = false;
    {
      absl::MutexLock lock(&mu_);
      NM_RETURN_IF_ERROR(AcceptingPointsLocked());
      last_activity_ = absl::Now();
      if (!appended->positions.empty()) {
        absl::StatusOr<QuantizationBox> cube =
            CubeWithLocked(BoundsOf(appended->positions), &grown);
        if (!cube.ok()) return cube.status();
        box = *cube;
      }
    }
    // Stored before it is taken, as it came (outliers too, so that a restored session's filter
    // judges as this one did): a batch is acknowledged only once a restart would keep it.
    if (record_ != nullptr) {
      // `appended` holds points of batches that passed ValidateBatch.
      NM_RETURN_IF_ERROR(points_.CheckRoomFor(*appended));
      NM_RETURN_IF_ERROR(record_->AppendBatch(batch));
    }
    const size_t first_index = points_.size();
    // A batch of outliers only: nothing to append.
    if (!appended->positions.empty()) NM_RETURN_IF_ERROR(points_.Append(*appended));
    if (!appended->colors.empty()) point_colors_.Append(appended->positions, appended->colors);
    if (outlier_filter_ != nullptr) {
      held_outliers_.Hold(batch, judgement.held, static_cast<uint32_t>(outlier_filter_->size()));
      held_outliers_.Forget(judgement.released);
      held_outliers_.Forget(judgement.dropped);
      released = judgement.released.size();
      dropped = judgement.dropped.size();
      outlier_filter_->Add(batch.positions, std::move(judgement));
    }
    RecordArrivalSampleLocked(appended->positions, first_index);
    total = points_.size();
    if (held_back != nullptr) *held_back = held_count;

    absl::MutexLock lock(&mu_);
    // Only ingestion changes the cube, and ingest_mu_ is held: box_ is as CubeWithLocked saw it.
    if (box.has_value()) {
      has_box_ = true;
      box_ = *box;
      if (grown) ++epoch_;
    }
    learning_.set_points_received(total);
    points_taken_ += batch.positions.size();
    if (metrics_ != nullptr) metrics_->AddPointsAccepted(batch.positions.size());
    learning_.set_points_removed_as_outliers(learning_.points_removed_as_outliers() + dropped);
    learning_.set_outliers_accepted_later(learning_.outliers_accepted_later() + released);
    learning_.set_outliers_held(held_outliers_.size());
    learning_.set_allowed_vertices(AllowedVerticesLocked());
  }
  if (wake) Wake();
  return total;
}

void Session::RecordArrivalSampleLocked(absl::Span<const Vec3f> positions, size_t first_index) {
  // Keep the points whose arrival index is a multiple of the stride; entry j then holds point
  // j * stride, and thinning keeps the even entries.
  size_t i = (first_index + arrival_stride_ - 1) / arrival_stride_ * arrival_stride_;
  for (; i < first_index + positions.size(); i += arrival_stride_) {
    arrival_sample_.push_back(positions[i - first_index]);
    if (arrival_sample_.size() >= kMaxArrivalSample) {
      size_t kept = 0;
      for (size_t j = 0; j < arrival_sample_.size(); j += 2) {
        arrival_sample_[kept++] = arrival_sample_[j];
      }
      arrival_sample_.resize(kept);
      arrival_stride_ *= 2;
      // The next kept index is the next multiple of the new stride after i.
      i = i / arrival_stride_ * arrival_stride_;
    }
  }
}

absl::Status Session::Finish() {
  {
    absl::MutexLock ingest(&ingest_mu_);
    absl::MutexLock lock(&mu_);
    last_activity_ = absl::Now();
    if (!AcceptsPointsLocked()) {
      return absl::FailedPreconditionError(absl::StrCat(
          "session ", id_, " is ", v1::SessionState_Name(state_), " and cannot finish"));
    }
    const size_t final_vertices = AllowedVerticesLocked();
    if (final_vertices < std::max(kMinTargetVertices, start_vertices_)) {
      return absl::FailedPreconditionError(absl::StrCat(
          "session ", id_, " has ", points_.size(), " points; finishing needs at least ",
          static_cast<size_t>(
              std::ceil(std::max(kMinTargetVertices, start_vertices_) * config_.points_per_vertex)),
          start_vertices_ > kMinTargetVertices
              ? absl::StrCat(" (the start mesh's ", start_vertices_, " vertices")
              : std::string(" (4 vertices"),
          " at points_per_vertex ", config_.points_per_vertex, ")"));
    }
    NM_RETURN_IF_ERROR(StoreState(v1::SESSION_STATE_FINISHING, ""));
    final_vertices_ = final_vertices;
    state_ = v1::SESSION_STATE_FINISHING;
    learning_.set_allowed_vertices(final_vertices_);
    // No point will come near the held ones any more: their verdicts stand.
    if (outlier_filter_ != nullptr) {
      const std::vector<uint32_t> dropped = outlier_filter_->DropHeld();
      held_outliers_.Forget(dropped);
      learning_.set_points_removed_as_outliers(learning_.points_removed_as_outliers() +
                                               dropped.size());
      learning_.set_outliers_held(0);
    }
  }
  Wake();
  return absl::OkStatus();
}

absl::Status Session::Cancel(absl::string_view reason) {
  {
    absl::MutexLock lock(&mu_);
    last_activity_ = absl::Now();
    if (state_ == v1::SESSION_STATE_CANCELLED) return absl::OkStatus();
    if (state_ == v1::SESSION_STATE_FINISHED || state_ == v1::SESSION_STATE_FAILED) {
      return absl::FailedPreconditionError(absl::StrCat(
          "session ", id_, " is ", v1::SessionState_Name(state_), " and cannot be cancelled"));
    }
    NM_RETURN_IF_ERROR(StoreState(v1::SESSION_STATE_CANCELLED, std::string(reason)));
    state_ = v1::SESSION_STATE_CANCELLED;
    error_ = std::string(reason);
    cancel_.store(true);
  }
  if (metrics_ != nullptr) metrics_->CountSessionEnded(v1::SESSION_STATE_CANCELLED);
  Record(absl::StrCat("cancelled: ", reason));
  updates_.Close(absl::CancelledError(absl::StrCat("session ", id_, " was cancelled: ", reason)));
  Wake();  // Lets the pool drop the session at its next slice.
  return absl::OkStatus();
}

void Session::Terminate(const absl::Status& status) {
  {
    absl::MutexLock lock(&mu_);
    if (state_ != v1::SESSION_STATE_FINISHED && state_ != v1::SESSION_STATE_FAILED &&
        state_ != v1::SESSION_STATE_CANCELLED) {
      state_ = v1::SESSION_STATE_CANCELLED;
      error_ = std::string(status.message());
    }
    cancel_.store(true);
    encode_queue_.clear();
  }
  updates_.Close(status);
}

void Session::Fail(const absl::Status& status) {
  {
    absl::MutexLock lock(&mu_);
    // Ended already (a second failure keeps the first one's reason).
    if (state_ == v1::SESSION_STATE_CANCELLED || state_ == v1::SESSION_STATE_FINISHED ||
        state_ == v1::SESSION_STATE_FAILED) {
      return;
    }
    state_ = v1::SESSION_STATE_FAILED;
    error_ = std::string(status.message());
    cancel_.store(true);
  }
  if (metrics_ != nullptr) metrics_->CountSessionEnded(v1::SESSION_STATE_FAILED);
  Record(absl::StrCat("failed: ", status.message()));
  if (absl::Status stored = StoreState(v1::SESSION_STATE_FAILED, std::string(status.message()));
      !stored.ok()) {
    Record(absl::StrCat("could not store the failure: ", stored.message()));
  }
  updates_.Close(absl::InternalError(
      absl::StrCat("learning failed in session ", id_, ": ", status.message())));
}

absl::Status Session::StoreState(v1::SessionState state, const std::string& error) const {
  if (record_ == nullptr) return absl::OkStatus();
  return record_->SetState(state, error);
}

void Session::StoreMesh(const v1::MeshUpdate& update, bool durable) {
  if (record_ == nullptr) return;
  const absl::Status stored = record_->WriteLatestMesh(update, durable);
  if (!stored.ok() && !mesh_store_failed_.exchange(true)) {
    Record(absl::StrCat("could not store mesh ", update.sequence(),
                        " (a restart would learn it "
                        "again; later failures are not recorded): ",
                        stored.message()));
  }
}

void Session::SkipMilestonesUpToLocked(size_t vertices) {
  const std::vector<size_t>& milestones = config_.lod_milestones;
  const size_t past = static_cast<size_t>(
      std::upper_bound(milestones.begin(), milestones.end(), vertices) - milestones.begin());
  next_milestone_ = std::max(next_milestone_, past);
}

void Session::StoreCheckpoint(const Snapshot& snapshot) {
  if (record_ == nullptr) return;
  const absl::Status stored = record_->WriteCheckpoint(snapshot.mesh, snapshot.learning,
                                                       snapshot.kind == v1::UPDATE_KIND_MILESTONE
                                                           ? CheckpointKind::kMilestone
                                                           : CheckpointKind::kRefresh);
  if (!stored.ok() && !checkpoint_store_failed_.exchange(true)) {
    Record(absl::StrCat("could not store the learner's mesh of ", snapshot.mesh.positions.size(),
                        " vertices (a restart would learn on from an older one or from the "
                        "initial mesh; later failures are not recorded): ",
                        stored.message()));
  }
}

void Session::FinishRestore(v1::SessionState state, const std::string& error,
                            uint64_t paused_at_points, std::shared_ptr<v1::MeshUpdate> latest,
                            std::optional<LearnerCheckpoint> checkpoint,
                            std::unique_ptr<SessionRecord> record) {
  record_ = std::move(record);
  const bool ended = state == v1::SESSION_STATE_FINISHED || state == v1::SESSION_STATE_CANCELLED ||
                     state == v1::SESSION_STATE_FAILED;
  if (checkpoint.has_value() && !ended) {
    // Learning goes on from the checkpoint's mesh, and its counts from the checkpoint's.
    const v1::LearningState& before = checkpoint->learning;
    start_mesh_ = std::move(checkpoint->mesh);
    start_mesh_name_ = "the stored mesh";
    start_vertices_ = start_mesh_->positions.size();
    earlier_learning_.basic_steps = before.basic_steps();
    earlier_learning_.splits = before.splits();
    earlier_learning_.collapses = before.collapses();
    learning_time_ = absl::Seconds(before.learning_seconds());
    absl::MutexLock lock(&mu_);
    learning_.set_basic_steps(before.basic_steps());
    learning_.set_splits(before.splits());
    learning_.set_collapses(before.collapses());
    learning_.set_learning_seconds(before.learning_seconds());
  }
  if (latest != nullptr) {
    absl::MutexLock lock(&mu_);
    // The milestones up to the stored mesh were published before the restart. Learning again
    // publishes nothing coarser: refreshes come only after a first publication, which is a
    // later milestone or, paused for lack of points, a mesh of as many vertices as before.
    SkipMilestonesUpToLocked(latest->vertex_count());
    if (ended) {
      // The counters of the learning that ended; the points are the replayed ones.
      v1::LearningState learning = latest->learning();
      learning.set_points_received(learning_.points_received());
      learning.set_allowed_vertices(learning_.allowed_vertices());
      learning_ = learning;
    }
    updates_.Restore(std::move(latest));
  }
  switch (state) {
    case v1::SESSION_STATE_FINISHED: {
      {
        absl::MutexLock lock(&mu_);
        state_ = state;
        next_milestone_ = config_.lod_milestones.size();
      }
      updates_.Close(absl::OkStatus());
      return;
    }
    case v1::SESSION_STATE_CANCELLED:
    case v1::SESSION_STATE_FAILED: {
      {
        absl::MutexLock lock(&mu_);
        state_ = state;
        error_ = error;
        cancel_.store(true);
      }
      updates_.Close(
          state == v1::SESSION_STATE_CANCELLED
              ? absl::CancelledError(absl::StrCat("session ", id_, " was cancelled: ", error))
              : absl::InternalError(absl::StrCat("learning failed in session ", id_, ": ", error)));
      return;
    }
    case v1::SESSION_STATE_FINISHING:
      if (absl::Status finished = Finish(); !finished.ok()) Fail(finished);
      return;
    default: {
      {
        absl::MutexLock lock(&mu_);
        if (paused_at_points > 0 && points_.size() <= paused_at_points) {
          stalled_at_points_ = paused_at_points;
          learning_.set_stalled(true);
        }
      }
      Wake();
      return;
    }
  }
}

void Session::Record(absl::string_view event) const {
  if (log_ != nullptr) log_->Record(id_, event);
}

v1::SessionState Session::state() const {
  absl::MutexLock lock(&mu_);
  return state_;
}

void Session::AddStream() {
  absl::MutexLock lock(&mu_);
  ++open_streams_;
  last_activity_ = absl::Now();
}

void Session::RemoveStream() {
  absl::MutexLock lock(&mu_);
  --open_streams_;
  last_activity_ = absl::Now();
}

void Session::Touch() {
  absl::MutexLock lock(&mu_);
  last_activity_ = absl::Now();
}

bool Session::IdleSince(absl::Time now, absl::Duration timeout) const {
  absl::MutexLock lock(&mu_);
  return open_streams_ == 0 && now - last_activity_ >= timeout;
}

std::string Session::owner() const {
  absl::MutexLock lock(&owner_mu_);
  return owner_;
}

void Session::SetOwner(std::string owner) {
  absl::MutexLock lock(&owner_mu_);
  owner_ = std::move(owner);
}

v1::Session Session::ToProto() const {
  v1::Session out;
  out.set_session_id(id_);
  out.set_name(name_);
  out.set_owner(owner());
  *out.mutable_config() = SessionConfigToProto(config_);
  out.set_create_time_us(absl::ToUnixMicros(create_time_));
  if (MeshUpdatePtr latest = updates_.latest(); latest != nullptr) {
    out.set_vertex_count(latest->vertex_count());
    out.set_face_count(latest->face_count());
    out.set_latest_sequence(latest->sequence());
  }
  out.set_watchers(static_cast<uint32_t>(updates_.subscribers()));
  absl::MutexLock lock(&mu_);
  out.set_state(state_);
  *out.mutable_learning() = learning_;
  out.set_points_taken(points_taken_);
  if (next_milestone_ < config_.lod_milestones.size()) {
    out.set_next_milestone(config_.lod_milestones[next_milestone_]);
  }
  if (has_box_) *out.mutable_quantization_box() = QuantizationBoxToProto(box_);
  out.set_error(error_);
  return out;
}

void Session::Wake() {
  if (pool_ != nullptr) pool_->Wake(shared_from_this());
}

void Session::UpdateLearningState() {
  const LearnerProgress progress = learner_->progress();
  absl::MutexLock lock(&mu_);
  const uint64_t steps = earlier_learning_.basic_steps + progress.basic_steps;
  learning_.set_basic_steps(steps);
  learning_.set_splits(earlier_learning_.splits + progress.splits);
  learning_.set_collapses(earlier_learning_.collapses + progress.collapses);
  learning_.set_learning_seconds(absl::ToDoubleSeconds(learning_time_));
  learning_.set_steps_per_second(
      learning_time_ > absl::ZeroDuration() ? steps / absl::ToDoubleSeconds(learning_time_) : 0.0);
  learning_.set_relearning(relearning_);
  last_activity_ = absl::Now();
}

SliceResult Session::RunSlice(absl::Time deadline) {
  while (true) {
    if (cancel_.load()) return {SliceResult::kDone};
    size_t allowed = 0;
    bool finishing = false;
    size_t milestone_index = 0;
    {
      absl::MutexLock lock(&mu_);
      if (state_ != v1::SESSION_STATE_COLLECTING && state_ != v1::SESSION_STATE_LEARNING &&
          state_ != v1::SESSION_STATE_FINISHING) {
        return {SliceResult::kDone};
      }
      allowed = AllowedVerticesLocked();
      finishing = state_ == v1::SESSION_STATE_FINISHING;
      milestone_index = next_milestone_;
    }

    if (finishing && !final_pass_decided_) {
      final_pass_decided_ = true;
      bool relearn = false;
      if (learner_ != nullptr || start_mesh_.has_value()) {
        if (config_.final_pass == FinalPass::kRelearn) {
          relearn = true;
        } else if (config_.final_pass == FinalPass::kAuto) {
          absl::MutexLock ingest(&ingest_mu_);
          relearn = IsSpatiallyBiased(arrival_sample_);
        }
      }
      if (relearn) {
        if (learner_ != nullptr) {
          const LearnerProgress progress = learner_->progress();
          earlier_learning_.basic_steps += progress.basic_steps;
          earlier_learning_.splits += progress.splits;
          earlier_learning_.collapses += progress.collapses;
          learner_.reset();
        }
        start_mesh_.reset();
        relearning_ = true;
      }
    }

    if (learner_ == nullptr) {
      // A start mesh waits for points enough for its vertices.
      if (allowed < std::max(kMinTargetVertices, start_vertices_)) return {SliceResult::kIdle};
      absl::StatusOr<std::unique_ptr<Learner>> learner = CreateLearner();
      if (!learner.ok()) {
        Fail(learner.status());
        return {SliceResult::kDone};
      }
      learner_ = *std::move(learner);
      growth_.emplace(LongestSplitInterval(config_.learner), learner_->num_vertices(), 0);
      {
        absl::MutexLock lock(&mu_);
        if (state_ == v1::SESSION_STATE_COLLECTING) state_ = v1::SESSION_STATE_LEARNING;
        // Milestones the start mesh has reached already are not published.
        SkipMilestonesUpToLocked(learner_->num_vertices());
        milestone_index = next_milestone_;
      }
      // A start mesh is shown at once (a restored session shows its stored mesh instead).
      if (updates_.latest() == nullptr && learner_->num_vertices() == start_vertices_ &&
          !relearning_ && !(finishing && learner_->num_vertices() >= allowed)) {
        const std::vector<size_t>& milestones = config_.lod_milestones;
        TakeSnapshot(v1::UPDATE_KIND_REFRESH,
                     milestone_index < milestones.size() ? milestones[milestone_index]
                                                         : config_.target_vertices,
                     static_cast<uint32_t>(milestone_index));
      }
    }

    if (stalled_at_points_.has_value()) {
      // Stalled while collecting: learning goes on once more points have come (or none will).
      {
        absl::MutexLock lock(&mu_);
        if (!finishing && points_.size() <= *stalled_at_points_) return {SliceResult::kIdle};
        stalled_at_points_.reset();
        learning_.set_stalled(false);
      }
      growth_.emplace(LongestSplitInterval(config_.learner), learner_->num_vertices(),
                      learner_->progress().basic_steps);
    }

    const std::vector<size_t>& milestones = config_.lod_milestones;
    const size_t vertices = learner_->num_vertices();

    // A milestone reached is published as such, unless it is the final count (published as
    // the final mesh below). While relearning, the watchers have seen these counts already.
    if (!relearning_ && milestone_index < milestones.size() &&
        vertices >= milestones[milestone_index] &&
        !(finishing && milestones[milestone_index] >= allowed)) {
      TakeSnapshot(v1::UPDATE_KIND_MILESTONE, milestones[milestone_index],
                   static_cast<uint32_t>(milestone_index));
      absl::MutexLock lock(&mu_);
      ++next_milestone_;
      continue;
    }

    if (vertices >= allowed) {
      if (finishing) {
        uint32_t lod_index = static_cast<uint32_t>(
            std::lower_bound(milestones.begin(), milestones.end(), allowed) - milestones.begin());
        TakeSnapshot(v1::UPDATE_KIND_FINAL, allowed, lod_index);
        {
          absl::MutexLock lock(&mu_);
          next_milestone_ = milestones.size();
        }
        learner_.reset();  // The final mesh is copied; free the learner's memory.
        return {SliceResult::kDone};
      }
      // Paused for lack of points: show the mesh as it is, at most once per refresh interval.
      const uint64_t steps = learner_->progress().basic_steps;
      if (config_.refresh_interval == absl::ZeroDuration() || steps == last_publish_steps_) {
        return {SliceResult::kIdle};
      }
      const absl::Time due = last_publish_time_ + config_.refresh_interval;
      if (absl::Now() < due) return {SliceResult::kIdle, due};
      const size_t heading = milestone_index < milestones.size() ? milestones[milestone_index]
                                                                 : config_.target_vertices;
      TakeSnapshot(v1::UPDATE_KIND_REFRESH, heading, static_cast<uint32_t>(milestone_index));
      return {SliceResult::kIdle};
    }

    absl::Time now = absl::Now();
    if (now >= deadline) return {SliceResult::kMore};
    size_t goal = allowed;
    if (!relearning_ && milestone_index < milestones.size()) {
      goal = std::min(goal, milestones[milestone_index]);
    }
    const bool refreshing = !relearning_ && config_.refresh_interval > absl::ZeroDuration();
    absl::Time stop_at = deadline;
    if (refreshing && last_publish_time_ != absl::InfinitePast()) {
      const absl::Time due = last_publish_time_ + config_.refresh_interval;
      if (now >= due && learner_->progress().basic_steps != last_publish_steps_) {
        const size_t heading = milestone_index < milestones.size() ? milestones[milestone_index]
                                                                   : config_.target_vertices;
        TakeSnapshot(v1::UPDATE_KIND_REFRESH, heading, static_cast<uint32_t>(milestone_index));
        continue;
      }
      stop_at = std::min(stop_at, due);
    }

    StopCriteria stop;
    stop.target_vertices = goal;
    stop.time_budget = std::max(stop_at - now, absl::Microseconds(100));
    stop.cancel = &cancel_;
    stop.poll_interval = kPollInterval;
    const absl::Time run_start = absl::Now();
    const uint64_t steps_before = learner_->progress().basic_steps;
    absl::StatusOr<StopReason> reason = learner_->Run(stop);
    const absl::Duration ran = absl::Now() - run_start;
    learning_time_ += ran;
    if (metrics_ != nullptr) {
      metrics_->AddLearning(learner_->progress().basic_steps - steps_before, ran);
    }
    if (!reason.ok()) {
      Fail(reason.status());
      return {SliceResult::kDone};
    }
    UpdateLearningState();
    if (absl::Status growth =
            growth_->Check(learner_->num_vertices(), learner_->progress().basic_steps);
        !growth.ok()) {
      if (finishing) {  // No point will come to let the mesh grow.
        Fail(growth);
        return {SliceResult::kDone};
      }
      size_t points = 0;
      {
        absl::MutexLock lock(&mu_);
        points = points_.size();
        stalled_at_points_ = points;
        learning_.set_stalled(true);
      }
      Record(absl::StrCat("paused: ", growth.message(), "; waiting for points past ", points));
      if (record_ != nullptr) {
        if (absl::Status stored = record_->SetPausedAt(points); !stored.ok()) {
          Record(
              absl::StrCat("could not store the pause (a restart would learn until it "
                           "stalls again): ",
                           stored.message()));
        }
      }
      return {SliceResult::kIdle};
    }
  }
}

absl::StatusOr<std::unique_ptr<Learner>> Session::CreateLearner() {
  if (!start_mesh_.has_value()) return Learner::Create(config_.learner, &points_);
  const TriangleMesh start = *std::move(start_mesh_);
  start_mesh_.reset();
  absl::StatusOr<std::unique_ptr<Learner>> learner =
      Learner::CreateFrom(config_.learner, &points_, start);
  if (learner.ok()) {
    Record(absl::StrCat("learning goes on from ", start_mesh_name_, " of ", start.positions.size(),
                        " vertices"));
    return learner;
  }
  Record(absl::StrCat("cannot learn on from ", start_mesh_name_, " (", learner.status().message(),
                      "); learning again from the initial mesh"));
  return Learner::Create(config_.learner, &points_);
}

void Session::TakeSnapshot(v1::UpdateKind kind, size_t milestone, uint32_t lod_index) {
  Snapshot snapshot;
  snapshot.mesh = learner_->Snapshot();
  snapshot.mesh.origin = config_.origin;
  snapshot.kind = kind;
  snapshot.lod_milestone = milestone;
  snapshot.lod_index = lod_index;
  snapshot.taken = absl::Now();
  last_publish_time_ = snapshot.taken;
  last_publish_steps_ = learner_->progress().basic_steps;
  UpdateLearningState();
  absl::MutexLock lock(&mu_);
  snapshot.learning = learning_;
  snapshot.state = kind == v1::UPDATE_KIND_FINAL ? v1::SESSION_STATE_FINISHED : state_;
  snapshot.box = box_;
  snapshot.epoch = epoch_;
  // A refresh that the encoder has not started yet is replaced by the newer one; milestones
  // and the final mesh are never dropped (there are few of them).
  if (kind == v1::UPDATE_KIND_REFRESH && !encode_queue_.empty() &&
      encode_queue_.back().kind == v1::UPDATE_KIND_REFRESH) {
    encode_queue_.back() = std::move(snapshot);
  } else {
    encode_queue_.push_back(std::move(snapshot));
  }
  if (!encoding_) ScheduleEncodeLocked();
}

void Session::ScheduleEncodeLocked() {
  encoding_ = true;
  std::shared_ptr<Session> self = shared_from_this();
  if (!encoder_->Schedule([self] { self->EncodeNext(); })) encoding_ = false;
}

void Session::EncodeNext() {
  Snapshot snapshot;
  {
    absl::MutexLock lock(&mu_);
    if (encode_queue_.empty()) {
      encoding_ = false;
      return;
    }
    snapshot = std::move(encode_queue_.front());
    encode_queue_.pop_front();
  }
  absl::StatusOr<std::shared_ptr<v1::MeshUpdate>> update = Encode(snapshot);
  if (!update.ok()) {
    Fail(update.status());
  } else if (snapshot.kind == v1::UPDATE_KIND_FINAL) {
    bool finished = false;
    {
      absl::MutexLock lock(&mu_);
      if (state_ == v1::SESSION_STATE_FINISHING) {
        state_ = v1::SESSION_STATE_FINISHED;
        finished = true;
      }
    }
    if (finished) {
      const std::shared_ptr<v1::MeshUpdate> final_mesh_ptr = *update;
      const v1::MeshUpdate& final_mesh = *final_mesh_ptr;
      if (metrics_ != nullptr) metrics_->CountSessionEnded(v1::SESSION_STATE_FINISHED);
      Record(absl::StrFormat(
          "finished: %d vertices, %d faces, genus %d, %d boundaries, %d Basic Steps in %.2f s "
          "of learning, %d points",
          final_mesh.vertex_count(), final_mesh.face_count(), final_mesh.report().genus(),
          final_mesh.report().boundary_loops(), final_mesh.learning().basic_steps(),
          final_mesh.learning().learning_seconds(), final_mesh.learning().points_received()));
      // Stored before any watcher has it, so that a client that has the final mesh finds it
      // again after a restart. Only this task publishes, so the sequence number it will get is
      // known.
      final_mesh_ptr->set_sequence(updates_.next_sequence());
      StoreMesh(final_mesh, /*durable=*/true);
      if (absl::Status stored = StoreState(v1::SESSION_STATE_FINISHED, ""); !stored.ok()) {
        Record(
            absl::StrCat("could not store the finish (a restart would learn the final mesh "
                         "again): ",
                         stored.message()));
      }
      if (updates_.Publish(final_mesh_ptr) != 0 && metrics_ != nullptr) {
        metrics_->AddMeshPublished(final_mesh.draco_mesh().size());
      }
      updates_.Close(absl::OkStatus());
    }
  } else {
    const std::shared_ptr<v1::MeshUpdate> published = *update;
    if (updates_.Publish(published) != 0) {
      if (metrics_ != nullptr) metrics_->AddMeshPublished(published->draco_mesh().size());
      StoreMesh(*published, /*durable=*/false);
      StoreCheckpoint(snapshot);
    }
  }
  // One snapshot per task, so that sessions take turns on the encoder threads.
  absl::MutexLock lock(&mu_);
  if (encode_queue_.empty()) {
    encoding_ = false;
  } else {
    ScheduleEncodeLocked();
  }
}

absl::StatusOr<std::shared_ptr<v1::MeshUpdate>> Session::Encode(const Snapshot& snapshot) const {
  auto update = std::make_shared<v1::MeshUpdate>();
  update->set_session_id(id_);
  update->set_kind(snapshot.kind);
  update->set_lod_milestone(snapshot.lod_milestone);
  update->set_lod_index(snapshot.lod_index);
  update->set_vertex_count(snapshot.mesh.positions.size());
  update->set_face_count(snapshot.mesh.faces.size());
  *update->mutable_report() = MeshReportToProto(ComputeMeshReport(snapshot.mesh));
  *update->mutable_learning() = snapshot.learning;
  update->set_state(snapshot.state);
  *update->mutable_quantization_box() = QuantizationBoxToProto(snapshot.box);
  update->set_quantization_epoch(snapshot.epoch);
  update->set_snapshot_time_us(absl::ToUnixMicros(snapshot.taken));

  // Early coarse meshes (the initial tetrahedron encloses the data) may reach outside the
  // cube; clamping a copy of them keeps one grid for the whole session (the snapshot stays as
  // the learner had it, for the checkpoint).
  const QuantizationBox& box = snapshot.box;
  auto inside = [&box](const Vec3f& p) {
    for (int c = 0; c < 3; ++c) {
      if (!(p[c] >= box.origin[c] && p[c] <= box.origin[c] + box.range)) return false;
    }
    return true;
  };
  // A clamped or painted mesh is one copy of the snapshot, clamped first.
  const bool clamp =
      !std::all_of(snapshot.mesh.positions.begin(), snapshot.mesh.positions.end(), inside);
  const bool paint = point_colors_.size() > 0;
  const TriangleMesh* mesh = &snapshot.mesh;
  TriangleMesh copy;
  if (clamp || paint) {
    copy = snapshot.mesh;
    mesh = &copy;
  }
  if (clamp) {
    for (Vec3f& p : copy.positions) {
      for (int c = 0; c < 3; ++c) {
        p[c] = std::clamp(p[c], box.origin[c], box.origin[c] + box.range);
      }
    }
  }
  if (paint) {
    const absl::Time paint_start = absl::Now();
    point_colors_.Paint(&copy);
    if (metrics_ != nullptr) metrics_->AddMeshPainted(absl::Now() - paint_start);
  }
  update->mutable_report()->set_colored(!mesh->colors.empty());
  DracoOptions options = config_.draco;
  options.quantization_box = box;
  const absl::Time start = absl::Now();
  absl::StatusOr<std::string> bytes = EncodeMesh(*mesh, options);
  if (!bytes.ok()) return bytes.status();
  update->set_encode_time_us(absl::ToInt64Microseconds(absl::Now() - start));
  update->set_draco_mesh(*std::move(bytes));
  return update;
}

}  // namespace neuralmesh::server
