// The subcommands that talk to a neuralmesh-server: `reconstruct --server`, `watch` and
// `sessions` (those on one session are in session_commands.h).
#ifndef NEURALMESH_CLIENT_REMOTE_COMMANDS_H_
#define NEURALMESH_CLIENT_REMOTE_COMMANDS_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "client/reconnecting_calls.h"
#include "client/reconstruction_client.h"
#include "core/analysis/color_source.h"
#include "core/analysis/statistical_outliers.h"
#include "core/io/draco_codec.h"
#include "core/io/point_selection.h"
#include "core/learning/learner_options.h"

namespace neuralmesh::client {

// A client of `server` (host:port, --server); INVALID_ARGUMENT when it is empty.
absl::StatusOr<std::unique_ptr<ReconstructionClient>> ConnectTo(const std::string& server,
                                                                const ClientOptions& options);

struct RemoteReconstructOptions {
  // A point cloud file or builtin:NAME; or several point cloud files, uploaded as one.
  std::vector<std::string> inputs;
  std::string server;        // host:port.
  std::string out_dir;       // Where the LOD files go.
  size_t vertices = 0;       // Final vertex count; 0: one vertex per 2 points, at most 10000.
  std::vector<size_t> lods;  // Milestones; empty: the server's 1-2-5 series.
  LearnerOptions learner;
  std::optional<OutlierOptions> outliers;  // Set: remove the points' outliers before upload,
  bool outliers_on_server = false;         // or, when this is set, the session as they arrive.
  PointSelection selection;                // Which points of a LAS file are uploaded.
  // Upload the one file INPUT's records read where they lie, spread over the file from the
  // first batch on (FileRecordsUpload), instead of reading it whole: the upload starts at once
  // and the client's memory holds no points. No client-side outlier removal; no colours.
  bool off_core = false;
  // Set: upload the points' colours, which the session paints its meshes with, blending
  // `neighbours` points (SessionConfig.color_neighbours).
  std::optional<PointColorOptions> colors = PointColorOptions{};
  DracoOptions draco;              // Quantization bits and encode speed of the server's meshes.
  size_t batch_size = 10000;       // Points per uploaded batch.
  size_t builtin_points = 100000;  // Points sampled from a builtin:NAME input.
  std::vector<std::string> also;   // Extensions each mesh saved is also written in (".ply").
  bool progress = false;           // Draw progress bars on `err`.
  ClientOptions connection;        // Connect timeout, TLS, access token.
  // How long the upload, the watch and the finish keep trying after a lost connection
  // (client/reconnecting_calls.h); zero: the first lost connection ends the command.
  absl::Duration reconnect_for = ReconnectOptions().give_up_after;
  // Set: no new session; the upload into this one, which still takes points, goes on from the
  // points it has taken (Session.points_taken). The inputs (in the same order) and their flags
  // must be those of the first run; the session keeps the configuration it was created with.
  std::string resume_session;
  // A mesh file for a new session to learn on from (CreateSessionRequest.start_mesh); empty:
  // learner.initial_mesh.
  std::string start_mesh;
};

// Creates a session (or takes up `resume_session`), watches it while the input streams up in
// batches, finishes it and writes every LOD milestone (<stem>_lod<N>.drc) and the final mesh
// (<stem>.drc; the stem of the first input) into out_dir, printing each update's figures on
// `out`. Returns OK only when the final mesh arrived; otherwise the first error. A lost
// connection is ridden out for `reconnect_for` (notices on `err`): the upload goes on from the
// points the session has taken. When the upload fails the session is cancelled, except when
// the connection stayed lost (UNAVAILABLE): the session keeps its points and the message says
// how to resume. A first SIGINT or SIGTERM cancels the session and returns CANCELLED.
absl::Status RunRemoteReconstruct(const RemoteReconstructOptions& options, std::ostream& out,
                                  std::ostream& err);

struct WatchOptions {
  std::string session_id;
  std::string server;
  std::string out_dir;
  std::vector<std::string> also;  // As above.
  ClientOptions connection;
  absl::Duration reconnect_for = ReconnectOptions().give_up_after;  // As above.
};

// Watches a session until it ends, saving and printing updates as RunRemoteReconstruct does
// (the file stem is the session id), watching again after lost connections for
// `reconnect_for` (notices on `err`). OK only when the final mesh arrived.
absl::Status RunWatch(const WatchOptions& options, std::ostream& out, std::ostream& err);

struct SessionsOptions {
  std::string server;
  bool json = false;  // A JSON array instead of a table.
  ClientOptions connection;
  // How long to ask again while the server is out of reach or still restoring its sessions
  // after a restart (a listing is UNAVAILABLE until it is done); notices go to `err`.
  absl::Duration reconnect_for = ReconnectOptions().give_up_after;
};

// Lists the server's sessions as a table, or as JSON.
absl::Status RunSessions(const SessionsOptions& options, std::ostream& out, std::ostream& err);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_REMOTE_COMMANDS_H_
