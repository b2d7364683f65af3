#include "http/bearer_token.h"

#include <gtest/gtest.h>

namespace neuralmesh::http {
namespace {

TEST(BearerTokenTest, ASecretIsOneUrlSafeWordOfSixteenCharactersOrMore) {
  absl::StatusOr<std::string> secret = ParseSecret("  abcdefgh-1234._~Z\n", "the token");
  ASSERT_TRUE(secret.ok()) << secret.status();
  EXPECT_EQ(*secret, "abcdefgh-1234._~Z");
  EXPECT_EQ(ParseSecret("short", "the metrics token").status().message(),
            "the metrics token has 5 characters; it needs at least 16");
  EXPECT_EQ(ParseSecret("", "the token").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseSecret("abcdefghijklmnop\nqrstuvwxyz", "the token").status().message(),
            "the token may hold letters, digits and \"-._~\" only (one line)");
  EXPECT_EQ(ParseSecret("abcdefghijklmnop/", "the token").status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(BearerTokenTest, TheTokenComesFromTheAuthorizationHeaderInAnyCaseOfItsScheme) {
  HttpRequest request;
  EXPECT_EQ(BearerTokenOf(request), "");
  request.headers["authorization"] = "Bearer abc";
  EXPECT_EQ(BearerTokenOf(request), "abc");
  request.headers["authorization"] = "bearer  abc";
  EXPECT_EQ(BearerTokenOf(request), "abc");
  request.headers["authorization"] = "Basic YWxhZGRpbjpvcGVuc2VzYW1l";
  EXPECT_EQ(BearerTokenOf(request), "");
  request.headers["authorization"] = "Bearer";
  EXPECT_EQ(BearerTokenOf(request), "");
}

TEST(BearerTokenTest, SecretsAreEqualOnlyWhenEveryCharacterIs) {
  EXPECT_TRUE(SameSecret("abcdefghijklmnop", "abcdefghijklmnop"));
  EXPECT_FALSE(SameSecret("abcdefghijklmnop", "abcdefghijklmnoq"));
  EXPECT_FALSE(SameSecret("abcdefghijklmnop", "abcdefghijklmno"));
  EXPECT_FALSE(SameSecret("", "a"));
}

TEST(BearerTokenTest, AChallengeIs401WithTheRealm) {
  const HttpResponse response = BearerChallenge("neuralmesh metrics", "bring the token");
  EXPECT_EQ(response.status, 401);
  EXPECT_EQ(response.body, "bring the token\n");
  ASSERT_EQ(response.headers.size(), 1u);
  EXPECT_EQ(response.headers[0].first, "WWW-Authenticate");
  EXPECT_EQ(response.headers[0].second, "Bearer realm=\"neuralmesh metrics\"");
}

}  // namespace
}  // namespace neuralmesh::http
