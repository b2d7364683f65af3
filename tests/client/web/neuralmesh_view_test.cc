// `neuralmesh view` as a user runs it: its error messages and exit codes, and a run against a
// neuralmesh-server that serves the API and stops on SIGTERM.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>
#include <cstdio>
#include <string>

#include "core/io/file_contents.h"
#include "tests/client/subprocess.h"
#include "tests/client/test_server.h"
#include "tests/client/web/viewer_test_support.h"
#include "tests/testing/http_client.h"
#include "tests/testing/https_client.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

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

// A GET of `path` with `header` ("Name: value") over plain HTTP.
HttpReply GetWith(int port, const std::string& path, const std::string& header) {
  return SendRawHttp(port, "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" + header +
                               "\r\n\r\n");
}

// SIGHUP reads --view_key_file again: the new key lets browsers in, the old key and its cookie
// no longer do; a file that holds no key leaves the key as it was.
TEST(NeuralmeshViewTest, SighupReadsTheViewerKeyAgain) {
  std::string error;
  std::unique_ptr<TestServer> server = TestServer::Start({}, &error);
  ASSERT_NE(server, nullptr) << error;
  BackgroundProcess unkeyed("neuralmesh",
                            {"view", "--server=" + server->address(), "--listen=127.0.0.1:0"});
  ASSERT_NE(WaitForViewerPort(unkeyed), 0) << unkeyed.Stderr();
  unkeyed.Signal(SIGHUP);
  EXPECT_TRUE(unkeyed.AwaitStdout(
      "SIGHUP received; no HTTPS certificate or viewer key to read again"))
      << unkeyed.Stdout() << unkeyed.Stderr();
  EXPECT_EQ(unkeyed.SignalAndWait(SIGTERM), 0) << unkeyed.Stderr();

  const std::string old_key = "first-key-0123456789", new_key = "second-key-9876543210";
  const std::string key_file = MakeTempDir("view_key_reload") + "/key";
  ASSERT_TRUE(WriteFileContents(key_file, old_key + "\n").ok());
  BackgroundProcess viewer("neuralmesh", {"view", "--server=" + server->address(),
                                          "--listen=127.0.0.1:0", "--view_key_file=" + key_file});
  const int port = WaitForViewerPort(viewer);
  ASSERT_NE(port, 0) << viewer.Stderr();
  const HttpReply opened = HttpGet(port, "/?key=" + old_key);
  ASSERT_EQ(opened.status, 303);
  const std::string set_cookie = opened.Header("set-cookie");
  const std::string old_cookie = "Cookie: " + set_cookie.substr(0, set_cookie.find(';'));
  EXPECT_EQ(GetWith(port, "/api/sessions", old_cookie).status, 200);
  EXPECT_EQ(GetWith(port, "/api/sessions", "Authorization: Bearer " + new_key).status, 401);

  ASSERT_TRUE(WriteFileContents(key_file, new_key).ok());
  viewer.Signal(SIGHUP);
  EXPECT_TRUE(viewer.AwaitStdout("SIGHUP received; viewer key read again: browsers open http://"
                                 "127.0.0.1:" + std::to_string(port) + "/?key=" + new_key))
      << viewer.Stdout() << viewer.Stderr();
  EXPECT_EQ(GetWith(port, "/api/sessions", "Authorization: Bearer " + new_key).status, 200);
  EXPECT_EQ(GetWith(port, "/api/sessions", "Authorization: Bearer " + old_key).status, 401);
  EXPECT_EQ(GetWith(port, "/api/sessions", old_cookie).status, 401);
  EXPECT_EQ(HttpGet(port, "/?key=" + old_key).status, 401);
  EXPECT_EQ(HttpGet(port, "/?key=" + new_key).status, 303);

  // A key too short, then no file: refused, and the key read last stays.
  ASSERT_TRUE(WriteFileContents(key_file, "short").ok());
  viewer.Signal(SIGHUP);
  EXPECT_TRUE(viewer.AwaitStderr("SIGHUP received; the old viewer key stays: --view_key_file: "))
      << viewer.Stderr();
  ASSERT_EQ(std::remove(key_file.c_str()), 0);
  viewer.Signal(SIGHUP);
  EXPECT_TRUE(viewer.AwaitStderr("cannot open '" + key_file + "'")) << viewer.Stderr();
  EXPECT_EQ(GetWith(port, "/api/sessions", "Authorization: Bearer " + new_key).status, 200);
  EXPECT_EQ(GetWith(port, "/api/sessions", "Authorization: Bearer short").status, 401);
  EXPECT_EQ(viewer.SignalAndWait(SIGTERM), 0) << viewer.Stderr();
}

