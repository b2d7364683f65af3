// Which sessions a call may see and change, from the access token it carried
// (access_tokens.h): an admin token every session; a user token the sessions its client
// created, and new ones; a reader token sees every session and changes none. A server without
// tokens lets every call do everything.
#ifndef NEURALMESH_SERVER_SESSION_ACCESS_H_
#define NEURALMESH_SERVER_SESSION_ACCESS_H_

#include <grpcpp/server_context.h>

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/access_tokens.h"
#include "server/session.h"
#include "server/session_manager.h"

namespace neuralmesh::server {

// Who makes a call.
struct Caller {
  // The client name of the call's token; empty for an unnamed token or without tokens.
  std::string client;
  AccessRole role = AccessRole::kAdmin;
};

// The caller of a call, from the properties the token check put into its AuthContext.
Caller CallerOf(const grpc::ServerContextBase& context);

// What a call does with a session.
enum class SessionUse {
  kSee,     // GetSession, ListSessions, WatchSession, GetMesh.
  kChange,  // UploadPoints, Reconstruct, FinishSession, CancelSession, DeleteSession,
            // TransferSession.
};

// OK, or PERMISSION_DENIED saying why not.
absl::Status CheckMayCreate(const Caller& caller);
absl::Status CheckMayUse(const Caller& caller, const Session& session, SessionUse use);

// The session `id`, when `caller` may use it as `use` says: SessionManager::Get's errors, or
// PERMISSION_DENIED.
absl::StatusOr<std::shared_ptr<Session>> GetSessionFor(const SessionManager& manager,
                                                       const Caller& caller, absl::string_view id,
                                                       SessionUse use);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SESSION_ACCESS_H_
