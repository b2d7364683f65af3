// The server's port secured: TLS, mutual TLS and access tokens, over real connections on
// 127.0.0.1 with throw-away certificates (tests/testing/test_certificates.h).
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/notification.h"
#include "core/io/draco_codec.h"
#include "server/access_tokens.h"
#include "server/server.h"
#include "server/server_credentials.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::server {
namespace {

constexpr char kToken[] = "first-token-0123456789abcdef";
constexpr char kSecondToken[] = "second-token-0123456789abcdef";

class SecureServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    absl::StatusOr<neuralmesh::testing::TestCertificates> made =
        neuralmesh::testing::MakeTestCertificates(neuralmesh::testing::MakeTempDir("tls"));
    ASSERT_TRUE(made.ok()) << made.status();
    certificates_ = new neuralmesh::testing::TestCertificates(*std::move(made));
    absl::StatusOr<neuralmesh::testing::TestCertificates> renewed =
        neuralmesh::testing::MakeTestCertificates(neuralmesh::testing::MakeTempDir("renewed"));
    ASSERT_TRUE(renewed.ok()) << renewed.status();
    renewed_ = new neuralmesh::testing::TestCertificates(*std::move(renewed));
  }
  static void TearDownTestSuite() {
    delete certificates_;
    certificates_ = nullptr;
    delete renewed_;
    renewed_ = nullptr;
  }

  static const neuralmesh::testing::TestCertificates& certs() { return *certificates_; }
  // Another CA's set, as after a renewal.
  static const neuralmesh::testing::TestCertificates& renewed() { return *renewed_; }

  static ServerSecurity Tls() {
    ServerSecurity security;
    security.tls.certificate_chain = certs().server_chain;
    security.tls.private_key = certs().server_key;
    return security;
  }

  static std::unique_ptr<ReconstructionServer> Start(const ServerSecurity& security) {
    ServerOptions options;
    options.security = security;
    return testing::StartServer(/*listen=*/true, options);
  }

  // TLS credentials trusting `ca`, with a client certificate when `chain` is set.
  static std::shared_ptr<grpc::ChannelCredentials> TlsTrusting(const std::string& ca,
                                                               const std::string& chain = "",
                                                               const std::string& key = "") {
    grpc::SslCredentialsOptions options;
    options.pem_root_certs = ca;
    options.pem_cert_chain = chain;
    options.pem_private_key = key;
    return grpc::SslCredentials(options);
  }

  static std::unique_ptr<v1::ReconstructionService::Stub> Service(
      const ReconstructionServer& server,
      const std::shared_ptr<grpc::ChannelCredentials>& credentials) {
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(64 << 20);
    return v1::ReconstructionService::NewStub(
        grpc::CreateCustomChannel(server.target(), credentials, args));
  }

  // ListSessions within 5 s, with `authorization` as metadata when set.
  static grpc::Status List(v1::ReconstructionService::Stub& service,
                           const std::string& authorization = "") {
    grpc::ClientContext context;
    context.set_deadline(absl::ToChronoTime(absl::Now() + absl::Seconds(5)));
    if (!authorization.empty()) context.AddMetadata("authorization", authorization);
    v1::ListSessionsResponse response;
    return service.ListSessions(&context, v1::ListSessionsRequest(), &response);
  }

  // Waits up to 10 s (gRPC reads a replaced identity within a second) for `service` to
  // answer with `code`; returns the last status.
  static grpc::Status AwaitList(v1::ReconstructionService::Stub& service, grpc::StatusCode code) {
    grpc::Status status;
    for (int i = 0; i < 50; ++i) {
      status = List(service);
      if (status.error_code() == code) break;
      absl::SleepFor(absl::Milliseconds(200));
    }
    return status;
  }

 private:
  static neuralmesh::testing::TestCertificates* certificates_;
  static neuralmesh::testing::TestCertificates* renewed_;
};

neuralmesh::testing::TestCertificates* SecureServerTest::certificates_ = nullptr;
neuralmesh::testing::TestCertificates* SecureServerTest::renewed_ = nullptr;

