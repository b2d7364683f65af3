// neuralmesh-server --log_calls (server/call_log_interceptor.h): the lines the event log gets
// for calls over 127.0.0.1, with and without a named access token.
#include "server/call_log_interceptor.h"

#include <gmock/gmock.h>
#include <grpcpp/security/credentials.h>
#include <gtest/gtest.h>

#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::server {
namespace {

using ::testing::HasSubstr;
using ::testing::IsEmpty;

// The event lines about calls of `method`.
std::vector<std::string> CallLines(const testing::CapturedEvents& events,
                                   const std::string& method) {
  std::vector<std::string> out;
  for (const std::string& line : events.lines()) {
    if (absl::StrContains(line, " call " + method + " ")) out.push_back(line);
  }
  return out;
}

TEST(CallLogTest, ErrorsOnlyEachOnOneLineWithWhoWhatAndHowLong) {
  testing::CapturedEvents events;
  ServerOptions options;
  options.event_sink = events.Sink();
  options.log_calls = CallLogLevel::kErrors;
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true, options);
  ASSERT_NE(server, nullptr);
  auto stub = testing::NetworkService(*server);

  testing::MustCreate(*stub, testing::CreateRequest(100));
  grpc::Status missing;
  testing::GetSession(*stub, "s-no\nsuch", &missing);
  ASSERT_EQ(missing.error_code(), grpc::StatusCode::NOT_FOUND);

  EXPECT_THAT(CallLines(events, "CreateSession"), IsEmpty());
  const std::vector<std::string> lines = CallLines(events, "GetSession");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(std::regex_match(
      lines[0],
      std::regex("[0-9-]+T[0-9:.]+Z call GetSession from ipv4:127\\.0\\.0\\.1:[0-9]+: "
                 "NOT_FOUND \\(no session with id \"s-no such\"\\) in [0-9]+\\.[0-9] ms")))
      << lines[0];
}

TEST(CallLogTest, AllCallsWithTheClientNameOfTheirToken) {
  absl::StatusOr<neuralmesh::testing::TestCertificates> certs =
      neuralmesh::testing::MakeTestCertificates(neuralmesh::testing::MakeTempDir("call_log"));
  ASSERT_TRUE(certs.ok()) << certs.status();
  testing::CapturedEvents events;
  ServerOptions options;
  options.event_sink = events.Sink();
  options.log_calls = CallLogLevel::kAll;
  options.security.tls.certificate_chain = certs->server_chain;
  options.security.tls.private_key = certs->server_key;
  constexpr char kToken[] = "alices-token-0123456789abcdef";
  options.security.access_tokens = {AccessToken(kToken, "alice", AccessRole::kUser)};
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true, options);
  ASSERT_NE(server, nullptr);

  grpc::SslCredentialsOptions tls;
  tls.pem_root_certs = certs->ca;
  auto stub = v1::ReconstructionService::NewStub(grpc::CreateChannel(
      server->target(), grpc::CompositeChannelCredentials(grpc::SslCredentials(tls),
                                                          grpc::AccessTokenCredentials(kToken))));
  testing::MustCreate(*stub, testing::CreateRequest(100));

  const std::vector<std::string> lines = CallLines(events, "CreateSession");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_THAT(lines[0], HasSubstr(" (client alice): OK in "));

  // A token the server does not take is refused before the call reaches the interceptor.
  auto stranger = v1::ReconstructionService::NewStub(grpc::CreateChannel(
      server->target(),
      grpc::CompositeChannelCredentials(grpc::SslCredentials(tls),
                                        grpc::AccessTokenCredentials("not-a-token-0123456789"))));
  EXPECT_EQ(testing::Delete(*stranger, "s-1").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(CallLines(events, "DeleteSession"), IsEmpty());
}

TEST(CallLogTest, LevelsByName) {
  EXPECT_EQ(*ParseCallLogLevel("none"), CallLogLevel::kNone);
  EXPECT_EQ(*ParseCallLogLevel("errors"), CallLogLevel::kErrors);
  EXPECT_EQ(*ParseCallLogLevel("all"), CallLogLevel::kAll);
  const absl::Status unknown = ParseCallLogLevel("verbose").status();
  EXPECT_TRUE(absl::IsInvalidArgument(unknown));
  EXPECT_THAT(unknown.message(), HasSubstr("use none, errors or all"));
}

}  // namespace
}  // namespace neuralmesh::server
