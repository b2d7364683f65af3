#include "server/reconstruction_service.h"

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "core/status_macros.h"
#include "server/grpc_status.h"
#include "server/latest_wins_writer.h"
#include "server/off_thread_work.h"
#include "server/proto_conversion.h"
#include "server/session_access.h"
#include "server/session_stream_hold.h"
#include "server/update_channel.h"

namespace neuralmesh::server {
namespace {

// Locks shared by every reactor below, in this order: the registry's (AbortAll) or the update
// channel's (OnUpdate/OnClose) lock, then the reactor's own mutex. A reactor never calls into
// the registry, the channel or a session while it holds its own mutex, and calls
// StartWrite/Finish only with its mutex held, which is safe because gRPC never runs a reaction
// inline from StartWrite or Finish.

absl::Status Unavailable() { return absl::UnavailableError("the server is shutting down"); }

grpc::ServerUnaryReactor* FinishUnary(grpc::CallbackServerContext* context,
                                      const absl::Status& status) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  reactor->Finish(ToGrpcStatus(status));
  return reactor;
}

// Prefixes a batch error with where it happened and what the session keeps, keeping its code.
// `batch_number` counts the call's batches from 1; `call_batches` and `call_points` are what
// the call had added before it.
absl::Status BatchError(const absl::Status& status, uint64_t batch_number, uint64_t call_batches,
                        uint64_t call_points, size_t session_points) {
  return absl::Status(
      status.code(),
      absl::StrCat("batch ", batch_number, " of this call rejected: ", status.message(),
                   "; the session keeps its ", session_points, " points, ", call_points,
                   " of them from the ", call_batches, call_batches == 1 ? " batch" : " batches",
                   " this call sent before"));
}

// Creates the session `request` asks for, on behalf of `caller` (allowed to create).
absl::StatusOr<std::shared_ptr<Session>> CreateFromRequest(SessionManager& manager,
                                                           const v1::CreateSessionRequest& request,
                                                           absl::string_view peer,
                                                           const Caller& caller) {
  NM_ASSIGN_OR_RETURN(SessionConfig config, SessionConfigFromProto(request.config()));
  std::optional<TriangleMesh> start_mesh;
  if (request.has_start_mesh()) {
    NM_ASSIGN_OR_RETURN(start_mesh, StartMeshFromProto(request.start_mesh()));
    // A Draco mesh whose metadata give an origin is moved from it into the session's frame.
    if (start_mesh->origin != kNoOrigin) {
      const absl::Status moved = MoveOrigin(config.origin, &*start_mesh);
      if (!moved.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("start_mesh: ", moved.message()));
      }
    }
  }
  return manager.Create(std::move(config), request.name(), peer, caller.client,
                        std::move(start_mesh));
}

// What one batch added to a session.
struct Ingested {
  size_t accepted = 0;   // Points of the batch accepted (not those the session had already).
  size_t held_back = 0;  // Points of the batch held back as outliers.
  size_t total = 0;      // The session's running total of accepted points.
};

// Resolves and ingests one batch into `session`.
absl::StatusOr<Ingested> Ingest(Session& session, const v1::PointBatch& batch,
                                size_t max_batch_points) {
  absl::StatusOr<PointCloud> cloud = PointBatchFromProto(batch, max_batch_points);
  if (!cloud.ok()) return cloud.status();
  Ingested ingested;
  size_t skipped = 0;
  absl::StatusOr<size_t> running = session.AddPoints(
      *cloud, &ingested.held_back,
      batch.has_first_point() ? std::optional<uint64_t>(batch.first_point().value())
                              : std::nullopt,
      &skipped);
  if (!running.ok()) return running.status();
  ingested.total = *running;
  ingested.accepted = cloud->size() - skipped - ingested.held_back;
  return ingested;
}

