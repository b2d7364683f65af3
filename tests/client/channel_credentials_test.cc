// client/channel_credentials.h: which parts go together, and the client connecting to servers
// secured with TLS, mutual TLS and access tokens (in-process servers on 127.0.0.1, throw-away
// certificates).
#include "client/channel_credentials.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <memory>
#include <string>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "client/reconstruction_client.h"
#include "core/io/draco_codec.h"
#include "server/server.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::client {
namespace {

constexpr char kToken[] = "client-test-token-0123456789";

TEST(MakeChannelCredentialsTest, RefusesPartsThatDoNotGoTogether) {
  struct Case {
    const char* what;
    ClientSecurity security;
    const char* message;
  };
  ClientSecurity token_without_tls;
  token_without_tls.access_token = kToken;
  ClientSecurity ca_without_tls;
  ca_without_tls.tls.root_certificates = "-----BEGIN CERTIFICATE-----";
  ClientSecurity certificate_without_key;
  certificate_without_key.tls.enabled = true;
  certificate_without_key.tls.certificate_chain = "-----BEGIN CERTIFICATE-----";
  ClientSecurity key_without_certificate;
  key_without_certificate.tls.enabled = true;
  key_without_certificate.tls.private_key = "-----BEGIN PRIVATE KEY-----";
  ClientSecurity ca_not_pem;
  ca_not_pem.tls.enabled = true;
  ca_not_pem.tls.root_certificates = "MIIB";
  ClientSecurity name_without_tls;
  name_without_tls.tls.server_name = "scans.example.test";
  ClientSecurity token_with_space;
  token_with_space.tls.enabled = true;
  token_with_space.access_token = "two words";
  for (const Case& c : {Case{"token without TLS", token_without_tls, "needs TLS"},
                        Case{"CA without TLS", ca_without_tls, "without TLS"},
                        Case{"certificate alone", certificate_without_key, "private key"},
                        Case{"key alone", key_without_certificate, "private key"},
                        Case{"CA not PEM", ca_not_pem, "not PEM"},
                        Case{"server name without TLS", name_without_tls, "without TLS"},
                        Case{"token with a space", token_with_space, "printable ASCII"}}) {
    absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> credentials =
        MakeChannelCredentials(c.security);
    ASSERT_FALSE(credentials.ok()) << c.what;
    EXPECT_TRUE(absl::IsInvalidArgument(credentials.status())) << c.what;
    EXPECT_TRUE(absl::StrContains(credentials.status().message(), c.message))
        << c.what << ": " << credentials.status();
  }
  EXPECT_TRUE(MakeChannelCredentials({}).ok()) << "plaintext";
}

class SecureConnectionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    absl::StatusOr<testing::TestCertificates> made = testing::MakeTestCertificates(
        testing::MakeTempDir("tls"));
    ASSERT_TRUE(made.ok()) << made.status();
    certificates_ = new testing::TestCertificates(*std::move(made));
  }
  static void TearDownTestSuite() {
    delete certificates_;
    certificates_ = nullptr;
  }
  static const testing::TestCertificates& certs() { return *certificates_; }

  // A server on 127.0.0.1 with mutual TLS when `mutual`, and the access token kToken; with
  // `named`, its certificate names scans.example.test only.
  static std::unique_ptr<server::ReconstructionServer> StartServer(bool mutual,
                                                                   bool named = false) {
    server::ServerOptions options;
    options.security.tls.certificate_chain =
        named ? certs().named_server_chain : certs().server_chain;
    options.security.tls.private_key = named ? certs().named_server_key : certs().server_key;
    if (mutual) options.security.tls.client_ca_certificates = certs().ca;
    options.security.access_tokens = {kToken};
    return server::testing::StartServer(/*listen=*/true, options);
  }

  // Client options trusting the test CA and sending `token`.
  static ClientOptions Trusting(const std::string& token) {
    ClientOptions options;
    options.connect_timeout = absl::Seconds(2);
    options.security.tls.enabled = true;
    options.security.tls.root_certificates = certs().ca;
    options.security.access_token = token;
    return options;
  }

 private:
  static testing::TestCertificates* certificates_;
};

testing::TestCertificates* SecureConnectionTest::certificates_ = nullptr;

