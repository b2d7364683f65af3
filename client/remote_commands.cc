#include "client/remote_commands.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/synchronization/mutex.h"
#include "absl/synchronization/notification.h"
#include "absl/time/clock.h"
#include "client/inputs.h"
#include "client/interrupt.h"
#include "client/lod_plan.h"
#include "client/mesh_update_writer.h"
#include "client/progress_bar.h"
#include "client/proto_conversion.h"
#include "client/reconnecting_calls.h"
#include "client/reconstruction_client.h"
#include "client/session_json.h"
#include "client/upload_input.h"
#include "core/analysis/json_writer.h"
#include "core/status_macros.h"

namespace neuralmesh::client {
namespace {

constexpr size_t kDefaultMaxVertices = 10000;
// How long a cancel that only tidies up (after an interrupt or a failure) waits for the server:
// a server that stopped answering must not hold the command for the usual call timeout.
constexpr absl::Duration kTidyCancelTimeout = absl::Seconds(5);
constexpr double kDefaultPointsPerVertex = 2;  // SessionConfig.points_per_vertex's default.

// The end of a watch as the user should read it.
absl::Status ExplainWatchEnd(const absl::Status& status, const std::string& session_id) {
  if (status.ok()) {
    return absl::DataLossError(
        absl::StrCat("the watch of session ", session_id, " ended before the final mesh"));
  }
  if (absl::IsCancelled(status)) {
    return absl::CancelledError(absl::StrCat("session ", session_id, " was cancelled"));
  }
  if (absl::IsAborted(status)) {
    return absl::AbortedError(
        absl::StrCat("learning failed in session ", session_id, ": ", status.message()));
  }
  if (absl::IsUnavailable(status)) {
    return absl::UnavailableError(absl::StrCat(status.message(), "; once the server is back, ",
                                               "neuralmesh watch ", session_id,
                                               " saves the session's meshes"));
  }
  return status;
}

}  // namespace

absl::StatusOr<std::unique_ptr<ReconstructionClient>> ConnectTo(const std::string& server,
                                                                const ClientOptions& options) {
  if (server.empty()) return absl::InvalidArgumentError("--server HOST:PORT is required");
  return ReconstructionClient::Connect(server, options);
}

absl::Status RunRemoteReconstruct(const RemoteReconstructOptions& options, std::ostream& out,
                                  std::ostream& err) {
  NM_RETURN_IF_ERROR(options.learner.Validate());
  NM_RETURN_IF_ERROR(options.draco.Validate());
  if (options.out_dir.empty()) return absl::InvalidArgumentError("--out-dir DIR is required");
  if (options.batch_size == 0) return absl::InvalidArgumentError("--batch-size must be > 0");
  const bool outliers_on_server = options.outliers.has_value() && options.outliers_on_server;
  NM_ASSIGN_OR_RETURN(UploadInput input, LoadUploadInput(options, outliers_on_server, out));
  std::optional<TriangleMesh> start_mesh;
  if (!options.start_mesh.empty()) {
    if (!options.resume_session.empty()) {
      return absl::InvalidArgumentError(
          "--start_mesh applies to a new session; --resume goes on with the session's own");
    }
    NM_ASSIGN_OR_RETURN(start_mesh, ReadStartMesh(options.start_mesh));
    NM_RETURN_IF_ERROR(MoveStartMesh(input.origin, options.start_mesh, &*start_mesh));
  }
  const size_t affordable =
      input.streamed ? kDefaultMaxVertices
                     : static_cast<size_t>(std::floor(input.size / kDefaultPointsPerVertex));
  size_t target =
      options.vertices > 0 ? options.vertices : std::min(kDefaultMaxVertices, affordable);
  NM_ASSIGN_OR_RETURN(
      const std::vector<size_t> milestones,
      LodTargets(options.lods, target, start_mesh.has_value() ? start_mesh->positions.size() : 0));

  v1::SessionConfig config;
  *config.mutable_learner() = ToProto(options.learner);
  config.set_target_vertices(target);
  if (!options.lods.empty()) {
    for (size_t m : milestones) config.add_lod_milestones(m);
  }
  *config.mutable_draco() = ToProto(options.draco);
  if (input.origin != kNoOrigin) {
    config.mutable_origin()->set_x(input.origin[0]);
    config.mutable_origin()->set_y(input.origin[1]);
    config.mutable_origin()->set_z(input.origin[2]);
  }
  if (options.colors.has_value()) {
    config.mutable_color_neighbours()->set_value(static_cast<uint32_t>(options.colors->neighbours));
  }
  if (outliers_on_server) {
    // The session's cube grows with what it accepts: bounds taken here would hold the strays.
    v1::OutlierRemoval& removal = *config.mutable_outlier_removal();
    removal.mutable_neighbours()->set_value(options.outliers->neighbours);
    removal.mutable_std_ratio()->set_value(options.outliers->std_ratio);
  } else if (input.bounds.has_value()) {
    // Where the points lie is known before the upload: one quantization cube for the whole
    // session (off-core, the cube of the file's probe, which grows if a point lies outside).
    *config.mutable_bounds() = ToProto(*input.bounds);
  }
  NM_ASSIGN_OR_RETURN(*config.mutable_upload_order(), input.points->DescribeOrder());

  NM_ASSIGN_OR_RETURN(std::unique_ptr<ReconstructionClient> client,
                      ConnectTo(options.server, options.connection));
  const std::string stem = InputStem(options.inputs.front());
  // From here on Ctrl-C ends the upload and the watch at once and cancels the session (see
  // `canceller` below), so that the server does not keep learning for nobody.
  InterruptScope interrupt;
  size_t first_point = 0;
  v1::Session session;
  if (options.resume_session.empty()) {
    NM_ASSIGN_OR_RETURN(session,
                        client->CreateSession(config, stem, start_mesh ? &*start_mesh : nullptr));
  } else {
    // Right after a restart the server may still be restoring the session.
    ReconnectOptions reconnect;
    reconnect.give_up_after = options.reconnect_for;
    reconnect.notify = [&err](const std::string& notice) { err << notice << "\n"; };
    NM_ASSIGN_OR_RETURN(session,
                        GetSessionReconnecting(*client, options.resume_session, reconnect));
    if (session.state() != v1::SESSION_STATE_COLLECTING &&
        session.state() != v1::SESSION_STATE_LEARNING) {
      const bool finishing = session.state() == v1::SESSION_STATE_FINISHING ||
                             session.state() == v1::SESSION_STATE_FINISHED;
      return absl::FailedPreconditionError(absl::StrCat(
          "session ", session.session_id(), " is ", SessionStateName(session.state()),
          "; only a session that still takes points can be resumed",
          finishing
              ? absl::StrCat(" (neuralmesh watch ", session.session_id(), " saves its meshes)")
              : ""));
    }
    const v1::Origin& origin = session.config().origin();
    if (Origin{origin.x(), origin.y(), origin.z()} != input.origin) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "session %s holds points relative to (%.15g, %.15g, %.15g), this input is read "
          "relative to (%.15g, %.15g, %.15g): resume with the input of the first run",
          session.session_id(), origin.x(), origin.y(), origin.z(), input.origin[0],
          input.origin[1], input.origin[2]));
    }
    // Another order would send some points twice and others never.
    const v1::UploadOrder& ours = config.upload_order();
    if (const v1::UploadOrder& kept = session.config().upload_order();
        session.config().has_upload_order() &&
        (kept.name() != ours.name() || kept.items() != ours.items())) {
      return absl::InvalidArgumentError(
          absl::StrCat("session ", session.session_id(), " was uploaded in the order '",
                       kept.name(), "' of ", kept.items(), " items, this input goes in the order '",
                       ours.name(), "' of ", ours.items(),
                       ": resume with the input (and its flags, --off_core among them) of the "
                       "first run"));
    }
    // The same order over as many items, yet other points: another file, other LAS classes.
    if (const uint64_t kept = session.config().upload_order().fingerprint();
        kept != 0 && ours.fingerprint() != 0 && kept != ours.fingerprint()) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "session %s was uploaded from other points: the first %d it took differ from this "
          "input's (fingerprints %016x and %016x); resume with the input (and its flags, "
          "--las_classes among them) of the first run",
          session.session_id(), PointUpload::kFingerprintPoints, kept, ours.fingerprint()));
    }
    if (!input.points->SkipTo(session.points_taken()).ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("session ", session.session_id(), " has taken ", session.points_taken(),
                       " points, more than the ", input.points->size().value_or(0),
                       " of this input: resume with the input (and its flags) of the first run"));
    }
    first_point = static_cast<size_t>(session.points_taken());
    target = session.config().target_vertices();
  }
  const std::string& id = session.session_id();
  const double points_per_vertex = session.config().has_points_per_vertex()
                                       ? session.config().points_per_vertex().value()
                                       : kDefaultPointsPerVertex;
  const size_t reachable =
      input.streamed ? target
                     : std::min<size_t>(
                           target, static_cast<size_t>(std::floor(input.size / points_per_vertex)));
  out << "session " << id << " on " << client->address() << ": "
      << (input.streamed    ? std::string("points from standard input")
          : input.estimated ? absl::StrCat("about ", input.size, " points")
                            : absl::StrCat(input.size, " points"))
      << ", target " << target << " vertices";
  if (!options.resume_session.empty()) out << "; resuming at point " << first_point;
  out << "\n";
  if (reachable < target) {
    err << "note: " << (input.estimated ? "about " : "") << input.size << " points allow at most "
        << reachable << " vertices at the server's " << points_per_vertex << " points per vertex\n";
  }

  // The watcher thread prints rows on `out` while this thread draws the upload bar on `err`;
  // both go through `mu` so a row never lands in the middle of a bar.
  absl::Mutex mu;
  ProgressBar upload_bar(err, options.progress, "upload  ",
                         options.off_core ? "records" : "points");
  ProgressBar learn_bar(err, options.progress, "learning", "vertices");
  MeshUpdateWriter writer({options.out_dir, stem, options.also}, out);
  absl::Status write_status;
  absl::Status watch_status;
  ReconnectOptions reconnect;
  reconnect.give_up_after = options.reconnect_for;
  reconnect.notify = [&](const std::string& notice) {
    absl::MutexLock lock(&mu);
    upload_bar.Clear();
    learn_bar.Clear();
    err << notice << "\n";
  };
  std::thread watcher([&] {
    const auto on_update = [&](const v1::MeshUpdate& update) {
      absl::MutexLock lock(&mu);
      upload_bar.Clear();
      learn_bar.Clear();
      write_status = writer.Write(update);
      learn_bar.Update(update.vertex_count(), reachable);
      return write_status.ok();
    };
    watch_status = WatchReconnecting(*client, id, 0, on_update, reconnect);
  });

  absl::Notification done;
  bool interrupted = false;
  absl::Status interrupt_cancel;  // The server's answer to the cancel an interrupt sent.
  const auto on_interrupt = [&] {
    interrupted = true;
    client->CancelCalls();
    interrupt_cancel = client->Cancel(id, kTidyCancelTimeout).status();
  };
  std::thread canceller([&] {
    while (!done.WaitForNotificationWithTimeout(absl::Milliseconds(100))) {
      if (InterruptScope::interrupted()) {
        on_interrupt();
        return;
      }
    }
  });
  const auto stop_canceller = [&] {
    done.Notify();
    canceller.join();
    // An interrupt in the last moments, after the canceller's last look.
    if (!interrupted && InterruptScope::interrupted()) on_interrupt();
  };

  absl::StatusOr<v1::UploadPointsResponse> uploaded = UploadPointsReconnecting(
      *client, id, *input.points, options.batch_size,
      [&](uint64_t sent, uint64_t total) {
        absl::MutexLock lock(&mu);
        upload_bar.Update(sent, total);
      },
      first_point, reconnect);
  {
    absl::MutexLock lock(&mu);
    upload_bar.Finish();
  }
  absl::Status status = uploaded.status();
  if (status.ok()) {
    absl::StatusOr<v1::Session> finished = FinishReconnecting(*client, id, reconnect);
    status = finished.status();
    if (finished.ok() && outliers_on_server) {
      const v1::LearningState& learning = finished->learning();
      absl::MutexLock lock(&mu);
      out << "outliers removed by the server: " << learning.points_removed_as_outliers() << " of "
          << input.points->size().value_or(input.size) << " points ("
          << learning.outliers_accepted_later()
          << " more held back on arrival and accepted later)\n";
    }
  }
  const bool connection_lost = absl::IsUnavailable(status);
  if (connection_lost) {
    // The watch needs no more of its own window to learn that the server is out of reach.
    client->CancelCalls();
  } else if (!status.ok() && !InterruptScope::interrupted()) {
    // Without a finished upload no final mesh can come: stop the server's work and the watch.
    client->Cancel(id, kTidyCancelTimeout).IgnoreError();
  }
  watcher.join();
  stop_canceller();
  learn_bar.Finish();
  if (interrupted) {
    if (!interrupt_cancel.ok()) {
      return absl::CancelledError(
          absl::StrCat("interrupted; session ", id,
                       " may go on: cancelling it failed: ", interrupt_cancel.message()));
    }
    return absl::CancelledError(absl::StrCat("interrupted; session ", id, " cancelled"));
  }
  if (connection_lost) {
    // The session keeps what it has taken; the same command with --resume goes on from there.
    return absl::UnavailableError(absl::StrCat(status.message(), "; session ", id,
                                               " keeps the points it has taken: run this command "
                                               "again with --resume ",
                                               id, " to go on from there"));
  }
  NM_RETURN_IF_ERROR(status);
  if (!write_status.ok()) {
    client->Cancel(id, kTidyCancelTimeout).IgnoreError();
    return write_status;
  }
  if (!writer.final_received()) return ExplainWatchEnd(watch_status, id);

  const LodFigures& last = writer.saved().back();
  out << absl::StrFormat(
      "final mesh: %d vertices, %d faces, genus %d, %d boundaries, %.1f%% valence 6, "
      "%d basic steps, %.2fs learning; files written to %s: %d\n",
      last.vertices, last.faces, last.genus, last.boundaries, last.valence6_percent,
      last.basic_steps, absl::ToDoubleSeconds(last.elapsed), options.out_dir,
      writer.saved().size() * (1 + options.also.size()));
  return absl::OkStatus();
}