TEST(NeuralmeshViewTest, ServesHttpsWithItsCertificateAndKeepsTheKeyOffPlainHttp) {
  const std::string dir = MakeTempDir("view_tls");
  absl::StatusOr<TestCertificates> certificates = MakeTestCertificates(dir + "/first");
  ASSERT_TRUE(certificates.ok()) << certificates.status();
  // Files the viewer reads again on SIGHUP, below.
  const std::string cert_file = dir + "/live.pem", key_file_tls = dir + "/live.key";
  ASSERT_TRUE(WriteFileContents(cert_file, certificates->server_chain).ok());
  ASSERT_TRUE(WriteFileContents(key_file_tls, certificates->server_key).ok());
  const std::string cert = "--view_tls_cert_file=" + cert_file;
  const std::string key = "--view_tls_key_file=" + key_file_tls;

  // A certificate without its key, or with another's, is refused before anything is served.
  RunResult run = RunNeuralmesh({"view", "--server=127.0.0.1:1", cert});
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.err, HasSubstr("HTTPS needs both a certificate (--view_tls_cert_file) and its "
                                 "key (--view_tls_key_file)"));
  run = RunNeuralmesh({"view", "--server=127.0.0.1:1", cert,
                       "--view_tls_key_file=" + certificates->Path("client.key")});
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.err, HasSubstr("the TLS private key does not belong to the certificate"));
  run = RunNeuralmesh({"view", "--server=127.0.0.1:1", cert, "--view_tls_key_file=/nonexistent"});
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.err, HasSubstr("--view_tls_key_file: cannot open '/nonexistent'"));

  std::string error;
  std::unique_ptr<TestServer> server = TestServer::Start({}, &error);
  ASSERT_NE(server, nullptr) << error;
  const std::string key_file = MakeTempDir("view_tls_key") + "/key";
  ASSERT_TRUE(WriteFileContents(key_file, "view-key-0123456789abcdef\n").ok());
  BackgroundProcess viewer("neuralmesh", {"view", "--server=" + server->address(),
                                          "--listen=127.0.0.1:0", cert, key,
                                          "--view_key_file=" + key_file});
  const int port = WaitForViewerPort(viewer, "https");
  ASSERT_NE(port, 0) << viewer.Stdout() << viewer.Stderr();
  HttpsTarget target;
  target.port = port;
  target.ca = certificates->ca;

  const HttpReply sessions =
      HttpsGet(target, "/api/sessions", "view-key-0123456789abcdef", &error);
  EXPECT_EQ(sessions.status, 200) << error;
  EXPECT_EQ(sessions.body, "[]");
  // The key in the URL becomes a cookie that browsers send over HTTPS only.
  const HttpReply redirect = HttpsGet(target, "/?key=view-key-0123456789abcdef");
  EXPECT_EQ(redirect.status, 303);
  EXPECT_THAT(redirect.Header("set-cookie"), HasSubstr("; Secure"));
  EXPECT_EQ(HttpsGet(target, "/api/sessions").status, 401);
  EXPECT_EQ(HttpGet(port, "/api/sessions").status, 400) << "plain HTTP on the HTTPS port";

  // A renewed certificate written over the files applies after SIGHUP, without a restart.
  absl::StatusOr<TestCertificates> renewed = MakeTestCertificates(dir + "/renewed");
  ASSERT_TRUE(renewed.ok()) << renewed.status();
  ASSERT_TRUE(WriteFileContents(cert_file, renewed->server_chain).ok());
  ASSERT_TRUE(WriteFileContents(key_file_tls, renewed->server_key).ok());
  viewer.Signal(SIGHUP);
  EXPECT_TRUE(viewer.AwaitStdout("SIGHUP received; HTTPS certificate and key read again"))
      << viewer.Stdout() << viewer.Stderr();
  HttpsTarget renewed_target = target;
  renewed_target.ca = renewed->ca;
  EXPECT_EQ(HttpsGet(renewed_target, "/api/sessions", "view-key-0123456789abcdef", &error).status,
            200)
      << error;
  std::string stale_error;
  EXPECT_EQ(HttpsGet(target, "/api/sessions", "", &stale_error).status, 0)
      << "the old certificate is still served";
  EXPECT_THAT(stale_error, HasSubstr("certificate verify failed"));
  // Another certificate's key: refused, the renewed certificate stays.
  ASSERT_TRUE(WriteFileContents(key_file_tls, certificates->server_key).ok());
  viewer.Signal(SIGHUP);
  EXPECT_TRUE(viewer.AwaitStderr("the old HTTPS certificate stays: "));
  EXPECT_THAT(viewer.Stderr(), HasSubstr("the TLS private key does not belong to the certificate"));
  EXPECT_EQ(HttpsGet(renewed_target, "/api/sessions", "view-key-0123456789abcdef").status, 200);
  EXPECT_EQ(viewer.SignalAndWait(SIGTERM), 0) << viewer.Stderr();
}

}  // namespace
}  // namespace neuralmesh::testing