TEST_F(SecureConnectionTest, ReconstructsOverTlsWithAnAccessToken) {
  std::unique_ptr<server::ReconstructionServer> server = StartServer(/*mutual=*/false);
  ASSERT_NE(server, nullptr);
  absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
      ReconstructionClient::Connect(server->target(), Trusting(kToken));
  ASSERT_TRUE(client.ok()) << client.status();
  v1::SessionConfig config;
  config.set_target_vertices(500);
  size_t updates = 0;
  absl::StatusOr<ReconstructResult> result = (*client)->Reconstruct(
      config, "tls", server::testing::SpherePoints(5000, 3), 1000,
      [&](const v1::MeshUpdate&) { return ++updates > 0; });
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_GE(updates, 1u);
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(result->final_mesh.draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions.size(), 500u);
}

TEST_F(SecureConnectionTest, AWrongTokenConnectsButEveryCallIsUnauthenticated) {
  std::unique_ptr<server::ReconstructionServer> server = StartServer(/*mutual=*/false);
  ASSERT_NE(server, nullptr);
  absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
      ReconstructionClient::Connect(server->target(), Trusting("wrong-token-0123456789"));
  ASSERT_TRUE(client.ok()) << client.status();
  absl::StatusOr<std::vector<v1::Session>> sessions = (*client)->ListSessions();
  ASSERT_FALSE(sessions.ok());
  EXPECT_TRUE(absl::IsUnauthenticated(sessions.status())) << sessions.status();
  EXPECT_TRUE(absl::StrContains(sessions.status().message(), "ListSessions"));
  EXPECT_TRUE(absl::StrContains(sessions.status().message(), "not one this server accepts"));
}

TEST_F(SecureConnectionTest, AServerNameReachesACertificateForAnotherHost) {
  std::unique_ptr<server::ReconstructionServer> server =
      StartServer(/*mutual=*/false, /*named=*/true);
  ASSERT_NE(server, nullptr);
  ClientOptions dialled = Trusting(kToken);
  dialled.connect_timeout = absl::Milliseconds(500);
  absl::StatusOr<std::unique_ptr<ReconstructionClient>> refused =
      ReconstructionClient::Connect(server->target(), dialled);
  ASSERT_FALSE(refused.ok()) << "the certificate does not name 127.0.0.1";
  EXPECT_TRUE(absl::IsUnavailable(refused.status())) << refused.status();

  ClientOptions named = Trusting(kToken);
  named.security.tls.server_name = "scans.example.test";
  absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
      ReconstructionClient::Connect(server->target(), named);
  ASSERT_TRUE(client.ok()) << client.status();
  EXPECT_TRUE((*client)->ListSessions().ok());
}

TEST_F(SecureConnectionTest, ConnectNamesWhyTheHandshakeFailed) {
  std::unique_ptr<server::ReconstructionServer> server = StartServer(/*mutual=*/true);
  ASSERT_NE(server, nullptr);
  ClientOptions plaintext;
  plaintext.connect_timeout = absl::Seconds(1);
  ClientOptions other_ca = Trusting(kToken);
  other_ca.security.tls.root_certificates = certs().other_ca;
  ClientOptions no_client_certificate = Trusting(kToken);
  ClientOptions mutual = Trusting(kToken);
  mutual.security.tls.certificate_chain = certs().client_chain;
  mutual.security.tls.private_key = certs().client_key;
  struct Case {
    const char* what;
    ClientOptions options;
    const char* reason;
  };
  for (Case c : {Case{"plaintext", plaintext, "does the server want TLS"},
                 Case{"another CA", other_ca, "certificate verify failed"},
                 Case{"no client certificate", no_client_certificate,
                      "does the server want a client certificate"}}) {
    c.options.connect_timeout = absl::Milliseconds(500);
    absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
        ReconstructionClient::Connect(server->target(), c.options);
    ASSERT_FALSE(client.ok()) << c.what;
    EXPECT_TRUE(absl::IsUnavailable(client.status())) << c.what << ": " << client.status();
    EXPECT_TRUE(absl::StrContains(client.status().message(), "cannot reach a neuralmesh-server"))
        << client.status();
    EXPECT_TRUE(absl::StrContains(client.status().message(), c.reason)) << client.status();
  }

  absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
      ReconstructionClient::Connect(server->target(), mutual);
  ASSERT_TRUE(client.ok()) << client.status();
  EXPECT_TRUE((*client)->ListSessions().ok());
}

}  // namespace
}  // namespace neuralmesh::client
