#include "server/access_tokens.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "absl/strings/match.h"

namespace neuralmesh::server {
namespace {

using ::grpc::string_ref;

TEST(ParseAccessTokensTest, OneTokenPerLineWithCommentsAndBlankLines) {
  absl::StatusOr<std::vector<std::string>> tokens = ParseAccessTokens(
      "# the viewer's token\n"
      "viewer-0123456789abcdef\n"
      "\n"
      "   scanner-0123456789abcdef  \r\n"
      "#retired-0123456789abcdef\n");
  ASSERT_TRUE(tokens.ok()) << tokens.status();
  EXPECT_EQ(*tokens,
            (std::vector<std::string>{"viewer-0123456789abcdef", "scanner-0123456789abcdef"}));
}

TEST(ParseAccessTokensTest, BadTokensNameTheirLineButNotTheToken) {
  struct Case {
    std::string text;
    std::string message;
  };
  for (const Case& c : std::vector<Case>{
           {"good-token-0123456789\nshort\n", "line 2: an access token has 5 characters"},
           {"two words-0123456789abcdef\n", "line 1: an access token may hold printable ASCII"},
           {"tab\tinside-0123456789abcdef\n", "line 1: an access token may hold printable"},
           {"caf\xc3\xa9-0123456789abcdef\n", "line 1: an access token may hold printable"},
           {"", "no access token in it"},
           {"# only a comment\n\n", "no access token in it"}}) {
    absl::StatusOr<std::vector<std::string>> tokens = ParseAccessTokens(c.text);
    ASSERT_FALSE(tokens.ok()) << c.text;
    EXPECT_EQ(tokens.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_TRUE(absl::StartsWith(tokens.status().message(), c.message)) << tokens.status();
    EXPECT_FALSE(absl::StrContains(tokens.status().message(), "0123456789")) << "not echoed";
  }
}

class AccessTokenCheckerTest : public ::testing::Test {
 protected:
  // Runs the checker on a call to `path` with these `authorization` values.
  grpc::Status Check(const std::string& path, const std::vector<std::string>& authorization) {
    storage_ = authorization;
    storage_.push_back(path);
    grpc::AuthMetadataProcessor::InputMetadata metadata;
    metadata.emplace(string_ref(":path"), string_ref(storage_.back()));
    for (size_t i = 0; i + 1 < storage_.size(); ++i) {
      metadata.emplace(string_ref("authorization"), string_ref(storage_[i]));
    }
    consumed_.clear();
    grpc::AuthMetadataProcessor::OutputMetadata response;
    return checker_->Process(metadata, nullptr, &consumed_, &response);
  }

  std::shared_ptr<AccessTokenChecker> checker_ =
      *AccessTokenChecker::Create({"first-token-0123456789", "second-token-0123456789"});
  std::vector<std::string> storage_;
  grpc::AuthMetadataProcessor::OutputMetadata consumed_;
};

constexpr char kCreate[] = "/neuralmesh.v1.ReconstructionService/CreateSession";

TEST_F(AccessTokenCheckerTest, AcceptsEveryKnownTokenAndConsumesIt) {
  EXPECT_TRUE(Check(kCreate, {"Bearer first-token-0123456789"}).ok());
  EXPECT_EQ(consumed_.count("authorization"), 1u) << "handlers do not see the token";
  EXPECT_TRUE(Check(kCreate, {"Bearer second-token-0123456789"}).ok());
  EXPECT_TRUE(Check(kCreate, {"BEARER second-token-0123456789"}).ok()) << "caseless scheme";
  EXPECT_TRUE(Check(kCreate, {"Basic abc", "Bearer first-token-0123456789"}).ok());
}

TEST_F(AccessTokenCheckerTest, RefusesMissingAndUnknownTokens) {
  const grpc::Status missing = Check(kCreate, {});
  EXPECT_EQ(missing.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(absl::StrContains(missing.error_message(), "requires an access token"));
  for (const std::string& value :
       {"Bearer first-token-012345678", "Bearer first-token-01234567890",
        "Bearer first-token-0123456780", "Bearer ", "Bearer", "first-token-0123456789",
        "Basic first-token-0123456789", "Bearer  first-token-0123456789"}) {
    const grpc::Status refused = Check(kCreate, {value});
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAUTHENTICATED) << value;
    EXPECT_TRUE(absl::StrContains(refused.error_message(), "not one this server accepts"));
    EXPECT_FALSE(absl::StrContains(refused.error_message(), "0123456789")) << "not echoed";
    EXPECT_TRUE(consumed_.empty());
  }
}

TEST(AccessTokenCheckerCreateTest, RefusesAnEmptyListAndInvalidTokens) {
  EXPECT_TRUE(absl::IsInvalidArgument(AccessTokenChecker::Create({}).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(
      AccessTokenChecker::Create({"good-token-0123456789", "short"}).status()));
}

TEST_F(AccessTokenCheckerTest, HealthChecksAreOpen) {
  EXPECT_TRUE(Check("/grpc.health.v1.Health/Check", {}).ok());
  EXPECT_TRUE(Check("/grpc.health.v1.Health/Watch", {"Bearer wrong"}).ok());
  EXPECT_FALSE(Check("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", {}).ok());
  EXPECT_FALSE(Check("/grpc.health.v1.HealthX/Check", {}).ok());
}

}  // namespace
}  // namespace neuralmesh::server
