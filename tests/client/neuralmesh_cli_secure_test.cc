// The command line against a secured server: neuralmesh-server with TLS and access tokens,
// `neuralmesh reconstruct/sessions/view` connecting with --tls_ca_file and
// --access_token_file, all run as subprocesses on 127.0.0.1 with throw-away certificates; and
// the messages and exit codes of security flags that are wrong.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/file_contents.h"
#include "tests/client/subprocess.h"
#include "tests/client/test_server.h"
#include "tests/client/web/viewer_test_support.h"
#include "tests/testing/https_client.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::testing {
namespace {

using ::testing::HasSubstr;

constexpr char kToken[] = "cli-test-token-0123456789abcdef";
constexpr char kAliceToken[] = "cli-alice-token-0123456789abcdef";
constexpr char kWallToken[] = "cli-wall-token-0123456789abcdef";

class SecureCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(MakeTempDir("cli_secure"));
    absl::StatusOr<TestCertificates> made = MakeTestCertificates(*dir_ + "/tls");
    ASSERT_TRUE(made.ok()) << made.status();
    certificates_ = new TestCertificates(*std::move(made));
    ASSERT_TRUE(WriteFileContents(Path("tokens"),
                                  absl::StrCat("# test\n", kToken, "\n", kAliceToken, " alice\n",
                                               kWallToken, " wall reader\n"))
                    .ok());
    ASSERT_TRUE(WriteFileContents(Path("token"), absl::StrCat(kToken, "\n")).ok());
    ASSERT_TRUE(WriteFileContents(Path("alice_token"), kAliceToken).ok());
    ASSERT_TRUE(WriteFileContents(Path("wall_token"), kWallToken).ok());
    ASSERT_TRUE(WriteFileContents(Path("wrong_token"), "wrong-token-0123456789abcdef").ok());
    chmod(Path("token").c_str(), 0600);
    std::string error;
    server_ = TestServer::Start({"--tls_cert_file=" + certs().Path("server.pem"),
                                 "--tls_key_file=" + certs().Path("server.key"),
                                 "--access_tokens_file=" + Path("tokens")},
                                &error)
                  .release();
    ASSERT_NE(server_, nullptr) << error;
  }
  static void TearDownTestSuite() {
    delete server_;
    delete certificates_;
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }

  static std::string Path(const std::string& file) { return *dir_ + "/" + file; }
  static const TestCertificates& certs() { return *certificates_; }
  // The flags that reach the test server: its address, the CA and the token.
  static std::vector<std::string> Secured(std::vector<std::string> args) {
    args.insert(args.end(), {"--server=" + server_->address(),
                             "--tls_ca_file=" + certs().Path("ca.pem"),
                             "--access_token_file=" + Path("token")});
    return args;
  }

  static std::string* dir_;
  static TestCertificates* certificates_;
  static TestServer* server_;
};

std::string* SecureCliTest::dir_ = nullptr;
TestCertificates* SecureCliTest::certificates_ = nullptr;
TestServer* SecureCliTest::server_ = nullptr;

TEST_F(SecureCliTest, ReconstructAndSessionsOverTlsWithAToken) {
  const RunResult reconstruct =
      RunNeuralmesh(Secured({"reconstruct", "builtin:sphere", "--out-dir", Path("out"),
                             "--vertices", "300", "--points", "3000"}));
  ASSERT_EQ(reconstruct.exit_code, 0) << reconstruct.Describe();
  EXPECT_TRUE(std::filesystem::exists(Path("out/sphere.drc"))) << reconstruct.out;
  const RunResult stats = RunNeuralmesh({"stats", Path("out/sphere.drc"), "--json"});
  ASSERT_EQ(stats.exit_code, 0) << stats.Describe();
  EXPECT_THAT(stats.out, HasSubstr("\"vertices\": 300"));
  EXPECT_THAT(stats.out, HasSubstr("\"genus\": 0"));

  const RunResult sessions = RunNeuralmesh(Secured({"sessions"}));
  ASSERT_EQ(sessions.exit_code, 0) << sessions.Describe();
  EXPECT_THAT(sessions.out, HasSubstr("finished"));
  // As through a tunnel: the certificate's name, not the host dialled.
  const RunResult named = RunNeuralmesh(Secured({"sessions", "--tls_server_name=localhost"}));
  EXPECT_EQ(named.exit_code, 0) << named.Describe();
  const RunResult wrong_name =
      RunNeuralmesh(Secured({"sessions", "--tls_server_name=scans.example.test",
                             "--connect_timeout=1s"}));
  EXPECT_NE(wrong_name.exit_code, 0) << wrong_name.Describe();
  EXPECT_THAT(wrong_name.err, HasSubstr("cannot reach")) << wrong_name.Describe();
}

