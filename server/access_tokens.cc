#include "server/access_tokens.h"

#include <algorithm>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
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

absl::string_view AccessRoleName(AccessRole role) {
  switch (role) {
    case AccessRole::kAdmin:
      return "admin";
    case AccessRole::kUser:
      return "user";
    case AccessRole::kReader:
      return "reader";
  }
  return "admin";
}

absl::StatusOr<AccessRole> ParseAccessRole(absl::string_view name) {
  for (const AccessRole role : {AccessRole::kAdmin, AccessRole::kUser, AccessRole::kReader}) {
    if (name == AccessRoleName(role)) return role;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown role \"", absl::CHexEscape(name), "\" (admin, user or reader)"));
}

absl::Status ValidateClient(const AccessToken& token) {
  if (token.client.empty()) {
    if (token.role == AccessRole::kAdmin) return absl::OkStatus();
    return absl::InvalidArgumentError(absl::StrCat("a \"", AccessRoleName(token.role),
                                                   "\" token needs a client name"));
  }
  if (token.client.size() > kMaxClientNameLength) {
    return absl::InvalidArgumentError(absl::StrCat("the client name has ", token.client.size(),
                                                   " characters; at most ",
                                                   kMaxClientNameLength, " are allowed"));
  }
  for (const char c : token.client) {
    if (!absl::ascii_isalnum(c) && c != '.' && c != '_' && c != '@' && c != '-') {
      return absl::InvalidArgumentError(absl::StrCat(
          "the client name \"", absl::CHexEscape(token.client),
          "\" may hold letters, digits and \"._@-\" only"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<AccessToken>> ParseAccessTokens(absl::string_view text) {
  std::vector<AccessToken> tokens;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || line.front() == '#') continue;
    std::vector<absl::string_view> fields =
        absl::StrSplit(line, absl::ByAnyChar(" \t\r"), absl::SkipEmpty());
    // A field starting with '#' starts a comment (no token or client name starts with one).
    fields.erase(std::find_if(fields.begin(), fields.end(),
                              [](absl::string_view f) { return f.front() == '#'; }),
                 fields.end());
    const auto bad_line = [line_number](absl::string_view why) {
      return absl::InvalidArgumentError(absl::StrCat("line ", line_number, ": ", why));
    };
    if (fields.size() > 3) {
      return bad_line(absl::StrCat("expected TOKEN [CLIENT [ROLE]], found ", fields.size(),
                                   " fields"));
    }
    if (absl::Status valid = ValidateAccessToken(fields[0]); !valid.ok()) {
      return bad_line(valid.message());
    }
    AccessToken token{std::string(fields[0])};
    if (fields.size() >= 2) {
      token.client = std::string(fields[1]);
      token.role = AccessRole::kUser;
    }
    if (fields.size() == 3) {
      absl::StatusOr<AccessRole> role = ParseAccessRole(fields[2]);
      if (!role.ok()) return bad_line(role.status().message());
      token.role = *role;
    }
    if (absl::Status valid = ValidateClient(token); !valid.ok()) return bad_line(valid.message());
    tokens.push_back(std::move(token));
  }
  if (tokens.empty()) {
    return absl::InvalidArgumentError(
        "no access token in it (one per line: TOKEN [CLIENT [ROLE]]; '#' starts a comment "
        "line)");
  }
  return tokens;
}

absl::StatusOr<std::shared_ptr<AccessTokenChecker>> AccessTokenChecker::Create(
    std::vector<AccessToken> tokens) {
  std::shared_ptr<AccessTokenChecker> checker(new AccessTokenChecker());
  if (absl::Status s = checker->ReplaceTokens(std::move(tokens)); !s.ok()) return s;
  return checker;
}

absl::Status AccessTokenChecker::ReplaceTokens(std::vector<AccessToken> tokens) {
  if (tokens.empty()) return absl::InvalidArgumentError("no access token given");
  for (const AccessToken& token : tokens) {
    if (absl::Status valid = ValidateAccessToken(token.token); !valid.ok()) return valid;
    if (absl::Status valid = ValidateClient(token); !valid.ok()) return valid;
  }
  absl::MutexLock lock(&mu_);
  tokens_ = std::move(tokens);
  return absl::OkStatus();
}

std::optional<AccessToken> AccessTokenChecker::Find(absl::string_view token) const {
  absl::MutexLock lock(&mu_);
  const AccessToken* found = nullptr;
  for (const AccessToken& known : tokens_) {
    // Every byte of equal lengths is compared: the time tells nothing of a partial match.
    const std::string& bytes = known.token;
    unsigned char difference = bytes.size() == token.size() ? 0 : 1;
    for (size_t i = 0; i < token.size(); ++i) {
      difference |= static_cast<unsigned char>(bytes[i % bytes.size()] ^ token[i]);
    }
    found = difference == 0 ? &known : found;
  }
  if (found == nullptr) return std::nullopt;
  return AccessToken("", found->client, found->role);
}

grpc::Status AccessTokenChecker::Process(const InputMetadata& auth_metadata,
                                         grpc::AuthContext* context,
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
    if (std::optional<AccessToken> found = Find(value.substr(kBearer.size()))) {
      consumed_auth_metadata->emplace(std::string(kAuthorization), std::string(value));
      context->AddProperty(kClientProperty, found->client);
      context->AddProperty(kRoleProperty, std::string(AccessRoleName(found->role)));
      return grpc::Status::OK;
    }
  }
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                      "the access token is not one this server accepts (expected "
                      "'authorization: Bearer TOKEN' with a token of its --access_tokens_file)");
}

}  // namespace neuralmesh::server
