#include "http/bearer_token.h"

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"

namespace neuralmesh::http {

bool IsSecretCharacter(char c) {
  return absl::ascii_isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' || c == '_' ||
         c == '~';
}

absl::StatusOr<std::string> ParseSecret(absl::string_view contents, absl::string_view what) {
  const absl::string_view secret = absl::StripAsciiWhitespace(contents);
  if (secret.size() < kMinSecretLength) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, " has ", secret.size(), " characters; it needs at least ", kMinSecretLength));
  }
  for (const char c : secret) {
    if (!IsSecretCharacter(c)) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, " may hold letters, digits and \"-._~\" only (one line)"));
    }
  }
  return std::string(secret);
}

bool SameSecret(absl::string_view a, absl::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char difference = 0;
  for (size_t i = 0; i < a.size(); ++i) difference |= static_cast<unsigned char>(a[i] ^ b[i]);
  return difference == 0;
}

absl::string_view BearerTokenOf(const HttpRequest& request) {
  auto it = request.headers.find("authorization");
  if (it == request.headers.end()) return {};
  absl::string_view value = it->second;
  constexpr absl::string_view kScheme = "bearer ";
  if (!absl::StartsWithIgnoreCase(value, kScheme)) return {};
  value.remove_prefix(kScheme.size());
  return absl::StripLeadingAsciiWhitespace(value);
}

HttpResponse BearerChallenge(absl::string_view realm, absl::string_view message) {
  HttpResponse response = TextResponse(401, message);
  response.headers.emplace_back("WWW-Authenticate", absl::StrCat("Bearer realm=\"", realm, "\""));
  return response;
}

}  // namespace neuralmesh::http
