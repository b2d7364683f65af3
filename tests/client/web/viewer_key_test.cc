// client/web/viewer_key.h: the key a viewer asks of browsers, where a request may bring it and
// how the viewer turns a key in the URL into a cookie.
#include "client/web/viewer_key.h"

#include <gtest/gtest.h>

#include <string>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace neuralmesh::client::web {

using ::neuralmesh::http::HttpRequest;
using ::neuralmesh::http::HttpResponse;

namespace {

constexpr char kKey[] = "k3y-Of_The.Viewer~1";

TEST(ViewerKeyTest, AKeyFileHoldsOneUrlSafeKeyOfSixteenCharactersOrMore) {
  absl::StatusOr<std::string> key = ParseViewerKey(absl::StrCat("  ", kKey, "\n"));
  ASSERT_TRUE(key.ok()) << key.status();
  EXPECT_EQ(*key, kKey);
  EXPECT_EQ(ParseViewerKey("short-key").status().message(),
            "the viewer key has 9 characters; it needs at least 16");
  EXPECT_EQ(ParseViewerKey("").status().code(), absl::StatusCode::kInvalidArgument);
  for (const char* bad : {"0123456789abcdef ghi", "0123456789abcdef&x=1", "0123456789abcdef\nx"}) {
    EXPECT_EQ(ParseViewerKey(bad).status().message(),
              "the viewer key may hold letters, digits and \"-._~\" only (one line)")
        << bad;
  }
}

TEST(ViewerKeyTest, TheKeyComesInTheQueryACookieOrABearerHeader) {
  HttpRequest request;
  request.path = "/api/sessions";
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kRefused);
  request.headers["cookie"] = absl::StrCat("theme=dark; ", ViewerKeyCookieName(kKey), "=", kKey);
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kGranted);
  request.headers["cookie"] = absl::StrCat(ViewerKeyCookieName(kKey), "=", kKey, "x");
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kRefused);
  request.headers["cookie"] = absl::StrCat("x", ViewerKeyCookieName(kKey), "=", kKey);
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kRefused) << "another cookie's name";
  request.headers.erase("cookie");
  request.headers["authorization"] = absl::StrCat("Bearer ", kKey);
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kGranted);
  request.headers["authorization"] = absl::StrCat("Basic ", kKey);
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kRefused);
  request.query["key"] = kKey;
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kGrantedFromUrl);
  request.query["key"] = "k3y-Of_The.Viewer~2";
  request.headers["authorization"] = absl::StrCat("Bearer ", kKey);
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kRefused) << "a wrong key in the URL";
}

// Browsers keep cookies by host: two viewers on one host (say ports 8080 and 8081, each with
// its key) must not overwrite each other's cookie, or a browser open on both is let into one.
TEST(ViewerKeyTest, ViewersWithOtherKeysOnOneHostKeepCookiesOfTheirOwn) {
  constexpr char kOtherKey[] = "another-viewer-key-2";
  const std::string name = ViewerKeyCookieName(kKey);
  EXPECT_EQ(name, ViewerKeyCookieName(kKey)) << "the same name in every run";
  EXPECT_NE(name, ViewerKeyCookieName(kOtherKey));
  EXPECT_NE(name, ViewerKeyCookieName("k3y-Of_The.Viewer~2")) << "keys one character apart";
  EXPECT_TRUE(absl::StartsWith(name, "neuralmesh_view_key_")) << name;
  EXPECT_EQ(name.size(), std::string("neuralmesh_view_key_").size() + 16) << name;

  HttpRequest request;
  request.path = "/api/sessions";
  request.headers["cookie"] =
      absl::StrCat(ViewerKeyCookieName(kOtherKey), "=", kOtherKey, "; ", name, "=", kKey);
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kGranted);
  EXPECT_EQ(CheckViewerKey(request, kOtherKey), ViewerKeyCheck::kGranted);
  request.headers["cookie"] = absl::StrCat(ViewerKeyCookieName(kOtherKey), "=", kOtherKey);
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kRefused);
  request.headers["cookie"] = absl::StrCat(ViewerKeyCookieName(kOtherKey), "=", kKey);
  EXPECT_EQ(CheckViewerKey(request, kKey), ViewerKeyCheck::kRefused)
      << "the key under another viewer's name";
}

TEST(ViewerKeyTest, AKeyInTheUrlBecomesACookieAndTheUrlLosesIt) {
  HttpRequest request;
  request.path = "/";
  request.query = {{"key", kKey}, {"session", "s-1a2b"}, {"note", "a b&c"}};
  const HttpResponse response = ViewerKeyRedirect(request, kKey);
  EXPECT_EQ(response.status, 303);
  ASSERT_EQ(response.headers.size(), 2u);
  EXPECT_EQ(response.headers[0].first, "Location");
  EXPECT_EQ(response.headers[0].second, "/?note=a%20b%26c&session=s-1a2b");
  EXPECT_EQ(response.headers[1].first, "Set-Cookie");
  EXPECT_EQ(response.headers[1].second,
            absl::StrCat(ViewerKeyCookieName(kKey), "=", kKey,
                         "; HttpOnly; SameSite=Strict; Path=/"));
  request.path = "/api/sessions/s 1";
  request.query = {{"key", kKey}};
  EXPECT_EQ(ViewerKeyRedirect(request, kKey).headers[0].second, "/api/sessions/s%201");
}

}  // namespace
}  // namespace neuralmesh::client::web
