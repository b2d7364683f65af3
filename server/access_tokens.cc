#include "server/access_tokens.h"

#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace neuralmesh::server {
namespace {

constexpr absl::string_view kAuthorization = "authorization";
constexpr absl::string_view kBearer = "bearer ";
// Calls under this path need no token.
constexpr absl::string_view kOpenPathPrefix = "/grpc.health.v1.Health/";

absl::string_view View(const grpc::string_ref& ref) { return {ref.data(), ref.size()}; }

}  // namespace

absl::Status ValidateAccessToken(absl::string_view token) {
  if (token.size() < kMinAccessTokenLength) {
    return absl::InvalidArgumentError(absl::StrCat("an access token has ", token.size(),
                                                   " characters; it needs at least ",
                                                   kMinAccessTokenLength));
  }
  for (const char c : token) {
    if (c <= ' ' || c > '~') {
      return absl::InvalidArgumentError(
          "an access token may hold printable ASCII characters only, no spaces");
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<std::string>> ParseAccessTokens(absl::string_view text) {
  std::vector<std::string> tokens;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || line.front() == '#') continue;
    if (absl::Status valid = ValidateAccessToken(line); !valid.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("line ", line_number, ": ", valid.message()));
    }
    tokens.emplace_back(line);
  }
  if (tokens.empty()) {
    return absl::InvalidArgumentError(
        "no access token in it (one per line; '#' starts a comment line)");
  }
  return tokens;
}

absl::StatusOr<std::shared_ptr<AccessTokenChecker>> AccessTokenChecker::Create(
    std::vector<std::string> tokens) {
  std::shared_ptr<AccessTokenChecker> checker(new AccessTokenChecker());
  if (absl::Status s = checker->ReplaceTokens(std::move(tokens)); !s.ok()) return s;
  return checker;
}

absl::Status AccessTokenChecker::ReplaceTokens(std::vector<std::string> tokens) {
  if (tokens.empty()) return absl::InvalidArgumentError("no access token given");
  for (const std::string& token : tokens) {
    if (absl::Status valid = ValidateAccessToken(token); !valid.ok()) return valid;
  }
  absl::MutexLock lock(&mu_);
  tokens_ = std::move(tokens);
  return absl::OkStatus();
}

bool AccessTokenChecker::Accepts(absl::string_view token) const {
  absl::MutexLock lock(&mu_);
  bool accepted = false;
  for (const std::string& known : tokens_) {
    // Every byte of equal lengths is compared: the time tells nothing of a partial match.
    unsigned char difference = known.size() == token.size() ? 0 : 1;
    for (size_t i = 0; i < token.size(); ++i) {
      difference |= static_cast<unsigned char>(known[i % known.size()] ^ token[i]);
    }
    accepted |= difference == 0;
  }
  return accepted;
}

grpc::Status AccessTokenChecker::Process(const InputMetadata& auth_metadata,
                                         grpc::AuthContext* /*context*/,
                                         OutputMetadata* consumed_auth_metadata,
                                         OutputMetadata* /*response_metadata*/) {
  const auto path = auth_metadata.find(":path");
  if (path != auth_metadata.end() && absl::StartsWith(View(path->second), kOpenPathPrefix)) {
    return grpc::Status::OK;
  }
  const auto [begin, end] = auth_metadata.equal_range(
      grpc::string_ref(kAuthorization.data(), kAuthorization.size()));
  if (begin == end) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "this server requires an access token: send the metadata "
                        "'authorization: Bearer TOKEN' (neuralmesh: --access_token_file)");
  }
  for (auto it = begin; it != end; ++it) {
    const absl::string_view value = View(it->second);
    if (value.size() <= kBearer.size() ||
        !absl::EqualsIgnoreCase(value.substr(0, kBearer.size()), kBearer)) {
      continue;
    }
    if (Accepts(value.substr(kBearer.size()))) {
      consumed_auth_metadata->emplace(std::string(kAuthorization), std::string(value));
      return grpc::Status::OK;
    }
  }
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                      "the access token is not one this server accepts (expected "
                      "'authorization: Bearer TOKEN' with a token of its --access_tokens_file)");
}

}  // namespace neuralmesh::server