// Tokens that name their clients: a user sees its own sessions, a reader sees all and
// creates none; `sessions` shows who owns what.
TEST_F(SecureCliTest, NamedTokensOwnTheirSessionsAndAReaderOnlyLooks) {
  const auto as = [](const std::string& token_file, std::vector<std::string> args) {
    args.insert(args.end(), {"--server=" + server_->address(),
                             "--tls_ca_file=" + certs().Path("ca.pem"),
                             "--access_token_file=" + Path(token_file)});
    return RunNeuralmesh(args);
  };
  const RunResult alice = as("alice_token", {"reconstruct", "builtin:torus", "--out-dir",
                                             Path("alice"), "--vertices", "300", "--points",
                                             "3000"});
  ASSERT_EQ(alice.exit_code, 0) << alice.Describe();
  std::smatch match;
  ASSERT_TRUE(std::regex_search(alice.out, match, std::regex("session (s-[0-9a-f]+) on")))
      << alice.out;
  const std::string id = match[1];

  const RunResult own = as("alice_token", {"sessions"});
  ASSERT_EQ(own.exit_code, 0) << own.Describe();
  EXPECT_THAT(own.out, HasSubstr("owner"));
  EXPECT_TRUE(std::regex_search(own.out, std::regex(id + " +torus +alice +finished"))) << own.out;
  EXPECT_THAT(own.out, HasSubstr("\n1 session\n")) << "only alice's own";

  const RunResult all = as("wall_token", {"sessions", "--json"});
  ASSERT_EQ(all.exit_code, 0) << all.Describe();
  EXPECT_THAT(all.out, HasSubstr("\"owner\": \"alice\""));
  const RunResult watched = as("wall_token", {"watch", id, "--out-dir", Path("wall")});
  EXPECT_EQ(watched.exit_code, 0) << watched.Describe();
  EXPECT_TRUE(std::filesystem::exists(Path("wall/" + id + ".drc")));

  const RunResult refused = as("wall_token", {"reconstruct", "builtin:sphere", "--out-dir",
                                              Path("refused"), "--vertices", "100"});
  EXPECT_NE(refused.exit_code, 0) << refused.Describe();
  EXPECT_THAT(refused.err, HasSubstr("client wall is a reader")) << refused.err;
}

TEST_F(SecureCliTest, AMissingWrongOrUnprotectedTokenFailsClearly) {
  const std::string server = "--server=" + server_->address();
  const std::string ca = "--tls_ca_file=" + certs().Path("ca.pem");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const Case cases[] = {
      {{"sessions", server, ca}, "requires an access token"},
      {{"sessions", server, ca, "--access_token_file=" + Path("wrong_token")},
       "not one this server accepts"},
      {{"sessions", server, "--connect_timeout=1s"}, "does the server want TLS"},
      {{"sessions", server, "--access_token_file=" + Path("token")},
       "--access_token_file needs TLS"},
      {{"sessions", server, "--tls_ca_file=" + Path("missing.pem")},
       "--tls_ca_file: cannot open"},
      {{"sessions", server, "--tls_ca_file=" + Path("token")}, "not PEM text"},
      {{"sessions", server, "--tls", "--tls_cert_file=" + certs().Path("client.pem")},
       "needs its private key"},
      {{"reconstruct", "builtin:sphere", "-o", Path("local.ply"), "--vertices", "100", "--tls"},
       "--tls needs --server"},
  };
  for (const Case& c : cases) {
    const RunResult run = RunNeuralmesh(c.args);
    EXPECT_NE(run.exit_code, 0) << run.Describe();
    EXPECT_THAT(run.err, HasSubstr(c.message)) << run.Describe();
  }
}

