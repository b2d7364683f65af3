// `neuralmesh view` as a user runs it: its error messages and exit codes, and a run against a
// neuralmesh-server that serves the API and stops on SIGTERM.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>
#include <string>

#include "tests/client/subprocess.h"
#include "tests/client/test_server.h"
#include "tests/client/web/viewer_test_support.h"

namespace neuralmesh::testing {
namespace {

using ::testing::HasSubstr;

TEST(NeuralmeshViewTest, BadArgumentsGetAMessageAndAFailingExit) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const Case cases[] = {
      {{"view"}, "--server HOST:PORT is required"},
      {{"view", "extra", "--server=127.0.0.1:1"}, "unexpected argument 'extra'"},
      {{"view", "--server=127.0.0.1:1", "--listen=8080"}, "is not HOST:PORT"},
      {{"view", "--server=127.0.0.1:1", "--listen=127.0.0.1:99999"}, "is not HOST:PORT"},
      {{"view", "--server=127.0.0.1:1", "--web_root=/nonexistent"},
       "/nonexistent/static/index.html is missing: run scripts/install-deps.sh"},
      {{"view", "--server=127.0.0.1:1", "--connect_timeout=200ms"},
       "cannot reach a neuralmesh-server at 127.0.0.1:1"},
      {{"view", "--server=127.0.0.1:1", "--view_key_file=/nonexistent/key"},
       "--view_key_file: cannot open '/nonexistent/key'"},
      {{"view", "--server=127.0.0.1:1", "--view_key_file=/dev/null"},
       "--view_key_file: '/dev/null' is empty"},
  };
  for (const Case& c : cases) {
    const RunResult run = RunNeuralmesh(c.args);
    EXPECT_NE(run.exit_code, 0) << run.Describe();
    EXPECT_THAT(run.err, HasSubstr(c.message)) << run.Describe();
  }
}

TEST(NeuralmeshViewTest, ServesTheSessionsOfTheServerUntilSigterm) {
  std::string error;
  std::unique_ptr<TestServer> server = TestServer::Start({}, &error);
  ASSERT_NE(server, nullptr) << error;
  BackgroundProcess viewer("neuralmesh",
                           {"view", "--server=" + server->address(), "--listen=127.0.0.1:0"});
  const int port = WaitForViewerPort(viewer);
  ASSERT_NE(port, 0) << viewer.Stderr();
  const RunResult busy = RunNeuralmesh(
      {"view", "--server=" + server->address(), "--listen=127.0.0.1:" + std::to_string(port)});
  EXPECT_NE(busy.exit_code, 0);
  EXPECT_THAT(busy.err, HasSubstr("cannot listen on 127.0.0.1:" + std::to_string(port)));

  const HttpReply sessions = HttpGet(port, "/api/sessions");
  EXPECT_EQ(sessions.status, 200);
  EXPECT_EQ(sessions.body, "[]");
  EXPECT_EQ(HttpGet(port, "/").status, 200);
  EXPECT_EQ(viewer.SignalAndWait(SIGTERM), 0) << viewer.Stderr();
}

}  // namespace
}  // namespace neuralmesh::testing
