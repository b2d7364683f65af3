// One reconstruction session: a growing point cloud, the Neural Mesh learner that learns from
// it while it grows, and the channel its meshes are published on.
//
// Threads:
//  * Ingestion (AddPoints) runs on gRPC threads (on the server's filter executor for a session
//    that filters outliers), concurrently with learning: the point cloud takes appends while
//    the learner samples it.
//  * Learning runs in time slices on the WorkerPool (RunSlice); the pool runs one slice of a
//    session at a time, so the learner and the members marked "learning thread" below are
//    touched by one thread at a time without a lock (the pool's mutex orders the slices).
//  * Snapshots are copied on the learning thread and encoded (Draco, mesh report) on the
//    encoder Executor, one at a time per session so sequence numbers follow learning order.
//
// Learning follows the data: the mesh may have at most
//   allowed = min(target, floor(points_received / points_per_vertex))
// vertices (after Finish: the final count, the same bound frozen). The learner is created once
// allowed >= 4, with its initial tetrahedron around the points received so far; with a start
// mesh (CreateSessionRequest.start_mesh), once allowed reaches its vertex count, and the start
// mesh is published first. A slice runs the learner toward min(next milestone, allowed); at a
// milestone it snapshots; between milestones it snapshots every refresh interval; when it
// reaches `allowed` it pauses (one more refresh snapshot) until more points arrive.
//
// With a state directory (session_store.h) the session keeps its identity, state changes,
// batches, latest mesh and learner checkpoint on disk through a SessionRecord, and a server
// that starts again restores it: its batches are taken again in their order (so the points,
// the quantization cube and the outlier filter's verdicts come out as before), the stored
// latest mesh is published again with its sequence number, and a session that was still
// learning learns on from the learner's mesh at its latest checkpoint (a milestone, or a
// refresh every checkpoint interval; without one, again from the initial mesh), publishing no
// mesh coarser than the stored one (the milestones up to it are skipped). Its counters (Basic
// Steps, splits, collapses, learning time) go on from those of the checkpoint.
//
// A learner whose vertex count makes no new maximum for kStallSplits * C_vs Basic Steps while
// it should grow (Step 3 collapsing as many vertices as Step 2 splits, as happens on some thin
// shapes at a few vertices) fails the session with a message instead of spinning forever.
#ifndef NEURALMESH_SERVER_SESSION_H_
#define NEURALMESH_SERVER_SESSION_H_

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "absl/types/span.h"
#include "core/analysis/color_source.h"
#include "core/analysis/streaming_outlier_filter.h"
#include "core/bounding_box.h"
#include "core/io/draco_codec.h"
#include "core/learning/growth_watch.h"
#include "core/learning/learner.h"
#include "core/point_cloud.h"
#include "core/sampling/growing_point_cloud.h"
#include "core/triangle_mesh.h"
#include "neuralmesh/v1/reconstruction.pb.h"
#include "server/event_log.h"
#include "server/executor.h"
#include "server/held_outliers.h"
#include "server/server_metrics.h"
#include "server/session_config.h"
#include "server/session_store.h"
#include "server/update_channel.h"
#include "server/worker_pool.h"

namespace neuralmesh::server {

// Whether points arrived in a spatially biased order (region after region). `arrival_sample`
// holds points in arrival order, sampled uniformly over that order. Over a coarse 8x8x8 grid
// on the sample's bounds, counts the share of all sample points whose cell also holds a point
// of the first half of the sample: biased when below 90%. Random order gives nearly 100%; a
// scan, about 50%. Samples of fewer than 256 points count as biased (relearning them is cheap).
bool IsSpatiallyBiased(absl::Span<const Vec3f> arrival_sample);

class Session : public Schedulable, public std::enable_shared_from_this<Session> {
 public:
  // `config` must have passed ResolveSessionConfig. `pool` and `encoder` must outlive every
  // slice and encoding task of the session (the server shuts them down before it lets go).
  // `log`, when set, records the session's end (finished, cancelled, failed). `owner` is the
  // client name of the access token that created the session (session_access.h); empty
  // without one.
  Session(std::string id, std::string name, SessionConfig config, size_t max_points,
          WorkerPool* pool, Executor* encoder, std::shared_ptr<EventLog> log = nullptr,
          std::string owner = "", absl::Time create_time = absl::Now());
  ~Session() override;

  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Keeps the session on disk from now on (session_store.h): every batch taken, every state
  // change and every published mesh. Once, before the session is shared with other threads.
  void AttachRecord(std::unique_ptr<SessionRecord> record) { record_ = std::move(record); }
  // The session's files, or null without a state directory.
  SessionRecord* record() const { return record_.get(); }
  // Adds the session's work from now on to `metrics` (server_metrics.h): points accepted,
  // learning, meshes published, its end. Once, before the session is shared with other threads
  // (for a restored one: after its batches are taken again, which are not new work).
  void AttachMetrics(ServerMetrics* metrics) { metrics_ = metrics; }
  // Learning starts from `mesh` (CreateSessionRequest.start_mesh, checked by CheckStartMesh)
  // once the points allow its vertex count, and publishes it first. Once, before the session
  // is shared with other threads.
  void SetStartMesh(TriangleMesh mesh) {
    start_vertices_ = mesh.positions.size();
    start_mesh_ = std::move(mesh);
  }

