// Calls of the neuralmesh.v1 service that ride out a lost connection.
//
// When a call ends with UNAVAILABLE (the network dropped, a keepalive went unanswered, the
// server's listener went away), these wait for the server to answer again
// (ReconstructionClient::AwaitSession), ask the session where to go on, and go on from there:
// - an upload from the points the session has taken (Session.points_taken), so that every
//   point arrives once;
// - a watch after the last update it delivered (latest wins: updates published and superseded
//   meanwhile are skipped, as for any slow watcher; the final mesh is never skipped);
// - a finish, unless the session is finishing or finished already (the answer was lost).
// A server that restarted on its state directory answers UNAVAILABLE for a session it is
// still restoring: these wait for that too.
//
// They give up when `give_up_after` passes without the call getting any further, with the last
// UNAVAILABLE and a message that says so. Any other status ends them at once, as CancelCalls
// does (CANCELLED). NOT_FOUND after a reconnect means the server no longer has the session (a
// restarted server keeps none).
//
//   ReconnectOptions reconnect{absl::Seconds(60), [](const std::string& n) { log(n); }};
//   NM_RETURN_IF_ERROR(UploadPointsReconnecting(client, id, cloud, 10000, {}, 0, reconnect)
//                          .status());
#ifndef NEURALMESH_CLIENT_RECONNECTING_CALLS_H_
#define NEURALMESH_CLIENT_RECONNECTING_CALLS_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "client/reconstruction_client.h"
#include "core/point_cloud.h"

namespace neuralmesh::client {

struct ReconnectOptions {
  // How long to keep trying after a lost connection, counted from the call's last progress (a
  // batch the session took, an update delivered). Zero: fail at the first lost connection.
  absl::Duration give_up_after = absl::Seconds(60);
  // Told, for the user, when the connection is lost and when the call goes on; may be empty.
  std::function<void(const std::string& notice)> notify;
};

// UploadPoints (the same arguments) that goes on after lost connections. Returns the
// acknowledgement of the last UploadPoints call it made: total_points is the session's
// running total.
absl::StatusOr<v1::UploadPointsResponse> UploadPointsReconnecting(
    ReconstructionClient& client, const std::string& session_id, const PointCloud& cloud,
    size_t batch_size, const ReconstructionClient::UploadProgress& progress, size_t first_point,
    const ReconnectOptions& options);
absl::StatusOr<v1::UploadPointsResponse> UploadPointsReconnecting(
    ReconstructionClient& client, const std::string& session_id, PointUpload& upload,
    size_t batch_size, const ReconstructionClient::UploadProgress& progress, uint64_t first_point,
    const ReconnectOptions& options);

// Watch (the same arguments) that watches again after lost connections.
absl::Status WatchReconnecting(ReconstructionClient& client, const std::string& session_id,
                               uint64_t after_sequence,
                               const ReconstructionClient::UpdateCallback& on_update,
                               const ReconnectOptions& options);

// Finish that asks again after lost connections, unless the session turns out to be finishing
// or finished already; returns the session as the server last answered.
absl::StatusOr<v1::Session> FinishReconnecting(ReconstructionClient& client,
                                               const std::string& session_id,
                                               const ReconnectOptions& options);

// GetSession that asks again while the server is out of reach, or answers that it is still
// restoring the session after a restart (UNAVAILABLE as well).
absl::StatusOr<v1::Session> GetSessionReconnecting(ReconstructionClient& client,
                                                  const std::string& session_id,
                                                  const ReconnectOptions& options);

// ListSessions that asks again while the server is out of reach, or answers that it is still
// restoring its sessions after a restart (a listing is never partial: UNAVAILABLE until then).
absl::StatusOr<std::vector<v1::Session>> ListSessionsReconnecting(
    ReconstructionClient& client, const ReconnectOptions& options);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_RECONNECTING_CALLS_H_
