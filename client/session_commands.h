// The subcommands that act on one session of a neuralmesh-server: `finish`, `cancel`,
// `delete`, `transfer` and `get`.
#ifndef NEURALMESH_CLIENT_SESSION_COMMANDS_H_
#define NEURALMESH_CLIENT_SESSION_COMMANDS_H_

#include <ostream>
#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "client/reconstruction_client.h"
#include "core/io/mesh_io.h"

namespace neuralmesh::client {

enum class SessionAction {
  kFinish,  // FinishSession: every point has arrived; learn to the target, publish the final mesh.
  kCancel,  // CancelSession: stop learning; the latest mesh stays.
  kDelete,  // DeleteSession: the session, its meshes and its files are gone.
  kTransfer,  // TransferSession: another client owns the session.
};

struct SessionActionOptions {
  std::string session_id;
  std::string server;  // host:port.
  std::string new_owner;  // kTransfer: the client that is to own the session.
  ClientOptions connection;
};

// Asks the server for `action` on the session and prints what became of it on `out`
// ("session ID: finishing, 40000 points, 1532 of 5000 vertices"; "session ID deleted";
// "session ID: collecting, ..., owned by client bob").
// INVALID_ARGUMENT for a transfer without a new owner; the server's status otherwise
// (NOT_FOUND for an unknown session, FAILED_PRECONDITION for a session that has ended or, for
// a finish, has too few points, PERMISSION_DENIED, ...).
absl::Status RunSessionAction(SessionAction action, const SessionActionOptions& options,
                              std::ostream& out);

struct GetMeshOptions {
  std::string session_id;
  std::string server;
  // Where the mesh goes, its format by extension: .drc holds the server's Draco bytes as they
  // came; the other formats of kMeshExtensions the decoded mesh, written with `writing`.
  std::string output;
  MeshWriteOptions writing;
  bool final = false;  // The final mesh of a finished session instead of the latest one.
  // Zero (or less): the mesh must exist now (NOT_FOUND otherwise); more: wait up to this long
  // for it (DEADLINE_EXCEEDED after).
  absl::Duration wait = absl::ZeroDuration();
  ClientOptions connection;
};

// Fetches a session's latest (or final) mesh, writes it to `output` and prints its figures on
// `out`.
absl::Status RunGetMesh(const GetMeshOptions& options, std::ostream& out);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_SESSION_COMMANDS_H_