// ---------------------------------------------------------------------------------------------
// WatchSession: server-to-client stream, latest wins.
//
// Flow control. gRPC allows one outstanding write per stream, and a watcher may read slower
// than the session publishes. The update channel calls OnUpdate on the publishing thread (the
// encoder); `writer_` (latest_wins_writer.h) writes the update at once if no write is in
// flight, and otherwise keeps it as the one to write next, replacing an older one, so the
// updates in between are skipped and the publisher never waits. OnWriteDone starts the write
// of the waiting update if there is one. Updates carry increasing sequence numbers; nothing
// older than the last one written is ever sent (a reconnecting watcher passes after_sequence).
//
// The end of the stream: the channel's OnClose (OK after the final mesh, CANCELLED, NOT_FOUND
// when deleted, INTERNAL when learning failed; the waiting update still goes out first), Abort
// from the registry at shutdown (UNAVAILABLE, dropping the waiting update), or the client going
// away (OnCancel, or a failed write). The writer finishes the call once no write is in flight,
// so the final mesh is always written before OK. OnDone unsubscribes (after which the channel
// never calls again), unregisters and deletes the reactor.
class WatchReactor final : public grpc::ServerWriteReactor<v1::MeshUpdate>,
                           public UpdateSubscriber,
                           public LiveReactor {
 public:
  WatchReactor(SessionManager* manager, ReactorRegistry* reactors, const Caller& caller,
               const v1::WatchSessionRequest& request)
      : hold_(reactors), writer_(request.after_sequence()) {
    if (!hold_.Register(this)) {
      EndNow(Unavailable());
      return;
    }
    absl::StatusOr<std::shared_ptr<Session>> session =
        GetSessionFor(*manager, caller, request.session_id(), SessionUse::kSee);
    if (!session.ok()) {
      EndNow(session.status());
      return;
    }
    hold_.Attach(*std::move(session));
    // May call OnUpdate/OnClose right away (the latest mesh, a closed session).
    hold_.Subscribe(this, request.after_sequence());
  }

  void OnUpdate(const MeshUpdatePtr& update) override {
    absl::MutexLock lock(&mu_);
    writer_.Offer(update);
    MaybeWriteLocked();
  }

  void OnClose(const absl::Status& status) override {
    absl::MutexLock lock(&mu_);
    writer_.End(status);
    MaybeWriteLocked();
  }

  void Abort(const absl::Status& status) override {
    absl::MutexLock lock(&mu_);
    writer_.Abort(status);
    MaybeWriteLocked();
  }

  void OnWriteDone(bool ok) override {
    absl::MutexLock lock(&mu_);
    writer_.WriteDone();
    // A failed write means the client is gone; nothing more can be written.
    if (!ok) writer_.EndNow(absl::CancelledError("the watcher went away"));
    MaybeWriteLocked();
  }

  void OnCancel() override { EndNow(absl::CancelledError("the watcher cancelled the call")); }

  void OnDone() override {
    hold_.Release();
    delete this;
  }

 private:
  void EndNow(const absl::Status& status) {
    absl::MutexLock lock(&mu_);
    writer_.EndNow(status);
    MaybeWriteLocked();
  }

  void MaybeWriteLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    if (writer_.CanWrite() && writer_.has_update()) {
      StartWrite(&writer_.StartUpdate());
    } else if (std::optional<absl::Status> end = writer_.TakeFinish()) {
      Finish(ToGrpcStatus(*end));
    }
  }

  SessionStreamHold hold_;  // Set up in the constructor, released in OnDone.

  absl::Mutex mu_;
  LatestWinsWriter writer_ ABSL_GUARDED_BY(mu_);
};