  // Restoring a stored session, before it is shared: ReplayBatch takes each batch of its
  // journal as AddPoints took it, without waking the learner; FinishRestore then restores the
  // stored state and latest mesh (which must belong to the session and carry its sequence
  // number), attaches `record`, and sets learning going again unless the session had ended:
  // from `checkpoint`'s mesh when there is one (unless the final pass relearns, see
  // SessionConfig::final_pass), and from the initial mesh when there is none or the learner
  // cannot take it (the event log says why). A collecting session that had paused for lack of
  // growth at `paused_at_points` points (0: never) and has no more waits paused again.
  absl::Status ReplayBatch(const PointCloud& batch) ABSL_LOCKS_EXCLUDED(ingest_mu_, mu_);
  void FinishRestore(v1::SessionState state, const std::string& error, uint64_t paused_at_points,
                     std::shared_ptr<v1::MeshUpdate> latest,
                     std::optional<LearnerCheckpoint> checkpoint,
                     std::unique_ptr<SessionRecord> record) ABSL_LOCKS_EXCLUDED(ingest_mu_, mu_);

  const std::string& id() const { return id_; }
  const std::string& name() const { return name_; }
  // The client that owns the session (session_access.h): its creator, or the client it was
  // handed to since (SetOwner).
  std::string owner() const ABSL_LOCKS_EXCLUDED(owner_mu_);
  void SetOwner(std::string owner) ABSL_LOCKS_EXCLUDED(owner_mu_);
  const SessionConfig& config() const { return config_; }
  // Whether AddPoints filters outliers (SessionConfig::outlier_removal): work proportional to
  // the batch times log^2 of the points so far, too long for a gRPC callback thread.
  bool filters_outliers() const { return config_.outlier_removal.has_value(); }
  absl::Time create_time() const { return create_time_; }

  // Appends one batch, all or nothing, and wakes the learner. With outlier removal configured,
  // the batch's outliers (streaming_outlier_filter.h) are held back and their count goes to
  // `*held_back` when it is not null (0 otherwise); the rest is appended, with the points held
  // back by earlier batches that the filter now accepts. Returns the session's running total.
  // FAILED_PRECONDITION when the session no longer accepts points (finishing, finished,
  // cancelled, failed); INVALID_ARGUMENT for non-finite values or mismatched
  // weights/normals/colours; RESOURCE_EXHAUSTED when the session's point limit would be
  // exceeded (with outlier removal, by the points received, outliers included). On error
  // nothing changes.
  //
  // With `first_point` (the batch's place in the client's upload, PointBatch.first_point), the
  // points the session has taken already are skipped, their count going to `*skipped`: a
  // batch resent after a lost connection adds only what is new. OUT_OF_RANGE, nothing taken,
  // when `first_point` is beyond the points taken (a gap).
  //
  // With a record, the batch is stored before it is taken; when that fails (a full disk:
  // RESOURCE_EXHAUSTED) the batch is refused and nothing changes.
  absl::StatusOr<size_t> AddPoints(const PointCloud& batch, size_t* held_back = nullptr,
                                   std::optional<uint64_t> first_point = std::nullopt,
                                   size_t* skipped = nullptr) ABSL_LOCKS_EXCLUDED(ingest_mu_, mu_);

  // No more points: learn to the final vertex count and publish the final mesh. The points
  // outlier removal still holds back are dropped. FAILED_PRECONDITION when already finishing,
  // finished, cancelled or failed, or when the points received are too few for the initial
  // tetrahedron; with a record, the error of storing the new state (nothing changes then).
  absl::Status Finish() ABSL_LOCKS_EXCLUDED(ingest_mu_, mu_);