TEST_F(SecureCliTest, TheViewerReachesASecuredServer) {
  BackgroundProcess viewer("neuralmesh", Secured({"view", "--listen=127.0.0.1:0"}));
  const int port = WaitForViewerPort(viewer);
  ASSERT_NE(port, 0) << viewer.Stderr();
  const HttpReply sessions = HttpGet(port, "/api/sessions");
  EXPECT_EQ(sessions.status, 200) << sessions.body;
  EXPECT_THAT(sessions.body, ::testing::StartsWith("["))
      << "listed through TLS with the token (a refused call is a 502 with an error object)";
  EXPECT_EQ(viewer.SignalAndWait(SIGTERM), 0) << viewer.Stderr();

  const RunResult refused = RunNeuralmesh({"view", "--server=" + server_->address(),
                                           "--tls_ca_file=" + certs().Path("ca.pem"),
                                           "--access_token_file=" + Path("wrong_token"),
                                           "--listen=127.0.0.1:0"});
  EXPECT_NE(refused.exit_code, 0) << refused.Describe();
  EXPECT_THAT(refused.err, HasSubstr("not one this server accepts")) << "said at start";
}

// A renewed certificate written over the server's files applies after SIGHUP, without a
// restart; files that went wrong keep the certificate the server has.
TEST_F(SecureCliTest, SighupRenewsTheCertificate) {
  absl::StatusOr<TestCertificates> renewed = MakeTestCertificates(Path("renewed"));
  ASSERT_TRUE(renewed.ok()) << renewed.status();
  const std::string cert = Path("live_server.pem");
  const std::string key = Path("live_server.key");
  ASSERT_TRUE(WriteFileContents(cert, certs().server_chain).ok());
  ASSERT_TRUE(WriteFileContents(key, certs().server_key).ok());
  std::string error;
  std::unique_ptr<TestServer> server =
      TestServer::Start({"--tls_cert_file=" + cert, "--tls_key_file=" + key}, &error);
  ASSERT_NE(server, nullptr) << error;
  auto sessions_trusting = [&](const std::string& ca) {
    return RunNeuralmesh(
        {"sessions", "--server=" + server->address(), "--tls_ca_file=" + ca, "--connect_timeout=2s"});
  };
  EXPECT_EQ(sessions_trusting(certs().Path("ca.pem")).exit_code, 0);

  ASSERT_TRUE(WriteFileContents(cert, renewed->server_chain).ok());
  ASSERT_TRUE(WriteFileContents(key, renewed->server_key).ok());
  server->Signal(SIGHUP);
  server->AwaitStdout("TLS certificate and key read");
  EXPECT_THAT(server->Stdout(), HasSubstr("SIGHUP received; TLS certificate and key read again"));
  RunResult renewed_sessions;
  for (int i = 0; i < 20; ++i) {  // gRPC takes the new identity within a second.
    renewed_sessions = sessions_trusting(renewed->Path("ca.pem"));
    if (renewed_sessions.exit_code == 0) break;
    usleep(250 * 1000);
  }
  EXPECT_EQ(renewed_sessions.exit_code, 0) << renewed_sessions.Describe();
  const RunResult stale = sessions_trusting(certs().Path("ca.pem"));
  EXPECT_NE(stale.exit_code, 0);
  EXPECT_THAT(stale.err, HasSubstr("certificate verify failed")) << stale.Describe();

  // The old CA's key with the renewed certificate: refused, the renewed identity stays.
  ASSERT_TRUE(WriteFileContents(key, certs().server_key).ok());
  server->Signal(SIGHUP);
  server->AwaitStderr("stays");
  EXPECT_THAT(server->Stderr(), HasSubstr("the old TLS certificate stays: gRPC rejected the TLS "
                                          "certificate or key"));
  usleep(1500 * 1000);  // Past gRPC's next read of its copies.
  EXPECT_EQ(sessions_trusting(renewed->Path("ca.pem")).exit_code, 0);
}

