#include "client/session_commands.h"

#include <memory>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "client/lod_table.h"
#include "client/mesh_update_writer.h"
#include "client/remote_commands.h"
#include "client/session_json.h"
#include "core/io/draco_codec.h"
#include "core/io/file_contents.h"
#include "core/io/mesh_io.h"
#include "core/status_macros.h"

namespace neuralmesh::client {
namespace {

// "session ID: finishing, 40000 points, 1532 of 5000 vertices".
std::string SessionLine(const v1::Session& session) {
  return absl::StrCat("session ", session.session_id(), ": ",
                      SessionStateName(session.state()), ", ",
                      session.learning().points_received(), " points, ", session.vertex_count(),
                      " of ", session.config().target_vertices(), " vertices");
}

}  // namespace

absl::Status RunSessionAction(SessionAction action, const SessionActionOptions& options,
                              std::ostream& out) {
  if (options.session_id.empty()) return absl::InvalidArgumentError("SESSION is empty");
  if (action == SessionAction::kTransfer && options.new_owner.empty()) {
    return absl::InvalidArgumentError("--to CLIENT is required: the client to hand the session to");
  }
  NM_ASSIGN_OR_RETURN(std::unique_ptr<ReconstructionClient> client,
                      ConnectTo(options.server, options.connection));
  switch (action) {
    case SessionAction::kFinish: {
      NM_ASSIGN_OR_RETURN(const v1::Session session, client->Finish(options.session_id));
      out << SessionLine(session) << "\n";
      return absl::OkStatus();
    }
    case SessionAction::kCancel: {
      NM_ASSIGN_OR_RETURN(const v1::Session session, client->Cancel(options.session_id));
      out << SessionLine(session) << "\n";
      return absl::OkStatus();
    }
    case SessionAction::kDelete:
      NM_RETURN_IF_ERROR(client->Delete(options.session_id));
      out << "session " << options.session_id << " deleted\n";
      return absl::OkStatus();
    case SessionAction::kTransfer: {
      NM_ASSIGN_OR_RETURN(const v1::Session session,
                          client->Transfer(options.session_id, options.new_owner));
      out << SessionLine(session) << ", owned by client " << session.owner() << "\n";
      return absl::OkStatus();
    }
  }
  return absl::InternalError("unknown session action");
}

absl::Status RunGetMesh(const GetMeshOptions& options, std::ostream& out) {
  if (options.session_id.empty()) return absl::InvalidArgumentError("SESSION is empty");
  if (options.output.empty()) return absl::InvalidArgumentError("-o OUTPUT is required");
  if (!IsSupportedMeshExtension(options.output)) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot write '", options.output, "': use one of ", kMeshExtensions));
  }
  NM_ASSIGN_OR_RETURN(std::unique_ptr<ReconstructionClient> client,
                      ConnectTo(options.server, options.connection));
  const bool wait = options.wait > absl::ZeroDuration();
  NM_ASSIGN_OR_RETURN(
      const v1::MeshUpdate update,
      client->GetMesh(options.session_id,
                      options.final ? v1::MESH_VERSION_FINAL : v1::MESH_VERSION_LATEST, wait,
                      wait ? options.wait : options.connection.call_timeout));
  if (absl::EndsWithIgnoreCase(options.output, ".drc")) {
    NM_RETURN_IF_ERROR(WriteFileContents(options.output, update.draco_mesh()));
  } else {
    absl::StatusOr<TriangleMesh> mesh = DecodeMesh(update.draco_mesh());
    if (!mesh.ok()) {
      return absl::DataLossError(absl::StrCat("mesh ", update.sequence(), " of session ",
                                              options.session_id,
                                              " does not decode: ", mesh.status().message()));
    }
    NM_RETURN_IF_ERROR(WriteMesh(*mesh, options.output, options.writing));
  }
  LodFigures figures = FiguresOf(update);
  figures.path = options.output;
  PrintLodHeader(out);
  PrintLodRow(figures, out);
  return absl::OkStatus();
}

}  // namespace neuralmesh::client
