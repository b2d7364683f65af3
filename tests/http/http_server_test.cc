#include "http/http_server.h"

#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "absl/synchronization/notification.h"
#include "absl/time/clock.h"
#include "tests/testing/http_client.h"

namespace neuralmesh::http {
namespace {

using ::neuralmesh::testing::HttpGet;
using ::neuralmesh::testing::HttpReply;
using ::testing::HasSubstr;

// A connected socket that has sent nothing yet.
int ConnectIdle(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  return fd;
}

HttpResponse Echo(const HttpRequest& request) { return TextResponse(200, request.path); }

TEST(HttpServerTest, AnswersEachRequestWithTheHandlersResponse) {
  absl::StatusOr<std::unique_ptr<HttpServer>> server = HttpServer::Start("127.0.0.1", 0, Echo);
  ASSERT_TRUE(server.ok()) << server.status();
  EXPECT_GT((*server)->port(), 0);
  const HttpReply reply = HttpGet((*server)->port(), "/a%20b?x=1");
  EXPECT_EQ(reply.status, 200);
  EXPECT_EQ(reply.body, "/a b\n");
  EXPECT_EQ(reply.Header("content-length"), "5");
  EXPECT_EQ(reply.Header("connection"), "close");
}

TEST(HttpServerTest, RefusesBadAddresses) {
  EXPECT_EQ(HttpServer::Start("127.0.0.1", 70000, Echo).status().code(),
            absl::StatusCode::kInvalidArgument);
  const absl::Status unresolved = HttpServer::Start("no.such.host.invalid", 0, Echo).status();
  EXPECT_EQ(unresolved.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(unresolved.message(), HasSubstr("cannot resolve host \"no.such.host.invalid\""));
  absl::StatusOr<std::unique_ptr<HttpServer>> first = HttpServer::Start("127.0.0.1", 0, Echo);
  ASSERT_TRUE(first.ok());
  const absl::Status taken = HttpServer::Start("127.0.0.1", (*first)->port(), Echo).status();
  EXPECT_EQ(taken.code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(taken.message(), HasSubstr("cannot listen on 127.0.0.1:"));
}

TEST(HttpServerTest, AnswersBeyondItsConnectionLimitWithServiceUnavailable) {
  HttpServerOptions options;
  options.max_connections = 1;
  absl::StatusOr<std::unique_ptr<HttpServer>> server =
      HttpServer::Start("127.0.0.1", 0, Echo, options);
  ASSERT_TRUE(server.ok());
  const int idle = ConnectIdle((*server)->port());
  absl::SleepFor(absl::Milliseconds(100));  // Accepted: it holds the only slot.
  HttpReply reply = HttpGet((*server)->port(), "/");
  EXPECT_EQ(reply.status, 503);
  EXPECT_THAT(reply.body, HasSubstr("at most 1 connections"));
  close(idle);
  for (int i = 0; i < 50 && reply.status != 200; ++i) {
    absl::SleepFor(absl::Milliseconds(20));
    reply = HttpGet((*server)->port(), "/");
  }
  EXPECT_EQ(reply.status, 200) << "the slot is free again once the idle client left";
}

TEST(HttpServerTest, DropsAClientWhoseRequestHeadIsNotInWithinTheReadTimeout) {
  HttpServerOptions options;
  options.read_timeout = absl::Milliseconds(500);
  absl::StatusOr<std::unique_ptr<HttpServer>> server =
      HttpServer::Start("127.0.0.1", 0, Echo, options);
  ASSERT_TRUE(server.ok());
  // Nothing at all.
  const int idle = ConnectIdle((*server)->port());
  absl::Time start = absl::Now();
  char byte;
  EXPECT_EQ(recv(idle, &byte, 1, 0), 0) << "closed without an answer";
  EXPECT_LT(absl::Now() - start, absl::Seconds(5));
  close(idle);

  // A byte every 100 ms: each comes well within the timeout, the whole head never does.
  const int slow = ConnectIdle((*server)->port());
  const std::string request = "GET /trickled HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
  start = absl::Now();
  size_t sent = 0;
  for (; sent < request.size(); ++sent) {
    if (send(slow, &request[sent], 1, MSG_NOSIGNAL) != 1) break;
    absl::SleepFor(absl::Milliseconds(100));
    pollfd closed{slow, POLLIN, 0};
    if (poll(&closed, 1, 0) == 1) break;  // The server has given up on it.
  }
  EXPECT_LE(recv(slow, &byte, 1, 0), 0) << "closed without an answer";
  EXPECT_LT(sent, request.size()) << "the server waited for the whole trickled head";
  EXPECT_LT(absl::Now() - start, absl::Seconds(3));
  close(slow);
  // A client that sends its request at once is answered as before.
  EXPECT_EQ(HttpGet((*server)->port(), "/prompt").body, "/prompt\n");
}

TEST(HttpServerTest, ShutdownWaitsForTheHandlersInFlightAndClosesIdleConnections) {
  absl::Notification entered;
  absl::Notification release;
  std::atomic<bool> finished{false};
  absl::StatusOr<std::unique_ptr<HttpServer>> server =
      HttpServer::Start("127.0.0.1", 0, [&](const HttpRequest& request) {
        entered.Notify();
        release.WaitForNotification();
        finished = true;
        return TextResponse(200, "late");
      });
  ASSERT_TRUE(server.ok());
  const int port = (*server)->port();
  const int idle = ConnectIdle(port);
  HttpReply reply;
  std::thread client([&] { reply = HttpGet(port, "/slow"); });
  entered.WaitForNotification();
  std::thread shutdown([&] { (*server)->Shutdown(); });
  absl::SleepFor(absl::Milliseconds(100));
  EXPECT_FALSE(finished) << "the handler is still running";
  release.Notify();
  shutdown.join();
  EXPECT_TRUE(finished) << "Shutdown returned only after the handler";
  client.join();
  char byte;
  EXPECT_LE(recv(idle, &byte, 1, 0), 0) << "the idle connection was shut down";
  close(idle);
  EXPECT_EQ(HttpGet(port, "/").status, 0) << "no longer listening";
}

}  // namespace
}  // namespace neuralmesh::http