TEST_F(SecureServerTest, TlsClientReconstructsATorus) {
  std::unique_ptr<ReconstructionServer> server = Start(Tls());
  ASSERT_NE(server, nullptr);
  auto service = Service(*server, TlsTrusting(certs().ca));
  const std::string id = testing::MustCreate(*service, testing::CreateRequest(2000));
  ASSERT_FALSE(id.empty());
  v1::UploadPointsResponse response;
  const grpc::Status uploaded =
      testing::Upload(*service, id, testing::TorusPoints(40000, 5), 8, &response);
  ASSERT_TRUE(uploaded.ok()) << uploaded.error_message();
  EXPECT_EQ(response.points_accepted(), 40000u);
  ASSERT_TRUE(testing::Finish(*service, id).ok());
  v1::MeshUpdate final_mesh;
  const grpc::Status waited = testing::WaitFinal(*service, id, &final_mesh);
  ASSERT_TRUE(waited.ok()) << waited.error_message();
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(final_mesh.draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions.size(), 2000u);
  absl::StatusOr<double> chamfer = testing::ChamferToTorus(*mesh);
  ASSERT_TRUE(chamfer.ok()) << chamfer.status();
  EXPECT_LT(*chamfer, 0.02) << "2% of the diagonal";
}

TEST_F(SecureServerTest, PlaintextClientsAndUntrustedCertificatesAreRefused) {
  std::unique_ptr<ReconstructionServer> server = Start(Tls());
  ASSERT_NE(server, nullptr);
  auto plaintext = Service(*server, grpc::InsecureChannelCredentials());
  EXPECT_EQ(List(*plaintext).error_code(), grpc::StatusCode::UNAVAILABLE);

  // A client that trusts another CA rejects the server's certificate.
  auto distrustful = Service(*server, TlsTrusting(certs().other_ca));
  const grpc::Status refused = List(*distrustful);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_TRUE(absl::StrContains(refused.error_message(), "certificate verify failed"))
      << refused.error_message();

  auto trusting = Service(*server, TlsTrusting(certs().ca));
  const grpc::Status listed = List(*trusting);
  EXPECT_TRUE(listed.ok()) << listed.error_message();
}

TEST_F(SecureServerTest, MutualTlsNeedsAClientCertificateSignedByTheClientCa) {
  ServerSecurity security = Tls();
  security.tls.client_ca_certificates = certs().ca;
  std::unique_ptr<ReconstructionServer> server = Start(security);
  ASSERT_NE(server, nullptr);

  auto anonymous = Service(*server, TlsTrusting(certs().ca));
  EXPECT_EQ(List(*anonymous).error_code(), grpc::StatusCode::UNAVAILABLE);
  auto stranger = Service(*server, TlsTrusting(certs().ca, certs().other_client_chain,
                                            certs().other_client_key));
  EXPECT_EQ(List(*stranger).error_code(), grpc::StatusCode::UNAVAILABLE);
  auto known = Service(*server, TlsTrusting(certs().ca, certs().client_chain, certs().client_key));
  const grpc::Status listed = List(*known);
  EXPECT_TRUE(listed.ok()) << listed.error_message();
}

