// The write side of a latest-wins server stream (WatchSession, Reconstruct): which mesh update
// a streaming reactor writes next, and when it finishes the call.
//
// gRPC allows one outstanding write per stream, and a client may read slower than its session
// publishes. Mesh updates are snapshots, so only the newest matters: instead of a queue the
// writer keeps at most one update waiting, and a newer one replaces it (the ones in between
// are skipped). When the write in flight completes, the waiting update, the newest, goes next.
// A stream therefore holds at most two updates (one in flight, one waiting) however slowly its
// client reads, and the publisher never waits for it. Updates go out in increasing sequence
// order and never twice.
//
// The end of the stream is remembered and carried out once no write is in flight: End lets
// what waits go out first (the final mesh before OK); EndNow drops it and writes nothing more
// (an error, the client gone); Abort does the same and its status replaces an earlier end
// (server shutdown).
//
// The class holds no lock and calls nothing. A reactor calls it with its own mutex held and
// then performs what it decided (StartWrite, Finish) under that mutex, so the rules above are
// tested without gRPC. The usual step, after every event:
//
//   if (writer.CanWrite() && writer.has_update()) {
//     StartWrite(&writer.StartUpdate());
//   } else if (std::optional<absl::Status> end = writer.TakeFinish()) {
//     Finish(ToGrpcStatus(*end));
//   }
//
// A reactor with messages of its own (Reconstruct's session and acknowledgements) writes them
// through the same gate: it checks CanWrite, calls StartOther, and calls TakeFinish only after
// it found nothing of its own to write.
#ifndef NEURALMESH_SERVER_LATEST_WINS_WRITER_H_
#define NEURALMESH_SERVER_LATEST_WINS_WRITER_H_

#include <cstdint>
#include <optional>

#include "absl/status/status.h"
#include "server/update_channel.h"

namespace neuralmesh::server {

class LatestWinsWriter {
 public:
  // Updates with a sequence number up to `after_sequence` are never written (a watcher that
  // resumes passes the last one it saw).
  explicit LatestWinsWriter(uint64_t after_sequence = 0);

  // Keeps `update` as the one to write next, replacing an older one that waits. Ignored when
  // it is not newer than every update offered before, or once writing has stopped.
  void Offer(MeshUpdatePtr update);

  // The stream ends with `status` after the write in flight and the waiting update. Ignored
  // when an end is already set (the first one wins).
  void End(const absl::Status& status);
  // The stream ends with `status` (unless an end is already set) after the write in flight
  // only: the waiting update is dropped and nothing more is written.
  void EndNow(const absl::Status& status);
  // Like EndNow, but `status` replaces an end set before.
  void Abort(const absl::Status& status);

  // Whether an end is set (the call is ending or has finished).
  bool has_end() const { return end_.has_value(); }
  // Whether a write may start now: none is in flight, writing has not stopped and the call
  // has not finished.
  bool CanWrite() const { return !writing_ && !stopped_ && !finished_; }
  // Whether an update waits to be written.
  bool has_update() const { return pending_ != nullptr; }
  // Whether the update that waits is the session's final mesh.
  bool has_final_update() const {
    return pending_ != nullptr && pending_->kind() == v1::UPDATE_KIND_FINAL;
  }
  // Whether the final mesh has been handed to a write: nothing may follow it.
  bool final_written() const { return final_written_; }

  // Starts the write of the waiting update and returns it; it stays alive until WriteDone.
  // Requires CanWrite() and has_update().
  const v1::MeshUpdate& StartUpdate();
  // Starts the write of a message of the caller's own. Requires CanWrite().
  void StartOther();
  // The write in flight has completed (successfully or not: a failed write is the caller's to
  // turn into EndNow).
  void WriteDone();

  // Returns the status to finish the call with, exactly once: when an end is set, no write is
  // in flight and either nothing waits or writing has stopped. Call it after trying to start a
  // write, so that the caller's own waiting messages have gone first.
  std::optional<absl::Status> TakeFinish();

 private:
  MeshUpdatePtr in_flight_;  // Kept alive while gRPC writes it.
  MeshUpdatePtr pending_;
  uint64_t last_sequence_;  // Of the newest update offered and kept (or after_sequence).
  std::optional<absl::Status> end_;
  bool writing_ = false;
  bool stopped_ = false;
  bool finished_ = false;
  bool final_written_ = false;
};

// Reconstruct's rule for its acknowledgements (running point totals, latest wins like the
// updates) when one and an update both wait: they alternate, so that neither starves, except
// that the final mesh goes last, so an acknowledgement waiting with it goes first. Whether the
// waiting acknowledgement goes next, given that the last write was an update or not. (One made
// after the final mesh went out is dropped: see final_written.)
bool AcknowledgementGoesNext(const LatestWinsWriter& writer, bool last_write_was_update);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_LATEST_WINS_WRITER_H_