// ---------------------------------------------------------------------------------------------
// UploadPoints: client-to-server stream.
//
// Flow control. One read is outstanding at a time: OnReadDone ingests the batch (unpacking,
// validation and the append into the point cloud, all proportional to the batch) and only then
// starts the next read, so a client that sends faster than the session appends is held back by
// gRPC's flow-control window instead of filling server memory. Learning runs on the worker
// pool meanwhile; the append never waits for it. Batches of a session that filters outliers
// are ingested on the filter executor instead (off_thread_work.h), which starts the next read.
//
// The end: the client half-closes (OnReadDone(false)) and gets the counts with OK; a bad batch
// finishes the call at once with its status (the batches before it stay in the session); so
// does the session ending while the call is open (its update channel closes: deleted,
// cancelled, failed or finished by another call), so that a call left open never keeps a
// deleted session alive; Abort at shutdown finishes with UNAVAILABLE. gRPC completes a read
// outstanding at Finish with OnReadDone(false), after which no read is started again. The
// request is released after each batch, so an idle call holds no batch in memory.
class UploadReactor final : public grpc::ServerReadReactor<v1::UploadPointsRequest>,
                            public UpdateSubscriber,
                            public LiveReactor {
 public:
  UploadReactor(SessionManager* manager, ReactorRegistry* reactors, Executor* filter,
                Caller caller, v1::UploadPointsResponse* response)
      : manager_(manager),
        hold_(reactors),
        caller_(std::move(caller)),
        filter_(filter),
        response_(response),
        work_([this] { CleanUpAndDelete(); }) {
    if (!hold_.Register(this)) {
      FinishOnce(Unavailable());
      return;
    }
    StartRead(&request_);
  }

  void OnReadDone(bool ok) override {
    {
      absl::MutexLock lock(&mu_);
      if (finished_) return;
    }
    if (!ok) {
      if (session() == nullptr) {
        FinishOnce(absl::InvalidArgumentError(
            "the upload carried no message; the first one must name a session"));
        return;
      }
      {
        absl::MutexLock lock(&mu_);
        if (finished_) return;
        response_->set_session_id(session()->id());
        response_->set_points_accepted(points_);
        response_->set_points_held_back(held_back_);
        response_->set_batches_accepted(batches_);
        response_->set_total_points(total_);
      }
      FinishOnce(absl::OkStatus());
      return;
    }
    absl::Status status = ResolveSession();
    if (status.ok() && session()->filters_outliers()) {
      if (work_.Run(*filter_, [this] { ContinueAfter(IngestBatchUnlessFinished()); })) return;
      status = Unavailable();
    }
    ContinueAfter(status.ok() ? IngestBatch() : status);
  }

  // Mesh updates are not this call's business.
  void OnUpdate(const MeshUpdatePtr&) override {}

  // The session accepts no more points: the call ends now rather than at its next batch.
  // Deletion and shutdown keep their codes; a session that finished, was cancelled or failed
  // is FAILED_PRECONDITION, as a batch sent to it would be. (the session was attached before
  // the subscription that leads here.)
  void OnClose(const absl::Status& status) override {
    const std::string why = status.ok() ? absl::StrCat("session ", session()->id(), " is finished")
                                        : std::string(status.message());
    const absl::StatusCode code = status.code() == absl::StatusCode::kNotFound ||
                                          status.code() == absl::StatusCode::kUnavailable
                                      ? status.code()
                                      : absl::StatusCode::kFailedPrecondition;
    absl::MutexLock lock(&mu_);
    FinishLocked(absl::Status(
        code, absl::StrCat(why, "; it accepts no more points (this call had added ", points_,
                           " points in ", batches_, batches_ == 1 ? " batch)" : " batches)")));
  }

  void Abort(const absl::Status& status) override {
    absl::MutexLock lock(&mu_);
    FinishLocked(status);
  }

  void OnDone() override {
    if (work_.ReleaseOnDone()) CleanUpAndDelete();
  }

 private:
  // The session the call streams into; null until it is named.
  Session* session() const { return hold_.session().get(); }

  // After OnDone and the last batch ingested off gRPC's threads (OffThreadWork), which may
  // still subscribe to the session's channel after the call has ended.
  void CleanUpAndDelete() {
    hold_.Release();
    delete this;
  }

  // Ends the handling of a read: frees the batch's memory (up to a message's size) and starts
  // the next read, or finishes the call with `status`.
  void ContinueAfter(const absl::Status& status) {
    request_ = v1::UploadPointsRequest();
    if (!status.ok()) {
      FinishOnce(status);
      return;
    }
    absl::MutexLock lock(&mu_);
    if (!finished_) StartRead(&request_);
  }

  // The session the call uploads into: named by its first message, and any later message
  // that names one must name the same.
  absl::Status ResolveSession() {
    uint64_t batches = 0;
    {
      absl::MutexLock lock(&mu_);
      batches = batches_;
    }
    const uint64_t batch_number = batches + 1;
    if (session() == nullptr) {
      if (request_.session_id().empty()) {
        return absl::InvalidArgumentError("the first message must set session_id");
      }
      absl::StatusOr<std::shared_ptr<Session>> session =
          GetSessionFor(*manager_, caller_, request_.session_id(), SessionUse::kChange);
      if (!session.ok()) return session.status();
      hold_.Attach(*std::move(session));
    } else if (!request_.session_id().empty() && request_.session_id() != session()->id()) {
      return absl::InvalidArgumentError(
          absl::StrCat("batch ", batch_number, " of this call names session ",
                       QuotedSessionId(request_.session_id()), " but this call uploads into \"",
                       session()->id(), "\""));
    }
    return absl::OkStatus();
  }

  // Off gRPC's threads (off_thread_work.h) the call may have ended while the batch waited;
  // then it is not ingested, as no response could count it.
  absl::Status IngestBatchUnlessFinished() {
    {
      absl::MutexLock lock(&mu_);
      if (finished_) return absl::OkStatus();
    }
    return IngestBatch();
  }

  // Ingests request_'s batch into the session (resolved).
  absl::Status IngestBatch() {
    uint64_t points = 0, batches = 0;
    {
      absl::MutexLock lock(&mu_);
      points = points_;
      batches = batches_;
    }
    const uint64_t batch_number = batches + 1;
    absl::StatusOr<Ingested> ingested =
        Ingest(*session(), request_.batch(), manager_->limits().max_batch_points);
    if (!ingested.ok()) {
      return BatchError(ingested.status(), batch_number, batches, points,
                        session()->points_received());
    }
    {
      absl::MutexLock lock(&mu_);
      points_ += ingested->accepted;
      held_back_ += ingested->held_back;
      ++batches_;
      total_ = ingested->total;
    }
    if (!hold_.subscribed()) {
      // After the first batch, so that a session that had ended already refuses it in its own
      // words. No update is wanted (the sequence filter passes none), only OnClose, which
      // comes at once if the session ended since.
      hold_.Subscribe(this, std::numeric_limits<uint64_t>::max());
    }
    return absl::OkStatus();
  }

  void FinishOnce(const absl::Status& status) {
    absl::MutexLock lock(&mu_);
    FinishLocked(status);
  }

  void FinishLocked(const absl::Status& status) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    if (finished_) return;
    finished_ = true;
    Finish(ToGrpcStatus(status));
  }

  SessionManager* const manager_;
  // Set up by the constructor and OnReadDone, which gRPC serialises, released after every other
  // reaction.
  SessionStreamHold hold_;
  const Caller caller_;
  Executor* const filter_;
  v1::UploadPointsResponse* const response_;
  OffThreadWork work_;
  // Read-side state: touched only by the constructor and OnReadDone, which gRPC serialises,
  // and by OnDone after every other reaction.
  v1::UploadPointsRequest request_;

  absl::Mutex mu_;
  bool finished_ ABSL_GUARDED_BY(mu_) = false;
  uint64_t points_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t held_back_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t batches_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t total_ ABSL_GUARDED_BY(mu_) = 0;
};