TEST_F(SecureServerTest, CallsWithoutAKnownTokenAreUnauthenticated) {
  ServerSecurity security = Tls();
  security.access_tokens = {kToken, kSecondToken};
  std::unique_ptr<ReconstructionServer> server = Start(security);
  ASSERT_NE(server, nullptr);
  auto service = Service(*server, TlsTrusting(certs().ca));

  const grpc::Status missing = List(*service);
  EXPECT_EQ(missing.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(absl::StrContains(missing.error_message(), "requires an access token"))
      << missing.error_message();
  for (const std::string& wrong :
       {absl::StrCat("Bearer ", kToken, "x"), absl::StrCat("Bearer ", kToken).substr(0, 20),
        std::string("Bearer first-token-0123456789abcdeF"), absl::StrCat("Basic ", kToken),
        std::string(kToken)}) {
    const grpc::Status refused = List(*service, wrong);
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAUTHENTICATED) << wrong;
    EXPECT_TRUE(absl::StrContains(refused.error_message(), "not one this server accepts"))
        << refused.error_message();
  }
  for (const char* token : {kToken, kSecondToken}) {
    const grpc::Status listed = List(*service, absl::StrCat("Bearer ", token));
    EXPECT_TRUE(listed.ok()) << listed.error_message();
  }
  EXPECT_TRUE(List(*service, absl::StrCat("bearer ", kToken)).ok()) << "the scheme is caseless";

  // gRPC's own token credentials, as the neuralmesh client sends them.
  auto with_token = Service(*server, grpc::CompositeChannelCredentials(
                                      TlsTrusting(certs().ca),
                                      grpc::AccessTokenCredentials(kSecondToken)));
  const std::string id = testing::MustCreate(*with_token, testing::CreateRequest(100));
  ASSERT_FALSE(id.empty());

  // Streams are refused before their handlers run: an upload without the token leaves the
  // session untouched, a watch without it gets nothing.
  {
    grpc::ClientContext context;
    context.AddMetadata("authorization", "Bearer wrong-token-0123456789");
    v1::UploadPointsResponse response;
    auto writer = service->UploadPoints(&context, &response);
    v1::UploadPointsRequest request;
    request.set_session_id(id);
    *request.mutable_batch() = testing::Batch(testing::TorusPoints(1000, 1), 0, 1000);
    writer->Write(request);
    writer->WritesDone();
    EXPECT_EQ(writer->Finish().error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  {
    grpc::ClientContext context;
    context.set_deadline(absl::ToChronoTime(absl::Now() + absl::Seconds(5)));
    v1::WatchSessionRequest request;
    request.set_session_id(id);
    auto reader = service->WatchSession(&context, request);
    v1::MeshUpdate update;
    EXPECT_FALSE(reader->Read(&update));
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  grpc::Status got;
  const v1::Session session = testing::GetSession(*with_token, id, &got);
  ASSERT_TRUE(got.ok()) << got.error_message();
  EXPECT_EQ(session.learning().points_received(), 0u);
}

TEST_F(SecureServerTest, ReplacedTokensApplyToCallsThatStartLater) {
  ServerSecurity security = Tls();
  security.access_tokens = {kToken};
  std::unique_ptr<ReconstructionServer> server = Start(security);
  ASSERT_NE(server, nullptr);
  auto first = Service(*server, grpc::CompositeChannelCredentials(
                                 TlsTrusting(certs().ca), grpc::AccessTokenCredentials(kToken)));
  auto second = Service(*server, grpc::CompositeChannelCredentials(
                                  TlsTrusting(certs().ca),
                                  grpc::AccessTokenCredentials(kSecondToken)));
  const std::string id = testing::MustCreate(*first, testing::CreateRequest(300));
  ASSERT_FALSE(id.empty());
  // A watch opened with the first token...
  std::vector<v1::MeshUpdate> updates;
  grpc::Status watched;
  absl::Notification watching;
  std::thread watcher([&] {
    grpc::ClientContext context;
    context.set_deadline(absl::ToChronoTime(absl::Now() + absl::Seconds(60)));
    v1::WatchSessionRequest request;
    request.set_session_id(id);
    auto reader = first->WatchSession(&context, request);
    v1::MeshUpdate update;
    bool notified = false;
    while (reader->Read(&update)) {
      updates.push_back(update);
      if (!notified) watching.Notify();
      notified = true;
    }
    if (!notified) watching.Notify();
    watched = reader->Finish();
  });
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*first, id, testing::SpherePoints(1000, 2), 1, &response).ok());
  watching.WaitForNotification();

  // ...goes on after the first token is replaced by the second, which new calls need.
  const absl::Status invalid = server->ReplaceAccessTokens({"short"});
  EXPECT_TRUE(absl::IsInvalidArgument(invalid)) << invalid;
  EXPECT_TRUE(List(*first).ok()) << "an invalid list keeps the old tokens";
  ASSERT_TRUE(server->ReplaceAccessTokens({kSecondToken}).ok());
  EXPECT_EQ(List(*first).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(List(*second).ok());
  ASSERT_TRUE(testing::Upload(*second, id, testing::SpherePoints(3000, 3), 3, &response).ok());
  ASSERT_TRUE(testing::Finish(*second, id).ok());
  watcher.join();
  EXPECT_TRUE(watched.ok()) << watched.error_message();
  ASSERT_FALSE(updates.empty());
  EXPECT_EQ(updates.back().kind(), v1::UPDATE_KIND_FINAL);
  EXPECT_EQ(updates.back().vertex_count(), 300u);

  std::unique_ptr<ReconstructionServer> open = Start(Tls());
  ASSERT_NE(open, nullptr);
  EXPECT_TRUE(absl::IsFailedPrecondition(open->ReplaceAccessTokens({kToken})));
}

TEST_F(SecureServerTest, HealthChecksNeedNoToken) {
  ServerSecurity security = Tls();
  security.access_tokens = {kToken};
  std::unique_ptr<ReconstructionServer> server = Start(security);
  ASSERT_NE(server, nullptr);
  auto channel = grpc::CreateChannel(server->target(), TlsTrusting(certs().ca));
  std::string bytes;
  const grpc::Status status = testing::CheckHealth(channel, "", &bytes);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(bytes, std::string("\x08\x01", 2)) << "SERVING";
}

TEST_F(SecureServerTest, StartRejectsSecurityThatDoesNotGoTogether) {
  struct Case {
    const char* what;
    ServerSecurity security;
    absl::StatusCode code;
    const char* message;
  };
  ServerSecurity tokens_without_tls;
  tokens_without_tls.access_tokens = {kToken};
  ServerSecurity key_only;
  key_only.tls.private_key = certs().server_key;
  ServerSecurity client_ca_only;
  client_ca_only.tls.client_ca_certificates = certs().ca;
  ServerSecurity certificate_only = Tls();
  certificate_only.tls.private_key.clear();
  ServerSecurity not_pem = Tls();
  not_pem.tls.certificate_chain = "MIIB...";
  ServerSecurity short_token = Tls();
  short_token.access_tokens = {"short"};
  ServerSecurity wrong_key = Tls();
  wrong_key.tls.private_key = certs().client_key;
  ServerSecurity role_without_mutual_tls = Tls();
  role_without_mutual_tls.client_certificate_role = AccessRole::kUser;
  ServerSecurity role_and_tokens = Tls();
  role_and_tokens.tls.client_ca_certificates = certs().ca;
  role_and_tokens.access_tokens = {kToken};
  role_and_tokens.client_certificate_role = AccessRole::kUser;
  ServerSecurity roles_without_mutual_tls = Tls();
  roles_without_mutual_tls.client_roles = {{"neuralmesh-test-client", AccessRole::kUser}};
  const Case cases[] = {
      {"tokens without TLS", tokens_without_tls, absl::StatusCode::kInvalidArgument,
       "access tokens need TLS"},
      {"a key alone", key_only, absl::StatusCode::kInvalidArgument, "without a server certificate"},
      {"a client CA alone", client_ca_only, absl::StatusCode::kInvalidArgument,
       "without a server certificate"},
      {"a certificate alone", certificate_only, absl::StatusCode::kInvalidArgument,
       "without its private key"},
      {"not PEM", not_pem, absl::StatusCode::kInvalidArgument, "not PEM"},
      {"a short token", short_token, absl::StatusCode::kInvalidArgument, "at least 16"},
      {"another certificate's key", wrong_key, absl::StatusCode::kInvalidArgument,
       "rejected the TLS certificate or key"},
      {"a client certificate role without mutual TLS", role_without_mutual_tls,
       absl::StatusCode::kInvalidArgument, "need mutual TLS"},
      {"client roles without mutual TLS", roles_without_mutual_tls,
       absl::StatusCode::kInvalidArgument, "need mutual TLS"},
      {"a client certificate role and tokens", role_and_tokens,
       absl::StatusCode::kInvalidArgument, "do not go together"},
  };
  for (const Case& c : cases) {
    ServerOptions options;
    options.security = c.security;
    absl::StatusOr<std::unique_ptr<ReconstructionServer>> server =
        ReconstructionServer::Start(options);
    ASSERT_FALSE(server.ok()) << c.what;
    EXPECT_EQ(server.status().code(), c.code) << c.what << ": " << server.status();
    EXPECT_TRUE(absl::StrContains(server.status().message(), c.message))
        << c.what << ": " << server.status();
  }
}

// A renewed certificate applies to new connections while the server runs: a session opened
// under the old one goes on to its final mesh over its open connection.
TEST_F(SecureServerTest, ARenewedCertificateAppliesToNewConnectionsWithoutARestart) {
  std::unique_ptr<ReconstructionServer> server = Start(Tls());
  ASSERT_NE(server, nullptr);
  auto before = Service(*server, TlsTrusting(certs().ca));
  const std::string id = testing::MustCreate(*before, testing::CreateRequest(500));
  ASSERT_FALSE(id.empty());
  v1::UploadPointsResponse uploaded;
  ASSERT_TRUE(testing::Upload(*before, id, testing::SpherePoints(5000, 3), 2, &uploaded).ok());

  ServerTls renewal;
  renewal.certificate_chain = renewed().server_chain;
  renewal.private_key = renewed().server_key;
  ASSERT_TRUE(server->ReplaceTls(renewal).ok());
  auto after = Service(*server, TlsTrusting(renewed().ca));
  const grpc::Status renewed_listed = AwaitList(*after, grpc::StatusCode::OK);
  EXPECT_TRUE(renewed_listed.ok()) << renewed_listed.error_message();
  auto stale = Service(*server, TlsTrusting(certs().ca));
  const grpc::Status stale_listed = List(*stale);
  EXPECT_EQ(stale_listed.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_TRUE(absl::StrContains(stale_listed.error_message(), "certificate verify failed"))
      << stale_listed.error_message();

  // The connection made before the renewal still carries calls.
  ASSERT_TRUE(testing::Finish(*before, id).ok());
  v1::MeshUpdate final_mesh;
  const grpc::Status waited = testing::WaitFinal(*before, id, &final_mesh);
  ASSERT_TRUE(waited.ok()) << waited.error_message();
  EXPECT_EQ(final_mesh.vertex_count(), 500u);
}

TEST_F(SecureServerTest, AReplacementThatGrpcWouldNotTakeKeepsTheOldIdentity) {
  std::unique_ptr<ReconstructionServer> server = Start(Tls());
  ASSERT_NE(server, nullptr);
  ServerTls wrong_key;
  wrong_key.certificate_chain = renewed().server_chain;
  wrong_key.private_key = certs().server_key;
  ServerTls not_pem = wrong_key;
  not_pem.private_key = "MIIE...";
  ServerTls mutual;
  mutual.certificate_chain = renewed().server_chain;
  mutual.private_key = renewed().server_key;
  mutual.client_ca_certificates = renewed().ca;
  struct Case {
    const char* what;
    const ServerTls& tls;
    const char* message;
  };
  for (const Case& c : {Case{"another certificate's key", wrong_key, "rejected the TLS"},
                        Case{"not PEM", not_pem, "not PEM"},
                        Case{"mutual TLS turned on", mutual, "takes a restart"}}) {
    const absl::Status replaced = server->ReplaceTls(c.tls);
    EXPECT_TRUE(absl::IsInvalidArgument(replaced)) << c.what << ": " << replaced;
    EXPECT_TRUE(absl::StrContains(replaced.message(), c.message)) << c.what << ": " << replaced;
  }
  absl::SleepFor(absl::Milliseconds(2500));  // Past two of gRPC's reads of the identity.
  auto service = Service(*server, TlsTrusting(certs().ca));
  const grpc::Status listed = List(*service);
  EXPECT_TRUE(listed.ok()) << "the old certificate is still presented: " << listed.error_message();

  std::unique_ptr<ReconstructionServer> plaintext = Start(ServerSecurity());
  ASSERT_NE(plaintext, nullptr);
  EXPECT_TRUE(absl::IsFailedPrecondition(plaintext->ReplaceTls(wrong_key)));
}

// Under mutual TLS the client CAs are renewed with the certificate.
TEST_F(SecureServerTest, MutualTlsRenewsTheClientCasToo) {
  ServerSecurity security = Tls();
  security.tls.client_ca_certificates = certs().ca;
  std::unique_ptr<ReconstructionServer> server = Start(security);
  ASSERT_NE(server, nullptr);
  ServerTls renewal;
  renewal.certificate_chain = renewed().server_chain;
  renewal.private_key = renewed().server_key;
  renewal.client_ca_certificates = renewed().ca;
  ASSERT_TRUE(server->ReplaceTls(renewal).ok());
  auto known = Service(*server, TlsTrusting(renewed().ca, renewed().client_chain,
                                            renewed().client_key));
  const grpc::Status listed = AwaitList(*known, grpc::StatusCode::OK);
  EXPECT_TRUE(listed.ok()) << listed.error_message();
  auto former = Service(*server, TlsTrusting(renewed().ca, certs().client_chain,
                                             certs().client_key));
  EXPECT_EQ(List(*former).error_code(), grpc::StatusCode::UNAVAILABLE)
      << "a client certificate of the former CA";
  ServerTls without_client_cas = renewal;
  without_client_cas.client_ca_certificates.clear();
  EXPECT_TRUE(absl::IsInvalidArgument(server->ReplaceTls(without_client_cas)));
}

}  // namespace
}  // namespace neuralmesh::server
