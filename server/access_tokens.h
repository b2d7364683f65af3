// Bearer-token access control for neuralmesh-server: every call must carry the metadata
// "authorization: Bearer TOKEN" with one of the server's tokens, or it ends with
// UNAUTHENTICATED before any handler sees it. The standard health service
// (/grpc.health.v1.Health/) stays open, so that load balancers and orchestrators can probe a
// server they hold no token for.
//
// Tokens travel in every call's headers, so they are only accepted on TLS connections: gRPC
// runs an AuthMetadataProcessor only for secure server credentials (server_credentials.h
// refuses tokens without TLS), and its clients send call credentials only over TLS.
#ifndef NEURALMESH_SERVER_ACCESS_TOKENS_H_
#define NEURALMESH_SERVER_ACCESS_TOKENS_H_

#include <grpcpp/security/auth_metadata_processor.h>

#include <memory>
#include <string>
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

// Checks one token. INVALID_ARGUMENT saying what is wrong, without echoing the token.
absl::Status ValidateAccessToken(absl::string_view token);

// Parses a tokens file: one token per line; blank lines and lines starting with '#' are
// skipped, spaces around a token ignored. INVALID_ARGUMENT naming the line for a bad token or
// a file without any.
absl::StatusOr<std::vector<std::string>> ParseAccessTokens(absl::string_view text);

// The processor that gRPC runs for every call on a TLS port (not blocking: the check is a few
// comparisons). The accepted token is consumed, so handlers never see it. Thread-safe.
class AccessTokenChecker : public grpc::AuthMetadataProcessor {
 public:
  // A checker accepting `tokens`. INVALID_ARGUMENT for an empty list or an invalid token.
  static absl::StatusOr<std::shared_ptr<AccessTokenChecker>> Create(
      std::vector<std::string> tokens);

  // Replaces the tokens for the calls that start from now on (calls already running go on).
  // INVALID_ARGUMENT, and the old tokens kept, for an empty list or an invalid token.
  absl::Status ReplaceTokens(std::vector<std::string> tokens) ABSL_LOCKS_EXCLUDED(mu_);

  bool IsBlocking() const override { return false; }
  grpc::Status Process(const InputMetadata& auth_metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed_auth_metadata,
                       OutputMetadata* response_metadata) override;

 private:
  // Compares against every token in time independent of where the bytes differ.
  AccessTokenChecker() = default;

  bool Accepts(absl::string_view token) const ABSL_LOCKS_EXCLUDED(mu_);

  mutable absl::Mutex mu_;
  std::vector<std::string> tokens_ ABSL_GUARDED_BY(mu_);
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_ACCESS_TOKENS_H_