// ---------------------------------------------------------------------------------------------
// Reconstruct: bidirectional stream, points in and meshes out.
//
// Flow control, reads. As in UploadPoints: one outstanding read; the next read starts after the
// batch is ingested (on the filter executor for a session that filters outliers), so gRPC's
// window paces a fast sender.
//
// Flow control, writes. Three kinds of response compete for the one outstanding write: the
// session (once, first), acknowledgements and mesh updates. Acknowledgements carry running
// totals and updates are snapshots, so for both only the newest matters: `writer_`
// (latest_wins_writer.h) keeps one waiting update, the reactor one waiting acknowledgement,
// each replaced by a newer one while a write is in flight (latest wins, as in WatchSession),
// and the reactor alternates between the two kinds when both wait so neither starves, except
// that the final mesh always goes last (an acknowledgement waiting with it goes first). The
// response being written lives in `out_` until OnWriteDone. Memory per call is therefore
// bounded by a few responses however slowly the client reads, and neither ingestion nor
// learning ever waits for the writer.
//
// The end: when the client half-closes, the session is finished (no more points) and the call
// waits for the channel to close after the final mesh, then finishes with OK. A read also
// fails when the client cancels or its connection drops: that ends the call, not the session,
// which keeps its points and can be resumed (ReconstructStart.session_id). A bad batch, a
// failed start, the session being cancelled or deleted, Abort at shutdown or the client going
// away end the call with an error, and then nothing more is written (EndNow); Finish follows as
// soon as no write is in flight. An outstanding read is completed by gRPC with
// OnReadDone(false) after Finish; no read starts after it.
class ReconstructReactor final
    : public grpc::ServerBidiReactor<v1::ReconstructRequest, v1::ReconstructResponse>,
      public UpdateSubscriber,
      public LiveReactor {
 public:
  ReconstructReactor(grpc::CallbackServerContext* context, SessionManager* manager,
                     ReactorRegistry* reactors, Executor* filter)
      : context_(context),
        manager_(manager),
        hold_(reactors),
        filter_(filter),
        work_([this] { CleanUpAndDelete(); }) {
    if (!hold_.Register(this)) {
      End(Unavailable());
      return;
    }
    StartRead(&request_);
  }

  void OnReadDone(bool ok) override {
    {
      absl::MutexLock lock(&mu_);
      if (writer_.has_end()) return;
    }
    if (!ok) {
      if (context_->IsCancelled()) {
        End(absl::CancelledError("the client cancelled the call or went away"));
      } else {
        HalfClosed();
      }
      return;
    }
    if (session() != nullptr && session()->filters_outliers()) {
      if (work_.Run(*filter_, [this] { ContinueAfter(PointsUnlessEnded()); })) return;
      ContinueAfter(Unavailable());
      return;
    }
    ContinueAfter(session() == nullptr ? Start() : Points());
  }

  void OnUpdate(const MeshUpdatePtr& update) override {
    absl::MutexLock lock(&mu_);
    writer_.Offer(update);
    MaybeWriteLocked();
  }

  void OnClose(const absl::Status& status) override { End(status); }

  void Abort(const absl::Status& status) override {
    absl::MutexLock lock(&mu_);
    writer_.Abort(status);
    MaybeWriteLocked();
  }

  void OnWriteDone(bool ok) override {
    absl::MutexLock lock(&mu_);
    writer_.WriteDone();
    out_.Clear();
    if (!ok) writer_.EndNow(absl::CancelledError("the client went away"));
    MaybeWriteLocked();
  }

  void OnCancel() override { End(absl::CancelledError("the client cancelled the call")); }

  void OnDone() override {
    if (work_.ReleaseOnDone()) CleanUpAndDelete();
  }

 private:
  // The session the call streams into; null until it is named.
  Session* session() const { return hold_.session().get(); }

  // After OnDone and the last batch ingested off gRPC's threads (OffThreadWork).
  void CleanUpAndDelete() {
    hold_.Release();
    delete this;
  }

  // Ends the handling of a read: frees the batch's memory (up to a message's size) and starts
  // the next read, or ends the call with `status`.
  void ContinueAfter(const absl::Status& status) {
    request_ = v1::ReconstructRequest();
    if (!status.ok()) {
      End(status);
      return;
    }
    absl::MutexLock lock(&mu_);
    if (!writer_.has_end()) StartRead(&request_);
  }

  // Off gRPC's threads (off_thread_work.h) the call may have ended while the batch waited;
  // then it is not ingested, as no acknowledgement could count it.
  absl::Status PointsUnlessEnded() {
    {
      absl::MutexLock lock(&mu_);
      if (writer_.has_end()) return absl::OkStatus();
    }
    return Points();
  }

  // The first request: create or attach, then subscribe to the session's meshes.
  absl::Status Start() {
    if (request_.kind_case() != v1::ReconstructRequest::kStart) {
      return absl::InvalidArgumentError(
          "the first request must be a ReconstructStart (create or attach a session)");
    }
    const v1::ReconstructStart& start = request_.start();
    const Caller caller = CallerOf(*context_);
    std::shared_ptr<Session> chosen;
    switch (start.target_case()) {
      case v1::ReconstructStart::kCreate: {
        NM_RETURN_IF_ERROR(CheckMayCreate(caller));
        absl::StatusOr<std::shared_ptr<Session>> created =
            CreateFromRequest(*manager_, start.create(), context_->peer(), caller);
        if (!created.ok()) return created.status();
        chosen = *std::move(created);
        break;
      }
      case v1::ReconstructStart::kSessionId: {
        absl::StatusOr<std::shared_ptr<Session>> found =
            GetSessionFor(*manager_, caller, start.session_id(), SessionUse::kChange);
        if (!found.ok()) return found.status();
        chosen = *std::move(found);
        const v1::SessionState state = chosen->state();
        if (state != v1::SESSION_STATE_COLLECTING && state != v1::SESSION_STATE_LEARNING) {
          return absl::FailedPreconditionError(
              absl::StrCat("session ", chosen->id(), " is ", v1::SessionState_Name(state),
                           " and accepts no more points"));
        }
        break;
      }
      case v1::ReconstructStart::TARGET_NOT_SET:
        return absl::InvalidArgumentError(
            "ReconstructStart must set either create or session_id");
    }
    hold_.Attach(std::move(chosen));
    v1::Session proto = session()->ToProto();  // Before mu_: ToProto takes the channel's lock.
    {
      absl::MutexLock lock(&mu_);
      pending_session_ = std::move(proto);
      MaybeWriteLocked();
    }
    hold_.Subscribe(this, 0);
    return absl::OkStatus();
  }

  absl::Status Points() {
    const uint64_t batch_number = batches_ + 1;
    if (request_.kind_case() != v1::ReconstructRequest::kPoints) {
      return absl::InvalidArgumentError(
          absl::StrCat("request ", batch_number + 1, " of this call is not a point batch; only ",
                       "the first request may be a ReconstructStart"));
    }
    absl::StatusOr<Ingested> ingested =
        Ingest(*session(), request_.points(), manager_->limits().max_batch_points);
    if (!ingested.ok()) {
      return BatchError(ingested.status(), batch_number, batches_, points_,
                        session()->points_received());
    }
    points_ += ingested->accepted;
    held_back_ += ingested->held_back;
    ++batches_;
    v1::PointsAck ack;
    ack.set_batches_accepted(batches_);
    ack.set_points_accepted(points_);
    ack.set_points_held_back(held_back_);
    ack.set_total_points(ingested->total);
    absl::MutexLock lock(&mu_);
    pending_ack_ = std::move(ack);
    MaybeWriteLocked();
    return absl::OkStatus();
  }

  // No more points from this client: finish the session and wait for its final mesh.
  void HalfClosed() {
    if (session() == nullptr) {
      End(absl::InvalidArgumentError("the request stream ended before its ReconstructStart"));
      return;
    }
    absl::Status status = session()->Finish();
    if (!status.ok()) {
      // Finished by someone else meanwhile: the final mesh comes all the same.
      const v1::SessionState state = session()->state();
      if (state != v1::SESSION_STATE_FINISHING && state != v1::SESSION_STATE_FINISHED) {
        End(status);
      }
    }
  }

  // Ends the call: after what waits is written for OK (the final mesh), at once otherwise.
  void End(const absl::Status& status) {
    absl::MutexLock lock(&mu_);
    if (status.ok()) {
      writer_.End(status);
    } else {
      writer_.EndNow(status);
    }
    MaybeWriteLocked();
  }

  // The final mesh is the last response: an acknowledgement waiting with it goes first, and one
  // made after it was written (a batch accepted just before another call finished the
  // session) is dropped.
  void MaybeWriteLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    if (writer_.final_written()) pending_ack_.reset();
    if (writer_.CanWrite()) {
      if (pending_session_.has_value()) {
        *out_.mutable_session() = *std::move(pending_session_);
        pending_session_.reset();
        writer_.StartOther();
      } else if (pending_ack_.has_value() && AcknowledgementGoesNext(writer_, last_was_update_)) {
        *out_.mutable_ack() = *std::move(pending_ack_);
        pending_ack_.reset();
        last_was_update_ = false;
        writer_.StartOther();
      } else if (writer_.has_update()) {
        *out_.mutable_update() = writer_.StartUpdate();
        last_was_update_ = true;
      }
      if (out_.kind_case() != v1::ReconstructResponse::KIND_NOT_SET) {
        StartWrite(&out_);
        return;
      }
    }
    if (std::optional<absl::Status> end = writer_.TakeFinish()) Finish(ToGrpcStatus(*end));
  }

  grpc::CallbackServerContext* const context_;
  SessionManager* const manager_;
  // Set up by the constructor and OnReadDone (serialised by gRPC), released after every other
  // reaction.
  SessionStreamHold hold_;
  Executor* const filter_;
  OffThreadWork work_;
  // Read-side state: touched by the constructor and OnReadDone (serialised by gRPC), and by
  // OnDone after every other reaction.
  v1::ReconstructRequest request_;
  uint64_t points_ = 0;
  uint64_t held_back_ = 0;
  uint64_t batches_ = 0;

  absl::Mutex mu_;
  LatestWinsWriter writer_ ABSL_GUARDED_BY(mu_);
  v1::ReconstructResponse out_ ABSL_GUARDED_BY(mu_);
  std::optional<v1::Session> pending_session_ ABSL_GUARDED_BY(mu_);
  std::optional<v1::PointsAck> pending_ack_ ABSL_GUARDED_BY(mu_);
  bool last_was_update_ ABSL_GUARDED_BY(mu_) = false;
};

