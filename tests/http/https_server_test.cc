// HttpServer over TLS (HttpServerOptions::tls): the handshake with a client that checks the
// certificate, client certificates, a renewed certificate for new connections, plain HTTP on the HTTPS port, stalled
// handshakes at shutdown, and the certificate and key files TlsServerContext refuses.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>
#include <string>

#include "absl/time/clock.h"
#include "http/http_server.h"
#include "http/tls_server_context.h"
#include "tests/testing/http_client.h"
#include "tests/testing/https_client.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::http {
namespace {

using ::neuralmesh::testing::HttpGet;
using ::neuralmesh::testing::HttpReply;
using ::neuralmesh::testing::HttpsGet;
using ::neuralmesh::testing::HttpsTarget;
using ::neuralmesh::testing::TestCertificates;
using ::testing::HasSubstr;
using ::testing::StartsWith;

HttpResponse Echo(const HttpRequest& request) { return TextResponse(200, request.path); }

class HttpsServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    absl::StatusOr<TestCertificates> made =
        testing::MakeTestCertificates(testing::MakeTempDir("https"));
    ASSERT_TRUE(made.ok()) << made.status();
    certificates_ = new TestCertificates(*std::move(made));
  }
  static void TearDownTestSuite() {
    delete certificates_;
    certificates_ = nullptr;
  }

  static std::shared_ptr<const TlsServerContext> Context(const std::string& chain,
                                                         const std::string& key) {
    absl::StatusOr<std::shared_ptr<const TlsServerContext>> context =
        TlsServerContext::Create(chain, key);
    EXPECT_TRUE(context.ok()) << context.status();
    return context.ok() ? *context : nullptr;
  }

  // An HTTPS server of Echo with the certificate for 127.0.0.1 and localhost.
  static std::unique_ptr<HttpServer> StartHttps(HttpServerOptions options = {}) {
    options.tls = Context(certificates_->server_chain, certificates_->server_key);
    absl::StatusOr<std::unique_ptr<HttpServer>> server =
        HttpServer::Start("127.0.0.1", 0, Echo, options);
    EXPECT_TRUE(server.ok()) << server.status();
    return server.ok() ? *std::move(server) : nullptr;
  }

  static HttpsTarget Target(int port, const std::string& ca, const std::string& host) {
    HttpsTarget target;
    target.port = port;
    target.ca = ca;
    target.host = host;
    return target;
  }

  static inline const TestCertificates* certificates_ = nullptr;
};

TEST_F(HttpsServerTest, AnswersOverTlsToAClientThatChecksTheCertificate) {
  std::unique_ptr<HttpServer> server = StartHttps();
  ASSERT_NE(server, nullptr);
  EXPECT_STREQ(server->scheme(), "https");
  std::string error;
  const HttpReply reply =
      HttpsGet(Target(server->port(), certificates_->ca, "127.0.0.1"), "/a%20b", "", &error);
  EXPECT_EQ(reply.status, 200) << error;
  EXPECT_EQ(reply.body, "/a b\n");
  EXPECT_EQ(HttpsGet(Target(server->port(), certificates_->ca, "localhost"), "/x").status, 200);

  // A client that trusts another CA, or wants another name, ends the handshake; the server
  // goes on serving others.
  const HttpReply untrusted =
      HttpsGet(Target(server->port(), certificates_->other_ca, "127.0.0.1"), "/", "", &error);
  EXPECT_EQ(untrusted.status, 0);
  EXPECT_THAT(error, HasSubstr("certificate verify failed"));
  EXPECT_EQ(
      HttpsGet(Target(server->port(), certificates_->ca, "scans.example.test"), "/", "", &error)
          .status,
      0);
  EXPECT_THAT(error, HasSubstr("certificate verify failed"));
  EXPECT_EQ(HttpsGet(Target(server->port(), certificates_->ca, "127.0.0.1"), "/again").body,
            "/again\n");

  absl::StatusOr<std::unique_ptr<HttpServer>> plain = HttpServer::Start("127.0.0.1", 0, Echo);
  ASSERT_TRUE(plain.ok());
  EXPECT_STREQ((*plain)->scheme(), "http");
}

TEST_F(HttpsServerTest, APlainHttpRequestIsToldThatThePortSpeaksHttps) {
  std::unique_ptr<HttpServer> server = StartHttps();
  ASSERT_NE(server, nullptr);
  const HttpReply reply = HttpGet(server->port(), "/metrics");
  EXPECT_EQ(reply.status, 400);
  EXPECT_EQ(reply.body, "this port speaks HTTPS only: use an https:// address\n");
}