TEST_F(SecureCliTest, SighupReadsTheTokensFileAgain) {
  const std::string tokens = Path("reloaded_tokens");
  ASSERT_TRUE(WriteFileContents(tokens, absl::StrCat(kToken, "\n")).ok());
  std::string error;
  std::unique_ptr<TestServer> server =
      TestServer::Start({"--tls_cert_file=" + certs().Path("server.pem"),
                         "--tls_key_file=" + certs().Path("server.key"),
                         "--access_tokens_file=" + tokens},
                        &error);
  ASSERT_NE(server, nullptr) << error;
  const std::vector<std::string> sessions = {"sessions", "--server=" + server->address(),
                                             "--tls_ca_file=" + certs().Path("ca.pem")};
  auto with_token = [&](const std::string& token_file) {
    std::vector<std::string> args = sessions;
    args.push_back("--access_token_file=" + token_file);
    return RunNeuralmesh(args);
  };
  EXPECT_EQ(with_token(Path("token")).exit_code, 0);
  EXPECT_NE(with_token(Path("wrong_token")).exit_code, 0);

  // The file now holds the other token: after SIGHUP it is the one accepted.
  ASSERT_TRUE(WriteFileContents(tokens, ReadWholeFile(Path("wrong_token"))).ok());
  server->Signal(SIGHUP);
  server->AwaitStdout("access tokens read again");
  EXPECT_THAT(server->Stdout(), HasSubstr("SIGHUP received; 1 access tokens read again"));
  EXPECT_EQ(with_token(Path("wrong_token")).exit_code, 0);
  const RunResult old_token = with_token(Path("token"));
  EXPECT_NE(old_token.exit_code, 0);
  EXPECT_THAT(old_token.err, HasSubstr("not one this server accepts"));

  // A file that went wrong keeps the tokens the server has.
  ASSERT_TRUE(WriteFileContents(tokens, "short\n").ok());
  server->Signal(SIGHUP);
  server->AwaitStderr("stay");
  EXPECT_THAT(server->Stderr(),
              HasSubstr("the old access tokens stay: --access_tokens_file: line 1"));
  EXPECT_EQ(with_token(Path("wrong_token")).exit_code, 0);
}

// Under mutual TLS, --client_roles_file gives each certificate's common name its role; SIGHUP
// reads the file again.
TEST_F(SecureCliTest, SighupReadsTheClientRolesFileAgain) {
  const std::string roles = Path("client_roles");
  ASSERT_TRUE(WriteFileContents(roles, "neuralmesh-test-client user\n").ok());
  std::string error;
  std::unique_ptr<TestServer> server =
      TestServer::Start({"--tls_cert_file=" + certs().Path("server.pem"),
                         "--tls_key_file=" + certs().Path("server.key"),
                         "--tls_client_ca_file=" + certs().Path("ca.pem"),
                         "--client_roles_file=" + roles},
                        &error);
  ASSERT_NE(server, nullptr) << error;
  EXPECT_THAT(server->Stdout(), HasSubstr("mutual TLS, clients named by their certificates, 1 "
                                          "with roles of their own, others refused"));
  auto as = [&](const std::string& certificate) {
    return RunNeuralmesh({"sessions", "--server=" + server->address(),
                          "--tls_ca_file=" + certs().Path("ca.pem"),
                          "--tls_cert_file=" + certs().Path(certificate + ".pem"),
                          "--tls_key_file=" + certs().Path(certificate + ".key")});
  };
  EXPECT_EQ(as("client").exit_code, 0);
  const RunResult unlisted = as("second_client");
  EXPECT_NE(unlisted.exit_code, 0);
  EXPECT_THAT(unlisted.err, HasSubstr("\"neuralmesh-test-second_client\" has no role"));

  ASSERT_TRUE(WriteFileContents(roles, "neuralmesh-test-client user\n"
                                       "neuralmesh-test-second_client reader\n")
                  .ok());
  server->Signal(SIGHUP);
  server->AwaitStdout("client roles read again");
  EXPECT_THAT(server->Stdout(), HasSubstr("SIGHUP received; 2 client roles read again"));
  EXPECT_EQ(as("second_client").exit_code, 0) << as("second_client").Describe();

  // A file that went wrong keeps the roles the server has.
  ASSERT_TRUE(WriteFileContents(roles, "neuralmesh-test-client owner\n").ok());
  server->Signal(SIGHUP);
  server->AwaitStderr("stay");
  EXPECT_THAT(server->Stderr(),
              HasSubstr("the old client roles stay: --client_roles_file: line 1: unknown role"));
  EXPECT_EQ(as("second_client").exit_code, 0);
}

