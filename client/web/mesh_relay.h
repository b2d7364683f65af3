// Follows one session's published meshes for the live viewer: one WatchSession stream on a
// thread of its own keeps the latest mesh (latest wins, as for any watcher), and any number of
// HTTP long polls wait on it for a mesh newer than the one they have. A browser that polls
// slowly skips meshes but always gets the newest one, and the final one last.
#ifndef NEURALMESH_CLIENT_WEB_MESH_RELAY_H_
#define NEURALMESH_CLIENT_WEB_MESH_RELAY_H_

#include <grpcpp/channel.h>

#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "client/reconstruction_client.h"

namespace neuralmesh::client::web {

class MeshRelay {
 public:
  // Starts watching `session_id` over `channel`.
  MeshRelay(std::shared_ptr<grpc::Channel> channel, const ClientOptions& options,
            std::string session_id);
  // Stop().
  ~MeshRelay();
  MeshRelay(const MeshRelay&) = delete;
  MeshRelay& operator=(const MeshRelay&) = delete;

  struct State {
    std::shared_ptr<const v1::MeshUpdate> latest;  // Null before the first mesh.
    bool ended = false;  // The watch is over: no newer mesh will come through this relay.
    // How it ended: OK after the final mesh; otherwise the stream's status (NOT_FOUND,
    // CANCELLED for a cancelled session, ABORTED, UNAVAILABLE), or CANCELLED for Stop().
    absl::Status end_status;
  };

  // Waits up to `timeout` until the latest mesh's sequence is above `after_sequence` or the
  // watch has ended, and returns the state then (which may hold neither, on a timeout).
  State WaitForNewer(uint64_t after_sequence, absl::Duration timeout);

  // The state now, without waiting.
  State Peek() const;

  // When a poll last asked (for dropping relays nobody looks at).
  absl::Time last_used() const;

  // Ends the watch and wakes every waiting poll. Idempotent.
  void Stop();

 private:
  void Run();

  const std::string session_id_;
  ReconstructionClient client_;  // Of its own, so that Stop() cancels this watch only.
  std::thread thread_;

  mutable absl::Mutex mu_;
  State state_ ABSL_GUARDED_BY(mu_);
  bool stopped_ ABSL_GUARDED_BY(mu_) = false;
  absl::Time last_used_ ABSL_GUARDED_BY(mu_);
};

}  // namespace neuralmesh::client::web

#endif  // NEURALMESH_CLIENT_WEB_MESH_RELAY_H_
