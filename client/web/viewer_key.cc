#include "client/web/viewer_key.h"

#include <cstddef>
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "http/bearer_token.h"

namespace neuralmesh::client::web {

using ::neuralmesh::http::BearerTokenOf;
using ::neuralmesh::http::HttpRequest;
using ::neuralmesh::http::HttpResponse;
using ::neuralmesh::http::IsSecretCharacter;
using ::neuralmesh::http::SameSecret;
using ::neuralmesh::http::TextResponse;

namespace {

// The value of cookie `name` in a Cookie header, or nothing.
absl::string_view CookieValue(absl::string_view header, absl::string_view name) {
  for (absl::string_view pair : absl::StrSplit(header, ';')) {
    pair = absl::StripAsciiWhitespace(pair);
    if (absl::ConsumePrefix(&pair, name) && absl::ConsumePrefix(&pair, "=")) return pair;
  }
  return {};
}

// `text` percent-encoded for a URL path segment or query (letters, digits and "-._~" as they
// are).
std::string PercentEncoded(absl::string_view text) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string encoded;
  for (const char c : text) {
    if (IsSecretCharacter(c)) {
      encoded.push_back(c);
    } else {
      const unsigned char byte = static_cast<unsigned char>(c);
      encoded += {'%', kHex[byte >> 4], kHex[byte & 15]};
    }
  }
  return encoded;
}

}  // namespace

std::string ViewerKeyCookieName(absl::string_view key) {
  uint64_t hash = 0xcbf29ce484222325ull;  // 64-bit FNV-1a: the same name in every run.
  for (const char c : key) {
    hash = (hash ^ static_cast<unsigned char>(c)) * 0x100000001b3ull;
  }
  return absl::StrCat("neuralmesh_view_key_", absl::Hex(hash, absl::kZeroPad16));
}

absl::StatusOr<std::string> ParseViewerKey(absl::string_view contents) {
  return http::ParseSecret(contents, "the viewer key");
}

ViewerKeyCheck CheckViewerKey(const HttpRequest& request, absl::string_view key) {
  if (auto it = request.query.find("key"); it != request.query.end()) {
    return SameSecret(it->second, key) ? ViewerKeyCheck::kGrantedFromUrl : ViewerKeyCheck::kRefused;
  }
  if (auto it = request.headers.find("cookie"); it != request.headers.end()) {
    if (SameSecret(CookieValue(it->second, ViewerKeyCookieName(key)), key)) {
      return ViewerKeyCheck::kGranted;
    }
  }
  return SameSecret(BearerTokenOf(request), key) ? ViewerKeyCheck::kGranted
                                                 : ViewerKeyCheck::kRefused;
}

HttpResponse ViewerKeyRedirect(const HttpRequest& request, absl::string_view key, bool https) {
  std::string location;  // The path starts with '/': its first segment is empty.
  bool first = true;
  for (absl::string_view segment : absl::StrSplit(request.path, '/')) {
    if (!first) location.push_back('/');
    first = false;
    location += PercentEncoded(segment);
  }
  const char* separator = "?";
  for (const auto& [name, value] : request.query) {
    if (name == "key") continue;
    absl::StrAppend(&location, separator, PercentEncoded(name), "=", PercentEncoded(value));
    separator = "&";
  }
  HttpResponse response = TextResponse(303, "the key is kept in a cookie: on to the page");
  response.headers.emplace_back("Location", location);
  response.headers.emplace_back(
      "Set-Cookie",
      absl::StrCat(ViewerKeyCookieName(key), "=", key, "; HttpOnly; SameSite=Strict; Path=/",
                   https ? "; Secure" : ""));
  return response;
}

}  // namespace neuralmesh::client::web
