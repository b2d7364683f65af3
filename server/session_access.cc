#include "server/session_access.h"

#include <utility>

#include "absl/strings/str_cat.h"

namespace neuralmesh::server {
namespace {

std::string Only(const grpc::AuthContext& context, const char* property) {
  const std::vector<grpc::string_ref> values = context.FindPropertyValues(property);
  return values.empty() ? "" : std::string(values.front().data(), values.front().size());
}

// Only admins may be unnamed (access_tokens.h), so a refused caller has a name.
std::string Named(const Caller& caller) { return absl::StrCat("client ", caller.client); }

}  // namespace

Caller CallerOf(const grpc::ServerContextBase& context) {
  Caller caller;
  const std::shared_ptr<const grpc::AuthContext> auth = context.auth_context();
  if (auth == nullptr) return caller;
  const std::string role = Only(*auth, kRoleProperty);
  caller.client = Only(*auth, kClientProperty);
  if (role == AccessRoleName(AccessRole::kUser)) caller.role = AccessRole::kUser;
  if (role == AccessRoleName(AccessRole::kReader)) caller.role = AccessRole::kReader;
  return caller;
}

absl::Status CheckMayCreate(const Caller& caller) {
  if (caller.role != AccessRole::kReader) return absl::OkStatus();
  return absl::PermissionDeniedError(
      absl::StrCat(Named(caller),
                   " is a reader: it may list, get and watch sessions but not create one"));
}

absl::Status CheckMayUse(const Caller& caller, const Session& session, SessionUse use) {
  switch (caller.role) {
    case AccessRole::kAdmin:
      return absl::OkStatus();
    case AccessRole::kReader:
      if (use == SessionUse::kSee) return absl::OkStatus();
      return absl::PermissionDeniedError(
          absl::StrCat(Named(caller), " is a reader: it may not upload into, finish, hand over, "
                       "cancel or delete session ", session.id()));
    case AccessRole::kUser:
      if (session.owner() == caller.client) return absl::OkStatus();
      return absl::PermissionDeniedError(
          absl::StrCat("session ", session.id(), " belongs to another client; ", Named(caller),
                       " may use only the sessions it created"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<Session>> GetSessionFor(const SessionManager& manager,
                                                       const Caller& caller, absl::string_view id,
                                                       SessionUse use) {
  absl::StatusOr<std::shared_ptr<Session>> session = manager.Get(id);
  if (!session.ok()) return session.status();
  if (absl::Status allowed = CheckMayUse(caller, **session, use); !allowed.ok()) return allowed;
  return session;
}

}  // namespace neuralmesh::server
