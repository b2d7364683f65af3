// Bearer-token access control for neuralmesh-server: every call must carry the metadata
// "authorization: Bearer TOKEN" with one of the server's tokens, or it ends with
// UNAUTHENTICATED before any handler sees it. The standard health service
// (/grpc.health.v1.Health/) stays open, so that load balancers and orchestrators can probe a
// server they hold no token for.
//
// Tokens travel in every call's headers, so they are only accepted on TLS connections: gRPC
// runs an AuthMetadataProcessor only for secure server credentials (server_credentials.h
// refuses tokens without TLS), and its clients send call credentials only over TLS.
//
// A token may name the client that holds it and its role (AccessRole): the checker puts both
// into the call's AuthContext (kClientProperty, kRoleProperty), where session_access.h reads
// them to decide which sessions the call may see and change.
#ifndef NEURALMESH_SERVER_ACCESS_TOKENS_H_
#define NEURALMESH_SERVER_ACCESS_TOKENS_H_

#include <grpcpp/security/auth_metadata_processor.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"

namespace neuralmesh::server {

// A token is at least this long (guessing one must be hopeless) and printable ASCII without
// spaces (it is an HTTP/2 header value).
inline constexpr size_t kMinAccessTokenLength = 16;

// A client name is 1 to 64 of these: letters, digits and "._@-".
inline constexpr size_t kMaxClientNameLength = 64;

// What a token lets its holder do.
enum class AccessRole {
  kAdmin,   // "admin": every call on every session (what a token without a client name is).
  kUser,    // "user": creates sessions, and sees and uses only those its client created.
  kReader,  // "reader": lists, gets and watches every session and fetches its meshes; it
            // creates, uploads, finishes, cancels and deletes nothing.
};

// "admin", "user", "reader".
absl::string_view AccessRoleName(AccessRole role);
// The role of that name; INVALID_ARGUMENT for another name.
absl::StatusOr<AccessRole> ParseAccessRole(absl::string_view name);

// The AuthContext properties of a call whose token was accepted: the token's client name
// (empty for an unnamed token) and AccessRoleName of its role.
inline constexpr char kClientProperty[] = "neuralmesh.client";
inline constexpr char kRoleProperty[] = "neuralmesh.role";

// One token of the server's list.
struct AccessToken {
  // Implicit from a bare token: an unnamed admin token, as a line with the token alone.
  AccessToken(std::string token = "", std::string client = "", AccessRole role = AccessRole::kAdmin)
      : token(std::move(token)), client(std::move(client)), role(role) {}
  AccessToken(const char* token) : AccessToken(std::string(token)) {}

  std::string token;
  // Who holds the token: sessions belong to the client that created them, and the server's
  // event lines name it. Only an admin token may have none.
  std::string client;
  AccessRole role;
};

// Checks one token. INVALID_ARGUMENT saying what is wrong, without echoing the token.
absl::Status ValidateAccessToken(absl::string_view token);
// Checks a token's client name and that it has one unless it is an admin token.
absl::Status ValidateClient(const AccessToken& token);

// Parses a tokens file: one token per line as "TOKEN [CLIENT [ROLE]]", separated by spaces or
// tabs; a named token without a role is a "user" one, a token alone an unnamed "admin" one.
// Blank lines and lines starting with '#' are skipped, as is the rest of a line from a field
// that starts with '#'. INVALID_ARGUMENT naming the line for a
// bad token, client name or role, or a file without any token.
absl::StatusOr<std::vector<AccessToken>> ParseAccessTokens(absl::string_view text);

// The processor that gRPC runs for every call on a TLS port (not blocking: the check is a few
// comparisons). The accepted token is consumed, so handlers never see it. Thread-safe.
class AccessTokenChecker : public grpc::AuthMetadataProcessor {
 public:
  // A checker accepting `tokens`. INVALID_ARGUMENT for an empty list or an invalid token.
  static absl::StatusOr<std::shared_ptr<AccessTokenChecker>> Create(
      std::vector<AccessToken> tokens);

  // Replaces the tokens for the calls that start from now on (calls already running go on).
  // INVALID_ARGUMENT, and the old tokens kept, for an empty list, an invalid token or client
  // name.
  absl::Status ReplaceTokens(std::vector<AccessToken> tokens) ABSL_LOCKS_EXCLUDED(mu_);

  bool IsBlocking() const override { return false; }
  grpc::Status Process(const InputMetadata& auth_metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed_auth_metadata,
                       OutputMetadata* response_metadata) override;

 private:
  // Compares against every token in time independent of where the bytes differ.
  AccessTokenChecker() = default;

  // The accepted token's client and role, or nothing.
  std::optional<AccessToken> Find(absl::string_view token) const ABSL_LOCKS_EXCLUDED(mu_);

  mutable absl::Mutex mu_;
  std::vector<AccessToken> tokens_ ABSL_GUARDED_BY(mu_);
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_ACCESS_TOKENS_H_
