// neuralmesh-server --state_dir end to end: a server killed (SIGKILL) in the middle of a
// `neuralmesh reconstruct --server` run and started again on the same port and state directory
// restores the session, and the client, reconnecting by itself, finishes the reconstruction
// with every point once. Both run as subprocesses on 127.0.0.1.
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "client/reconstruction_client.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/client/subprocess.h"
#include "tests/client/test_server.h"

namespace neuralmesh::testing {
namespace {

constexpr uint64_t kPoints = 4000000;

// The points the server's one session has taken (0 before it exists or cannot be asked).
uint64_t PointsTaken(const std::string& address) {
  client::ClientOptions options;
  options.connect_timeout = absl::Milliseconds(200);
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(address, options);
  if (!service.ok()) return 0;
  absl::StatusOr<std::vector<v1::Session>> sessions = (*service)->ListSessions();
  if (!sessions.ok() || sessions->empty()) return 0;
  return sessions->front().points_taken();
}

TEST(RemoteCliRestartTest, AServerStartedAgainOnItsStateDirectoryLetsTheRunFinish) {
  const std::string state_dir = MakeTempDir("cli_restart_state");
  const std::string out_dir = MakeTempDir("cli_restart_out");
  std::string error;
  std::unique_ptr<TestServer> server = TestServer::Start({"--state_dir=" + state_dir}, &error);
  ASSERT_NE(server, nullptr) << error;
  const std::string address = server->address();
  const std::string port = address.substr(address.rfind(':') + 1);

  BackgroundProcess run("neuralmesh",
                        {"reconstruct", "builtin:sphere", "--server", address, "--out-dir",
                         out_dir, "--points", std::to_string(kPoints), "--batch-size", "20000",
                         "--vertices", "2000"});
  // Killed as soon as the session has points: in the middle of the upload, as a rule.
  uint64_t taken_before_kill = 0;
  const absl::Time start = absl::Now();
  while (run.Running() && absl::Now() - start < absl::Seconds(30)) {
    taken_before_kill = PointsTaken(address);
    if (taken_before_kill > 0) break;
    usleep(10 * 1000);
  }
  ASSERT_GT(taken_before_kill, 0u) << "the session never took a point: " << run.Stderr();
  server->Signal(SIGKILL);
  usleep(300 * 1000);

  std::unique_ptr<TestServer> again =
      TestServer::Start({"--state_dir=" + state_dir, "--port=" + port}, &error);
  ASSERT_NE(again, nullptr) << error;
  // It listens at once and reports the restore when it ends.
  const absl::Time restarted = absl::Now();
  while (!absl::StrContains(again->Stdout(), "restored from") &&
         absl::Now() - restarted < absl::Seconds(60)) {
    usleep(10 * 1000);
  }
  EXPECT_THAT(again->Stdout(), ::testing::HasSubstr("1 sessions ("));
  while (run.Running() && absl::Now() - restarted < absl::Seconds(120)) usleep(50 * 1000);
  ASSERT_FALSE(run.Running()) << "the run did not end: " << run.Stderr();
  ASSERT_EQ(run.exit_code(), 0) << run.Stderr();
  EXPECT_THAT(run.Stderr(), ::testing::HasSubstr("lost (")) << run.Stderr();
  EXPECT_THAT(run.Stderr(), ::testing::HasSubstr("reconnected")) << run.Stderr();
  EXPECT_THAT(run.Stderr(), ::testing::HasSubstr("reconnected: the upload into session"))
      << "the server was killed after the upload: " << run.Stderr();

  // The restored session took every point once and learned the sphere.
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(again->address());
  ASSERT_TRUE(service.ok()) << service.status();
  absl::StatusOr<std::vector<v1::Session>> sessions = (*service)->ListSessions();
  ASSERT_TRUE(sessions.ok()) << sessions.status();
  ASSERT_EQ(sessions->size(), 1u);
  const v1::Session& done = sessions->front();
  EXPECT_EQ(done.state(), v1::SESSION_STATE_FINISHED) << done.error();
  EXPECT_EQ(done.points_taken(), kPoints);
  EXPECT_EQ(done.learning().points_received(), kPoints) << "every point once";
  EXPECT_THAT(again->Stdout(), ::testing::HasSubstr("restored after a restart"));
  const RunResult eval =
      RunNeuralmesh({"eval", out_dir + "/sphere.drc", "--reference", "builtin:sphere", "--json"});
  ASSERT_EQ(eval.exit_code, 0) << eval.Describe();
  const size_t at = eval.out.find("\"hausdorff\": ");
  ASSERT_NE(at, std::string::npos) << eval.out;
  double hausdorff = 1;
  ASSERT_TRUE(absl::SimpleAtod(eval.out.substr(at + 13, eval.out.find_first_of(",\n", at) -
                                                            at - 13),
                               &hausdorff))
      << eval.out;
  EXPECT_LT(hausdorff, 0.05);
}

}  // namespace
}  // namespace neuralmesh::testing
