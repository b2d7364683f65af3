#include "server/access_tokens.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace neuralmesh::server {
namespace {

using ::grpc::string_ref;

// The fields of `tokens`, one "token client role" string each.
std::vector<std::string> Describe(const std::vector<AccessToken>& tokens) {
  std::vector<std::string> out;
  for (const AccessToken& t : tokens) {
    out.push_back(absl::StrCat(t.token, " ", t.client, " ", AccessRoleName(t.role)));
  }
  return out;
}

TEST(ParseAccessTokensTest, OneTokenPerLineWithCommentsAndBlankLines) {
  absl::StatusOr<std::vector<AccessToken>> tokens = ParseAccessTokens(
      "# the viewer's token\n"
      "viewer-0123456789abcdef\n"
      "\n"
      "   scanner-0123456789abcdef  \r\n"
      "#retired-0123456789abcdef\n");
  ASSERT_TRUE(tokens.ok()) << tokens.status();
  EXPECT_EQ(Describe(*tokens), (std::vector<std::string>{"viewer-0123456789abcdef  admin",
                                                         "scanner-0123456789abcdef  admin"}));
}

TEST(ParseAccessTokensTest, ATokenMayNameItsClientAndRole) {
  absl::StatusOr<std::vector<AccessToken>> tokens = ParseAccessTokens(
      "alice-0123456789abcdef alice\n"
      "bob-0123456789abcdef\tbob@lab.example  user\n"
      "wall-0123456789abcdef wall-display reader  # the lab's screen\n"
      "ops-0123456789abcdef ops_team admin\n"
      "root-0123456789abcdef #an admin token\n");
  ASSERT_TRUE(tokens.ok()) << tokens.status();
  EXPECT_EQ(Describe(*tokens), (std::vector<std::string>{
                                   "alice-0123456789abcdef alice user",
                                   "bob-0123456789abcdef bob@lab.example user",
                                   "wall-0123456789abcdef wall-display reader",
                                   "ops-0123456789abcdef ops_team admin",
                                   "root-0123456789abcdef  admin"}));
}

TEST(ParseAccessTokensTest, BadTokensNameTheirLineButNotTheToken) {
  struct Case {
    std::string text;
    std::string message;
  };
  for (const Case& c : std::vector<Case>{
           {"good-token-0123456789\nshort\n", "line 2: an access token has 5 characters"},
           {"two words-0123456789abcdef\n", "line 1: an access token has 3 characters"},
           {"caf\xc3\xa9-0123456789abcdef alice\n", "line 1: an access token may hold printable"},
           {"good-token-0123456789 al/ice\n", "line 1: the client name \"al/ice\" may hold"},
           {"good-token-0123456789 alice owner\n", "line 1: unknown role \"owner\""},
           {"good-token-0123456789 alice user extra\n",
            "line 1: expected TOKEN [CLIENT [ROLE]], found 4 fields"},
           {absl::StrCat("good-token-0123456789 ", std::string(65, 'a'), "\n"),
            "line 1: the client name has 65 characters"},
           {"caf\xc3\xa9-0123456789abcdef\n", "line 1: an access token may hold printable"},
           {"", "no access token in it"},
           {"# only a comment\n\n", "no access token in it"}}) {
    absl::StatusOr<std::vector<AccessToken>> tokens = ParseAccessTokens(c.text);
    ASSERT_FALSE(tokens.ok()) << c.text;
    EXPECT_EQ(tokens.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_TRUE(absl::StartsWith(tokens.status().message(), c.message)) << tokens.status();
    EXPECT_FALSE(absl::StrContains(tokens.status().message(), "0123456789")) << "not echoed";
  }
}

// An AuthContext that keeps the properties the checker adds (gRPC's own is internal).
class RecordingAuthContext : public grpc::AuthContext {
  // Iteration is not what the checker uses.
  struct NoProperties : grpc::AuthPropertyIterator {
    NoProperties() = default;
  };

 public:
  bool IsPeerAuthenticated() const override { return false; }
  std::vector<grpc::string_ref> GetPeerIdentity() const override { return {}; }
  std::string GetPeerIdentityPropertyName() const override { return ""; }
  std::vector<grpc::string_ref> FindPropertyValues(const std::string& name) const override {
    std::vector<grpc::string_ref> values;
    for (auto [it, end] = properties_.equal_range(name); it != end; ++it) {
      values.emplace_back(it->second);
    }
    return values;
  }
  grpc::AuthPropertyIterator begin() const override { return NoProperties(); }
  grpc::AuthPropertyIterator end() const override { return NoProperties(); }
  void AddProperty(const std::string& key, const grpc::string_ref& value) override {
    properties_.emplace(key, std::string(value.data(), value.size()));
  }
  bool SetPeerIdentityPropertyName(const std::string&) override { return false; }

  std::string Only(const std::string& name) const {
    const std::vector<grpc::string_ref> values = FindPropertyValues(name);
    return values.size() == 1 ? std::string(values[0].data(), values[0].size()) : "<none>";
  }
  void Clear() { properties_.clear(); }

 private:
  std::multimap<std::string, std::string> properties_;
};

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
    context_.Clear();
    grpc::AuthMetadataProcessor::OutputMetadata response;
    return checker_->Process(metadata, &context_, &consumed_, &response);
  }