// ---------------------------------------------------------------------------------------------
// GetMesh with wait: a unary call that finishes when the requested mesh is published.
//
// The reactor subscribes to the session's channel; the first update that matches (any for
// LATEST, the final one for FINAL) is copied into the response and finishes the call. The
// channel closing without it, the client's deadline or cancellation (OnCancel) and Abort at
// shutdown finish it with the matching status. Nothing is written before Finish, so there is
// no flow control beyond that.
class GetMeshReactor final : public grpc::ServerUnaryReactor,
                             public UpdateSubscriber,
                             public LiveReactor {
 public:
  GetMeshReactor(std::shared_ptr<Session> session, ReactorRegistry* reactors,
                 v1::MeshVersion version, v1::MeshUpdate* response)
      : hold_(reactors), version_(version), response_(response) {
    if (!hold_.Register(this)) {
      FinishOnce(Unavailable());
      return;
    }
    hold_.Attach(std::move(session));
    hold_.Subscribe(this, 0);
  }

  void OnUpdate(const MeshUpdatePtr& update) override {
    if (version_ == v1::MESH_VERSION_FINAL && update->kind() != v1::UPDATE_KIND_FINAL) return;
    absl::MutexLock lock(&mu_);
    if (finished_) return;
    *response_ = *update;
    FinishLocked(absl::OkStatus());
  }

  void OnClose(const absl::Status& status) override {
    absl::Status result = status;
    if (status.ok()) {
      result = absl::FailedPreconditionError("the session finished without a mesh");
    } else if (status.code() == absl::StatusCode::kCancelled ||
               status.code() == absl::StatusCode::kInternal) {
      result = absl::FailedPreconditionError(
          absl::StrCat("the requested mesh will not come: ", status.message()));
    }
    FinishOnce(result);
  }

  void Abort(const absl::Status& status) override { FinishOnce(status); }

  void OnCancel() override {
    FinishOnce(absl::CancelledError("the call was cancelled or its deadline passed"));
  }

  void OnDone() override {
    hold_.Release();
    delete this;
  }

 private:
  void FinishOnce(const absl::Status& status) {
    absl::MutexLock lock(&mu_);
    FinishLocked(status);
  }
  void FinishLocked(const absl::Status& status) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    if (finished_) return;
    finished_ = true;
    Finish(ToGrpcStatus(status));
  }

  SessionStreamHold hold_;  // Set up in the constructor, released in OnDone.
  const v1::MeshVersion version_;
  v1::MeshUpdate* const response_;

  absl::Mutex mu_;
  bool finished_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace

