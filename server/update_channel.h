// The mesh updates of one session, fanned out to any number of watchers, latest wins.
//
// The channel keeps only the newest update. Publishing never blocks and never queues: every
// subscriber is told about the new update and decides itself whether to send it now (its
// previous write is done) or to remember it as the one to send next, replacing an older one it
// had not sent yet. A slow watcher therefore skips to the newest update; it holds at most one
// update that it has not started writing, and the learner never waits for it.
//
// Subscribers are called with the channel's lock held, so that Unsubscribe() returning
// guarantees no call is running or will follow (the reactor may then delete itself). They must
// be quick and must not call back into the channel.
#ifndef NEURALMESH_SERVER_UPDATE_CHANNEL_H_
#define NEURALMESH_SERVER_UPDATE_CHANNEL_H_

#include <cstdint>
#include <memory>
#include <optional>

#include "absl/base/thread_annotations.h"
#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "neuralmesh/v1/reconstruction.pb.h"

namespace neuralmesh::server {

using MeshUpdatePtr = std::shared_ptr<const v1::MeshUpdate>;

class UpdateSubscriber {
 public:
  virtual ~UpdateSubscriber() = default;
  // A newer update than any this subscriber has seen.
  virtual void OnUpdate(const MeshUpdatePtr& update) = 0;
  // No update will follow: OK after the final mesh, otherwise why the session ended. Called at
  // most once, after the last OnUpdate.
  virtual void OnClose(const absl::Status& status) = 0;
};

class UpdateChannel {
 public:
  UpdateChannel() = default;
  UpdateChannel(const UpdateChannel&) = delete;
  UpdateChannel& operator=(const UpdateChannel&) = delete;

  // Assigns the next sequence number to `update`, makes it the latest and tells every
  // subscriber. Returns the sequence number, or 0 (and drops the update) after Close.
  uint64_t Publish(std::shared_ptr<v1::MeshUpdate> update) ABSL_LOCKS_EXCLUDED(mu_);

  // Makes `update`, as published before a restart of the server (session_store.h), the latest,
  // and continues its sequence numbers, so that a watcher that resumes after it
  // (after_sequence) is not sent it again. Only before the first Publish and Subscribe.
  void Restore(MeshUpdatePtr update) ABSL_LOCKS_EXCLUDED(mu_);

  // Ends the channel with `status`; later calls are ignored.
  void Close(const absl::Status& status) ABSL_LOCKS_EXCLUDED(mu_);

  // Registers `subscriber` and, before returning, calls OnUpdate with the latest update if its
  // sequence exceeds `after_sequence`, then OnClose if the channel is closed. Returns a handle
  // for Unsubscribe.
  uint64_t Subscribe(UpdateSubscriber* subscriber, uint64_t after_sequence)
      ABSL_LOCKS_EXCLUDED(mu_);
  // After this returns, `subscriber` is never called again. Unknown handles are ignored.
  void Unsubscribe(uint64_t handle) ABSL_LOCKS_EXCLUDED(mu_);

  MeshUpdatePtr latest() const ABSL_LOCKS_EXCLUDED(mu_);
  // The sequence number the next Publish assigns.
  uint64_t next_sequence() const ABSL_LOCKS_EXCLUDED(mu_);
  std::optional<absl::Status> close_status() const ABSL_LOCKS_EXCLUDED(mu_);
  size_t subscribers() const ABSL_LOCKS_EXCLUDED(mu_);

 private:
  mutable absl::Mutex mu_;
  MeshUpdatePtr latest_ ABSL_GUARDED_BY(mu_);
  uint64_t sequence_ ABSL_GUARDED_BY(mu_) = 0;
  std::optional<absl::Status> closed_ ABSL_GUARDED_BY(mu_);
  uint64_t next_handle_ ABSL_GUARDED_BY(mu_) = 1;
  absl::flat_hash_map<uint64_t, UpdateSubscriber*> subscribers_ ABSL_GUARDED_BY(mu_);
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_UPDATE_CHANNEL_H_