absl::Status RunWatch(const WatchOptions& options, std::ostream& out, std::ostream& err) {
  if (options.session_id.empty()) return absl::InvalidArgumentError("missing SESSION id");
  if (options.out_dir.empty()) return absl::InvalidArgumentError("--out-dir DIR is required");
  NM_ASSIGN_OR_RETURN(std::unique_ptr<ReconstructionClient> client,
                      ConnectTo(options.server, options.connection));
  MeshUpdateWriter writer({options.out_dir, options.session_id, options.also}, out);
  absl::Status write_status;
  ReconnectOptions reconnect;
  reconnect.give_up_after = options.reconnect_for;
  reconnect.notify = [&](const std::string& notice) { err << notice << "\n"; };
  const absl::Status watch_status = WatchReconnecting(
      *client, options.session_id, 0,
      [&](const v1::MeshUpdate& update) {
        write_status = writer.Write(update);
        return write_status.ok();
      },
      reconnect);
  NM_RETURN_IF_ERROR(write_status);
  if (!writer.final_received()) return ExplainWatchEnd(watch_status, options.session_id);
  return absl::OkStatus();
}

absl::Status RunSessions(const SessionsOptions& options, std::ostream& out, std::ostream& err) {
  NM_ASSIGN_OR_RETURN(std::unique_ptr<ReconstructionClient> client,
                      ConnectTo(options.server, options.connection));
  ReconnectOptions reconnect;
  reconnect.give_up_after = options.reconnect_for;
  reconnect.notify = [&err](const std::string& notice) { err << notice << "\n"; };
  NM_ASSIGN_OR_RETURN(const std::vector<v1::Session> sessions,
                      ListSessionsReconnecting(*client, reconnect));
  if (options.json) {
    JsonWriter writer(2);
    writer.BeginArray();
    for (const v1::Session& s : sessions) WriteSessionJson(s, writer);
    writer.EndArray();
    NM_ASSIGN_OR_RETURN(const std::string text, writer.Finish());
    out << text << "\n";
    return absl::OkStatus();
  }
  // The owner column only on a server that names its clients (tokens, client certificates).
  const bool owners = std::any_of(sessions.begin(), sessions.end(),
                                  [](const v1::Session& s) { return !s.owner().empty(); });
  const auto owner_cell = [owners](absl::string_view owner) {
    return owners ? absl::StrFormat("%-16s ", owner.empty() ? "-" : owner) : std::string();
  };
  out << absl::StrFormat("%-20s %-16s %s%-10s %10s %9s %9s %9s %8s\n", "session", "name",
                         owner_cell("owner"), "state", "points", "vertices", "faces", "target",
                         "updates");
  bool any_stalled = false;
  for (const v1::Session& s : sessions) {
    const bool stalled = s.learning().stalled();
    any_stalled = any_stalled || stalled;
    out << absl::StrFormat("%-20s %-16s %s%-10s %10d %9d %9d %9d %8d\n", s.session_id(), s.name(),
                           owner_cell(s.owner()),
                           stalled ? std::string("stalled") : SessionStateName(s.state()),
                           s.learning().points_received(), s.vertex_count(), s.face_count(),
                           s.config().target_vertices(), s.latest_sequence());
  }
  out << sessions.size() << (sessions.size() == 1 ? " session\n" : " sessions\n");
  if (any_stalled) {
    out << "stalled: learning, but the mesh stopped growing with the points so far; waiting for "
           "more\n";
  }
  return absl::OkStatus();
}

}  // namespace neuralmesh::client