TEST_F(SecureCliTest, TheMetricsPageOverHttpsAsksForItsTokenAndSighupReadsItAgain) {
  const std::string token_file = Path("metrics_token");
  ASSERT_TRUE(WriteFileContents(token_file, "metrics-token-0123456789\n").ok());
  std::string error;
  std::unique_ptr<TestServer> server =
      TestServer::Start({"--tls_cert_file=" + certs().Path("server.pem"),
                         "--tls_key_file=" + certs().Path("server.key"), "--metrics_port=0",
                         "--metrics_tls", "--metrics_token_file=" + token_file},
                        &error);
  ASSERT_NE(server, nullptr) << error;
  server->AwaitStdout("/metrics (with the token");
  std::smatch match;
  const std::string out = server->Stdout();
  ASSERT_TRUE(std::regex_search(
      out, match,
      std::regex("metrics on https://127\\.0\\.0\\.1:([0-9]+)/metrics \\(with the token of "
                 "--metrics_token_file\\)")))
      << out;
  HttpsTarget target;
  target.port = std::stoi(match[1].str());
  target.ca = certs().ca;
  const HttpReply scraped = HttpsGet(target, "/metrics", "metrics-token-0123456789", &error);
  EXPECT_EQ(scraped.status, 200) << error;
  EXPECT_THAT(scraped.body, HasSubstr("neuralmesh_sessions_limit "));
  EXPECT_EQ(HttpsGet(target, "/metrics").status, 401);

  ASSERT_TRUE(WriteFileContents(token_file, "metrics-token-renewed-42\n").ok());
  server->Signal(SIGHUP);
  server->AwaitStdout("metrics token read again");
  EXPECT_EQ(HttpsGet(target, "/metrics", "metrics-token-0123456789").status, 401);
  EXPECT_EQ(HttpsGet(target, "/metrics", "metrics-token-renewed-42").status, 200);

  // A file that went wrong keeps the token the page has.
  ASSERT_TRUE(WriteFileContents(token_file, "short\n").ok());
  server->Signal(SIGHUP);
  server->AwaitStderr("stays");
  EXPECT_THAT(server->Stderr(),
              HasSubstr("the old metrics token stays: --metrics_token_file: the metrics token "
                        "has 5 characters"));
  EXPECT_EQ(HttpsGet(target, "/metrics", "metrics-token-renewed-42").status, 200);
}

TEST_F(SecureCliTest, TheServerRefusesSecurityFlagsThatDoNotGoTogetherAndDocumentsThem) {
  const std::string cert = "--tls_cert_file=" + certs().Path("server.pem");
  const std::string key = "--tls_key_file=" + certs().Path("server.key");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const Case cases[] = {
      {{"--port=0", "--tls_cert_file=" + Path("missing.pem"), key}, "--tls_cert_file: cannot open"},
      {{"--port=0", cert}, "without its private key"},
      {{"--port=0", "--access_tokens_file=" + Path("tokens")}, "access tokens need TLS"},
      {{"--port=0", cert, key, "--access_tokens_file=" + certs().Path("ca.pem")},
       "--access_tokens_file: line 1"},
      {{"--port=0", cert, "--tls_key_file=" + certs().Path("client.key")},
       "rejected the TLS certificate or key"},
      {{"--port=0", "--metrics_port=0", "--metrics_tls"},
       "metrics_tls serves the metrics page with the server's TLS certificate, and there is "
       "none (tls_cert_file)"},
      {{"--port=0", "--metrics_token_file=" + Path("token")},
       "there is none (metrics_port)"},
      {{"--port=0", cert, key, "--metrics_port=0", "--metrics_tls",
        "--metrics_client_certificate"},
       "it needs metrics_tls and client CAs (tls_client_ca_file)"},
      {{"--port=0", "--metrics_port=0", "--metrics_token_file=" + certs().Path("ca.pem")},
       "--metrics_token_file: the metrics token may hold letters"},
      {{"--port=0", "--metrics_port=0", "--metrics_token_file=" + Path("missing")},
       "--metrics_token_file: cannot open"},
  };
  for (const Case& c : cases) {
    const RunResult run = RunBinary("neuralmesh-server", c.args);
    EXPECT_NE(run.exit_code, 0) << run.Describe();
    EXPECT_THAT(run.err, HasSubstr(c.message)) << run.Describe();
  }
  // --help documents them, with the server's other flags.
  const RunResult help = RunBinary("neuralmesh-server", {"--help"});
  for (const char* flag : {"--tls_cert_file", "--tls_key_file", "--tls_client_ca_file",
                           "--access_tokens_file", "--max_sessions", "--port", "--metrics_tls",
                           "--metrics_token_file", "--metrics_client_certificate"}) {
    EXPECT_THAT(help.out, HasSubstr(flag)) << help.Describe();
  }
}

}  // namespace
}  // namespace neuralmesh::testing