ReconstructionService::ReconstructionService(SessionManager* manager, ReactorRegistry* reactors,
                                             Executor* filter)
    : manager_(manager), reactors_(reactors), filter_(filter) {}

grpc::ServerUnaryReactor* ReconstructionService::CreateSession(
    grpc::CallbackServerContext* context, const v1::CreateSessionRequest* request,
    v1::Session* response) {
  const Caller caller = CallerOf(*context);
  if (absl::Status allowed = CheckMayCreate(caller); !allowed.ok()) {
    return FinishUnary(context, allowed);
  }
  absl::StatusOr<std::shared_ptr<Session>> session =
      CreateFromRequest(*manager_, *request, context->peer(), caller);
  if (!session.ok()) return FinishUnary(context, session.status());
  *response = (*session)->ToProto();
  return FinishUnary(context, absl::OkStatus());
}

grpc::ServerReadReactor<v1::UploadPointsRequest>* ReconstructionService::UploadPoints(
    grpc::CallbackServerContext* context, v1::UploadPointsResponse* response) {
  return new UploadReactor(manager_, reactors_, filter_, CallerOf(*context), response);
}

grpc::ServerWriteReactor<v1::MeshUpdate>* ReconstructionService::WatchSession(
    grpc::CallbackServerContext* context, const v1::WatchSessionRequest* request) {
  return new WatchReactor(manager_, reactors_, CallerOf(*context), *request);
}