TEST_F(HttpsServerTest, NewConnectionsGetTheReplacedCertificate) {
  HttpServerOptions options;
  options.tls = Context(certificates_->named_server_chain, certificates_->named_server_key);
  absl::StatusOr<std::unique_ptr<HttpServer>> server =
      HttpServer::Start("127.0.0.1", 0, Echo, options);
  ASSERT_TRUE(server.ok()) << server.status();
  const int port = (*server)->port();
  std::string error;
  EXPECT_EQ(HttpsGet(Target(port, certificates_->ca, "scans.example.test"), "/", "", &error).status,
            200)
      << error;
  EXPECT_EQ(HttpsGet(Target(port, certificates_->ca, "127.0.0.1"), "/").status, 0);

  ASSERT_TRUE(
      (*server)->ReplaceTls(Context(certificates_->server_chain, certificates_->server_key)).ok());
  EXPECT_EQ(HttpsGet(Target(port, certificates_->ca, "127.0.0.1"), "/", "", &error).status, 200)
      << error;
  EXPECT_EQ(HttpsGet(Target(port, certificates_->ca, "scans.example.test"), "/").status, 0);

  EXPECT_EQ((*server)->ReplaceTls(nullptr).code(), absl::StatusCode::kInvalidArgument);
  absl::StatusOr<std::unique_ptr<HttpServer>> plain = HttpServer::Start("127.0.0.1", 0, Echo);
  ASSERT_TRUE(plain.ok());
  const absl::Status refused =
      (*plain)->ReplaceTls(Context(certificates_->server_chain, certificates_->server_key));
  EXPECT_EQ(refused.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(refused.message(), "this HTTP server was started without TLS");
}

// With client CAs the server asks for a client certificate: one those CAs signed is marked on
// the request, none is let through unmarked, and one signed by another CA ends the handshake.
TEST_F(HttpsServerTest, AClientCertificateSignedByTheClientCaIsMarkedOnTheRequest) {
  HttpServerOptions options;
  absl::StatusOr<std::shared_ptr<const TlsServerContext>> context = TlsServerContext::Create(
      certificates_->server_chain, certificates_->server_key, certificates_->ca);
  ASSERT_TRUE(context.ok()) << context.status();
  options.tls = *context;
  const auto handler = [](const HttpRequest& request) {
    return TextResponse(200, request.client_certificate ? "certificate" : "none");
  };
  absl::StatusOr<std::unique_ptr<HttpServer>> server =
      HttpServer::Start("127.0.0.1", 0, handler, options);
  ASSERT_TRUE(server.ok()) << server.status();
  HttpsTarget target = Target((*server)->port(), certificates_->ca, "127.0.0.1");
  std::string error;
  HttpReply reply = HttpsGet(target, "/", "", &error);
  EXPECT_EQ(reply.status, 200) << error;
  EXPECT_EQ(reply.body, "none\n");

  target.client_chain = certificates_->client_chain;
  target.client_key = certificates_->client_key;
  reply = HttpsGet(target, "/", "", &error);
  EXPECT_EQ(reply.status, 200) << error;
  EXPECT_EQ(reply.body, "certificate\n");

  target.client_chain = certificates_->other_client_chain;
  target.client_key = certificates_->other_client_key;
  EXPECT_EQ(HttpsGet(target, "/", "", &error).status, 0) << "another CA's client was let in";

  // Without client CAs no certificate is asked for, so none is marked.
  std::unique_ptr<HttpServer> plain_tls = StartHttps();
  ASSERT_NE(plain_tls, nullptr);
  HttpsTarget unasked = Target(plain_tls->port(), certificates_->ca, "127.0.0.1");
  unasked.client_chain = certificates_->client_chain;
  unasked.client_key = certificates_->client_key;
  EXPECT_EQ(HttpsGet(unasked, "/x").body, "/x\n");
}

TEST_F(HttpsServerTest, ShutdownEndsAHandshakeThatStalls) {
  HttpServerOptions options;
  options.read_timeout = absl::Minutes(5);
  std::unique_ptr<HttpServer> server = StartHttps(options);
  ASSERT_NE(server, nullptr);
  // The first byte of a handshake record, and then nothing: the server waits in SSL_accept.
  const int fd = testing::ConnectToLoopback(server->port());
  ASSERT_GE(fd, 0);
  const char handshake = 0x16;
  ASSERT_EQ(send(fd, &handshake, 1, MSG_NOSIGNAL), 1);
  absl::SleepFor(absl::Milliseconds(200));
  const absl::Time start = absl::Now();
  server->Shutdown();
  EXPECT_LT(absl::Now() - start, absl::Minutes(1)) << "Shutdown waited for the read timeout";
  char byte;
  EXPECT_LE(recv(fd, &byte, 1, 0), 0) << "the connection is closed";
  close(fd);
}

TEST_F(HttpsServerTest, TlsServerContextSaysWhichPartIsWrong) {
  const auto message = [](const std::string& chain, const std::string& key) {
    absl::StatusOr<std::shared_ptr<const TlsServerContext>> context =
        TlsServerContext::Create(chain, key);
    EXPECT_EQ(context.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(context.status().message());
  };
  EXPECT_EQ(message("", certificates_->server_key),
            "the TLS certificate file holds no PEM certificate");
  EXPECT_EQ(message(certificates_->server_chain, certificates_->server_chain),
            "the TLS key file holds no PEM private key");
  EXPECT_THAT(message("-----BEGIN CERTIFICATE-----\nnot base64\n-----END CERTIFICATE-----\n",
                      certificates_->server_key),
              StartsWith("the TLS certificate cannot be read: "));
  EXPECT_THAT(message(certificates_->server_chain,
                      "-----BEGIN PRIVATE KEY-----\nAAAA\n-----END PRIVATE KEY-----\n"),
              StartsWith("the TLS private key cannot be read: "));
  EXPECT_THAT(message(certificates_->server_chain, certificates_->client_key),
              StartsWith("the TLS private key does not belong to the certificate: "));
  const auto client_ca_message = [](const std::string& client_ca) {
    absl::StatusOr<std::shared_ptr<const TlsServerContext>> context = TlsServerContext::Create(
        certificates_->server_chain, certificates_->server_key, client_ca);
    EXPECT_EQ(context.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(context.status().message());
  };
  EXPECT_EQ(client_ca_message(certificates_->server_key),
            "the client CA file holds no PEM certificate");
  EXPECT_EQ(client_ca_message("-----BEGIN CERTIFICATE-----\nnot base64\n-----END CERTIFICATE-----\n"),
            "the client CA certificates cannot be read");
  // A chain with an intermediate after the leaf (here the CA itself) is taken.
  EXPECT_TRUE(TlsServerContext::Create(certificates_->server_chain + certificates_->ca,
                                       certificates_->server_key)
                  .ok());
}

}  // namespace
}  // namespace neuralmesh::http