  std::shared_ptr<AccessTokenChecker> checker_ = *AccessTokenChecker::Create(
      {"first-token-0123456789", "second-token-0123456789",
       AccessToken("alice-token-0123456789", "alice", AccessRole::kUser),
       AccessToken("wall-token-0123456789", "wall", AccessRole::kReader)});
  RecordingAuthContext context_;
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

TEST_F(AccessTokenCheckerTest, TellsTheHandlersTheTokensClientAndRole) {
  ASSERT_TRUE(Check(kCreate, {"Bearer second-token-0123456789"}).ok());
  EXPECT_EQ(context_.Only(kClientProperty), "");
  EXPECT_EQ(context_.Only(kRoleProperty), "admin");
  ASSERT_TRUE(Check(kCreate, {"Bearer alice-token-0123456789"}).ok());
  EXPECT_EQ(context_.Only(kClientProperty), "alice");
  EXPECT_EQ(context_.Only(kRoleProperty), "user");
  ASSERT_TRUE(Check(kCreate, {"Bearer wall-token-0123456789"}).ok());
  EXPECT_EQ(context_.Only(kClientProperty), "wall");
  EXPECT_EQ(context_.Only(kRoleProperty), "reader");
  ASSERT_FALSE(Check(kCreate, {"Bearer wall-token-0123456780"}).ok());
  EXPECT_EQ(context_.Only(kRoleProperty), "<none>") << "a refused call gets no role";
}

TEST_F(AccessTokenCheckerTest, RefusesMissingAndUnknownTokens) {
  const grpc::Status missing = Check(kCreate, {});
  EXPECT_EQ(missing.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(absl::StrContains(missing.error_message(), "requires an access token"));
  for (const char* value :
       {"Bearer first-token-012345678", "Bearer first-token-01234567890",
        "Bearer first-token-0123456780", "Bearer ", "Bearer", "first-token-0123456789",
        "Basic first-token-0123456789", "Bearer  first-token-0123456789"}) {
    const grpc::Status refused = Check(kCreate, {value});
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAUTHENTICATED) << value;
    EXPECT_TRUE(absl::StrContains(refused.error_message(), "not one this server accepts"));
    EXPECT_FALSE(absl::StrContains(refused.error_message(), "0123456789")) << "not echoed";
    EXPECT_TRUE(consumed_.empty());
    EXPECT_EQ(context_.Only(kRoleProperty), "<none>");
  }
}

TEST(AccessTokenCheckerCreateTest, RefusesAnEmptyListAndInvalidTokens) {
  EXPECT_TRUE(absl::IsInvalidArgument(AccessTokenChecker::Create({}).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(
      AccessTokenChecker::Create({"good-token-0123456789", "short"}).status()));
  const absl::Status unnamed_user =
      AccessTokenChecker::Create({AccessToken("good-token-0123456789", "", AccessRole::kUser)})
          .status();
  EXPECT_TRUE(absl::IsInvalidArgument(unnamed_user));
  EXPECT_TRUE(absl::StrContains(unnamed_user.message(), "\"user\" token needs a client name"));
}

TEST_F(AccessTokenCheckerTest, HealthChecksAreOpen) {
  EXPECT_TRUE(Check("/grpc.health.v1.Health/Check", {}).ok());
  EXPECT_TRUE(Check("/grpc.health.v1.Health/Watch", {"Bearer wrong"}).ok());
  EXPECT_FALSE(Check("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", {}).ok());
  EXPECT_FALSE(Check("/grpc.health.v1.HealthX/Check", {}).ok());
}

}  // namespace
}  // namespace neuralmesh::server