grpc::ServerBidiReactor<v1::ReconstructRequest, v1::ReconstructResponse>*
ReconstructionService::Reconstruct(grpc::CallbackServerContext* context) {
  return new ReconstructReactor(context, manager_, reactors_, filter_);
}

grpc::ServerUnaryReactor* ReconstructionService::GetSession(
    grpc::CallbackServerContext* context, const v1::GetSessionRequest* request,
    v1::Session* response) {
  absl::StatusOr<std::shared_ptr<Session>> session =
      GetSessionFor(*manager_, CallerOf(*context), request->session_id(), SessionUse::kSee);
  if (!session.ok()) return FinishUnary(context, session.status());
  *response = (*session)->ToProto();
  return FinishUnary(context, absl::OkStatus());
}

grpc::ServerUnaryReactor* ReconstructionService::ListSessions(
    grpc::CallbackServerContext* context, const v1::ListSessionsRequest* request,
    v1::ListSessionsResponse* response) {
  absl::StatusOr<std::vector<std::shared_ptr<Session>>> sessions = manager_->List();
  if (!sessions.ok()) return FinishUnary(context, sessions.status());
  const Caller caller = CallerOf(*context);
  for (const std::shared_ptr<Session>& session : *sessions) {
    if (!CheckMayUse(caller, *session, SessionUse::kSee).ok()) continue;
    *response->add_sessions() = session->ToProto();
  }
  return FinishUnary(context, absl::OkStatus());
}