  // Stops learning; watchers end with CANCELLED and `reason`. Cancelling a cancelled session is
  // a no-op. FAILED_PRECONDITION when finished or failed; with a record, the error of storing
  // the new state (nothing changes then).
  absl::Status Cancel(absl::string_view reason) ABSL_LOCKS_EXCLUDED(mu_);

  // Ends the session in this process (deletion, server shutdown): cancels learning if it still
  // runs and ends every watcher with `status`. The record, if any, is left as it is: a deleted
  // session's caller removes it.
  void Terminate(const absl::Status& status) ABSL_LOCKS_EXCLUDED(mu_);

  v1::SessionState state() const ABSL_LOCKS_EXCLUDED(mu_);
  size_t points_received() const { return points_.size(); }
  v1::Session ToProto() const ABSL_LOCKS_EXCLUDED(mu_);

  // The session's mesh updates (latest wins).
  UpdateChannel& updates() { return updates_; }

  // Open streams (watchers, uploads) keep a session from idling out.
  void AddStream() ABSL_LOCKS_EXCLUDED(mu_);
  void RemoveStream() ABSL_LOCKS_EXCLUDED(mu_);
  // Records activity now (any RPC on the session, any learning slice).
  void Touch() ABSL_LOCKS_EXCLUDED(mu_);
  // Whether nothing happened for `timeout` and no stream is open.
  bool IdleSince(absl::Time now, absl::Duration timeout) const ABSL_LOCKS_EXCLUDED(mu_);

  SliceResult RunSlice(absl::Time deadline) override ABSL_LOCKS_EXCLUDED(mu_);

 private:
  // A mesh copied on the learning thread, waiting for the encoder.
  struct Snapshot {
    TriangleMesh mesh;
    v1::UpdateKind kind = v1::UPDATE_KIND_UNSPECIFIED;
    size_t lod_milestone = 0;
    uint32_t lod_index = 0;
    v1::LearningState learning;
    v1::SessionState state = v1::SESSION_STATE_UNSPECIFIED;
    QuantizationBox box;
    uint32_t epoch = 0;
    absl::Time taken;
  };

  absl::StatusOr<size_t> AddPointsAndMaybeWake(const PointCloud& sent, size_t* held_back,
                                               std::optional<uint64_t> first_point, size_t* skipped,
                                               bool wake) ABSL_LOCKS_EXCLUDED(ingest_mu_, mu_);
  // Stores a new state; OK without a record.
  absl::Status StoreState(v1::SessionState state, const std::string& error) const;
  // Stores a published mesh; a failure is recorded in the event log (once per session), as the
  // mesh can be learned again.
  void StoreMesh(const v1::MeshUpdate& update, bool durable);
  // Stores the learner's mesh of a published milestone or refresh as the checkpoint, as the
  // record's checkpoint interval allows (SessionRecord::WriteCheckpoint); a failure is
  // recorded like StoreMesh's.
  void StoreCheckpoint(const Snapshot& snapshot);
  // A learner for the points so far: from start_mesh_ when there is one that the learner
  // takes, else from the initial mesh (learning thread).
  absl::StatusOr<std::unique_ptr<Learner>> CreateLearner();
  bool AcceptsPointsLocked() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // OK, or FAILED_PRECONDITION naming the state in which the session refuses points.
  absl::Status AcceptingPointsLocked() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  size_t AllowedVerticesLocked() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Moves the next milestone past every one of at most `vertices` vertices (never back).
  void SkipMilestonesUpToLocked(size_t vertices) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // The quantization cube once a batch with `batch_bounds` is in, and in `grown` whether the
  // present (or the first) cube had to grow for it; INVALID_ARGUMENT when no cube Draco can
  // use holds the batch.
  absl::StatusOr<QuantizationBox> CubeWithLocked(const BoundingBox& batch_bounds, bool* grown) const
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void RecordArrivalSampleLocked(absl::Span<const Vec3f> positions, size_t first_index)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(ingest_mu_);
  // Updates the learning counters after a Run (learning thread).
  void UpdateLearningState() ABSL_LOCKS_EXCLUDED(mu_);
  // Copies the mesh and hands it to the encoder (learning thread).
  void TakeSnapshot(v1::UpdateKind kind, size_t milestone, uint32_t lod_index)
      ABSL_LOCKS_EXCLUDED(mu_);
  void ScheduleEncodeLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void EncodeNext() ABSL_LOCKS_EXCLUDED(mu_);
  absl::StatusOr<std::shared_ptr<v1::MeshUpdate>> Encode(const Snapshot& snapshot) const;
  void Fail(const absl::Status& status) ABSL_LOCKS_EXCLUDED(mu_);
  // Records `event` in the event log, if there is one.
  void Record(absl::string_view event) const;
  void Wake();