grpc::ServerUnaryReactor* ReconstructionService::FinishSession(
    grpc::CallbackServerContext* context, const v1::FinishSessionRequest* request,
    v1::Session* response) {
  absl::StatusOr<std::shared_ptr<Session>> session =
      GetSessionFor(*manager_, CallerOf(*context), request->session_id(), SessionUse::kChange);
  if (!session.ok()) return FinishUnary(context, session.status());
  if (absl::Status status = (*session)->Finish(); !status.ok()) {
    return FinishUnary(context, status);
  }
  *response = (*session)->ToProto();
  return FinishUnary(context, absl::OkStatus());
}

grpc::ServerUnaryReactor* ReconstructionService::CancelSession(
    grpc::CallbackServerContext* context, const v1::CancelSessionRequest* request,
    v1::Session* response) {
  absl::StatusOr<std::shared_ptr<Session>> session =
      GetSessionFor(*manager_, CallerOf(*context), request->session_id(), SessionUse::kChange);
  if (!session.ok()) return FinishUnary(context, session.status());
  if (absl::Status status = (*session)->Cancel("cancelled by a CancelSession call");
      !status.ok()) {
    return FinishUnary(context, status);
  }
  *response = (*session)->ToProto();
  return FinishUnary(context, absl::OkStatus());
}

grpc::ServerUnaryReactor* ReconstructionService::DeleteSession(
    grpc::CallbackServerContext* context, const v1::DeleteSessionRequest* request,
    v1::DeleteSessionResponse* response) {
  absl::StatusOr<std::shared_ptr<Session>> session =
      GetSessionFor(*manager_, CallerOf(*context), request->session_id(), SessionUse::kChange);
  if (!session.ok()) return FinishUnary(context, session.status());
  return FinishUnary(context, manager_->Delete(request->session_id()));
}

grpc::ServerUnaryReactor* ReconstructionService::TransferSession(
    grpc::CallbackServerContext* context, const v1::TransferSessionRequest* request,
    v1::Session* response) {
  const Caller caller = CallerOf(*context);
  const std::string by = caller.client.empty()
                             ? context->peer()
                             : absl::StrCat("client ", caller.client, " at ", context->peer());
  // The caller's right to the session is checked as the owner changes, not before.
  const absl::StatusOr<std::shared_ptr<Session>> session =
      manager_->Transfer(request->session_id(), request->new_owner(), by,
                         [&caller](const Session& current) {
                           return CheckMayUse(caller, current, SessionUse::kChange);
                         });
  if (!session.ok()) return FinishUnary(context, session.status());
  *response = (*session)->ToProto();
  return FinishUnary(context, absl::OkStatus());
}

grpc::ServerUnaryReactor* ReconstructionService::GetMesh(grpc::CallbackServerContext* context,
                                                         const v1::GetMeshRequest* request,
                                                         v1::MeshUpdate* response) {
  absl::StatusOr<std::shared_ptr<Session>> session =
      GetSessionFor(*manager_, CallerOf(*context), request->session_id(), SessionUse::kSee);
  if (!session.ok()) return FinishUnary(context, session.status());
  const bool final = request->version() == v1::MESH_VERSION_FINAL;
  if (request->version() != v1::MESH_VERSION_LATEST && !final) {
    return FinishUnary(context, absl::InvalidArgumentError(absl::StrCat(
                                    "version has the unknown value ", request->version())));
  }
  MeshUpdatePtr latest = (*session)->updates().latest();
  if (latest != nullptr && (!final || latest->kind() == v1::UPDATE_KIND_FINAL)) {
    *response = *latest;
    return FinishUnary(context, absl::OkStatus());
  }
  if (request->wait()) {
    return new GetMeshReactor(*std::move(session), reactors_, request->version(), response);
  }
  const v1::SessionState state = (*session)->state();
  return FinishUnary(context,
                     absl::FailedPreconditionError(absl::StrCat(
                         "session ", request->session_id(), " is ", v1::SessionState_Name(state),
                         final ? " and has no final mesh" : " and has published no mesh yet",
                         state == v1::SESSION_STATE_COLLECTING ||
                                 state == v1::SESSION_STATE_LEARNING ||
                                 state == v1::SESSION_STATE_FINISHING
                             ? "; set wait to wait for it"
                             : "")));
}

}  // namespace neuralmesh::server