  const std::string id_;
  const std::string name_;
  mutable absl::Mutex owner_mu_;  // Taken alone, or last (after mu_).
  std::string owner_ ABSL_GUARDED_BY(owner_mu_);
  const SessionConfig config_;
  const absl::Time create_time_;
  // The vertices of the start mesh or restored checkpoint (0: none). Set before the session is
  // shared and not changed after: learning and Finish wait for points enough for them.
  size_t start_vertices_ = 0;
  WorkerPool* const pool_;
  Executor* const encoder_;
  const std::shared_ptr<EventLog> log_;  // May be null.

  GrowingPointCloud points_;
  // The coloured points taken (outliers left out), which paint the meshes the encoder
  // publishes. Synchronised internally.
  mutable GrowingPointColors point_colors_;
  UpdateChannel updates_;
  std::atomic<bool> cancel_{false};  // Polled by the learner.

  // Serialises ingestion with Finish, so the final count sees every accepted batch, and keeps
  // the arrival sample in arrival order. Acquired before mu_.
  absl::Mutex ingest_mu_ ABSL_ACQUIRED_BEFORE(mu_);
  std::vector<Vec3f> arrival_sample_ ABSL_GUARDED_BY(ingest_mu_);
  size_t arrival_stride_ ABSL_GUARDED_BY(ingest_mu_) = 1;
  // Set when the configuration asks for outlier removal; knows every point of every batch
  // taken in, outliers included.
  std::unique_ptr<StreamingOutlierFilter> outlier_filter_ ABSL_GUARDED_BY(ingest_mu_);
  // The points the filter holds back, whole.
  HeldOutliers held_outliers_ ABSL_GUARDED_BY(ingest_mu_);

  mutable absl::Mutex mu_;
  v1::SessionState state_ ABSL_GUARDED_BY(mu_) = v1::SESSION_STATE_COLLECTING;
  std::string error_ ABSL_GUARDED_BY(mu_);
  size_t final_vertices_ ABSL_GUARDED_BY(mu_) = 0;  // Set by Finish.
  // Points taken from uploads, outliers included (changed with ingest_mu_ held too).
  uint64_t points_taken_ ABSL_GUARDED_BY(mu_) = 0;
  size_t next_milestone_ ABSL_GUARDED_BY(mu_) = 0;  // Index into config_.lod_milestones.
  bool has_box_ ABSL_GUARDED_BY(mu_) = false;
  QuantizationBox box_ ABSL_GUARDED_BY(mu_);
  uint32_t epoch_ ABSL_GUARDED_BY(mu_) = 0;
  v1::LearningState learning_ ABSL_GUARDED_BY(mu_);
  std::deque<Snapshot> encode_queue_ ABSL_GUARDED_BY(mu_);
  bool encoding_ ABSL_GUARDED_BY(mu_) = false;
  int open_streams_ ABSL_GUARDED_BY(mu_) = 0;
  absl::Time last_activity_ ABSL_GUARDED_BY(mu_);

  // Learning thread only (see the file comment).
  std::unique_ptr<Learner> learner_;
  bool final_pass_decided_ = false;
  bool relearning_ = false;
  // The counters of learning that learner_ does not count: learners discarded for a relearn,
  // and the learning before a restart (the checkpoint's counters).
  LearnerProgress earlier_learning_;
  absl::Duration learning_time_;
  // The start mesh or the restored checkpoint's mesh, until the learner is created, and what
  // the event log calls it.
  std::optional<TriangleMesh> start_mesh_;
  const char* start_mesh_name_ = "the start mesh";
  absl::Time last_publish_time_ = absl::InfinitePast();
  uint64_t last_publish_steps_ = 0;
  std::optional<GrowthWatch> growth_;  // Stall detection for the current learner.
  // While collecting, a stalled learner waits for points past this many instead of failing
  // the session (more points may let the mesh grow); unset while learning goes on.
  std::optional<size_t> stalled_at_points_;

  std::unique_ptr<SessionRecord> record_;  // Null without a state directory.
  ServerMetrics* metrics_ = nullptr;       // May be null.
  std::atomic<bool> mesh_store_failed_{false};
  std::atomic<bool> checkpoint_store_failed_{false};
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SESSION_H_
