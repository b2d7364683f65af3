// server/session_access.h: which sessions a call may see and change, by the client name and
// role of its access token, over real TLS connections on 127.0.0.1 (throw-away certificates,
// tests/testing/test_certificates.h). Two users, a reader and two admins share one server.
#include "server/session_access.h"

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/draco_codec.h"
#include "core/sampling/implicit_surfaces.h"
#include "server/client_certificate_identity.h"
#include "server/server.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::server {
namespace {

using ::neuralmesh::server::testing::CreateRequest;
using ::neuralmesh::server::testing::MustCreate;
using Service = v1::ReconstructionService::Stub;

constexpr char kAlice[] = "alice-token-0123456789abcdef";
constexpr char kBob[] = "bob-token-0123456789abcdef";
constexpr char kWall[] = "wall-token-0123456789abcdef";
constexpr char kOps[] = "ops-token-0123456789abcdef";
constexpr char kUnnamed[] = "unnamed-token-0123456789abcdef";

class SessionAccessTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    absl::StatusOr<neuralmesh::testing::TestCertificates> made =
        neuralmesh::testing::MakeTestCertificates(neuralmesh::testing::MakeTempDir("access"));
    ASSERT_TRUE(made.ok()) << made.status();
    certificates_ = new neuralmesh::testing::TestCertificates(*std::move(made));
  }
  static void TearDownTestSuite() {
    delete certificates_;
    certificates_ = nullptr;
  }

  void SetUp() override { StartServer(/*max_sessions_per_client=*/0); }

  void StartServer(size_t max_sessions_per_client) {
    server_.reset();
    ServerOptions options;
    options.limits.max_sessions_per_client = max_sessions_per_client;
    options.security.tls.certificate_chain = certificates_->server_chain;
    options.security.tls.private_key = certificates_->server_key;
    options.security.access_tokens = {AccessToken(kAlice, "alice", AccessRole::kUser),
                                      AccessToken(kBob, "bob", AccessRole::kUser),
                                      AccessToken(kWall, "wall", AccessRole::kReader),
                                      AccessToken(kOps, "ops", AccessRole::kAdmin), kUnnamed};
    options.event_sink = events_.Sink();
    server_ = testing::StartServer(/*listen=*/true, options);
    ASSERT_NE(server_, nullptr);
    alice_ = As(kAlice);
    bob_ = As(kBob);
    wall_ = As(kWall);
    ops_ = As(kOps);
    unnamed_ = As(kUnnamed);
  }

  // A client of `server` (under mutual TLS) that presents the certificate `chain` with `key`.
  static std::unique_ptr<Service> Presenting(const ReconstructionServer& server,
                                             const std::string& chain, const std::string& key) {
    grpc::SslCredentialsOptions tls;
    tls.pem_root_certs = certificates_->ca;
    tls.pem_cert_chain = chain;
    tls.pem_private_key = key;
    return v1::ReconstructionService::NewStub(
        grpc::CreateChannel(server.target(), grpc::SslCredentials(tls)));
  }

  // A client of the server whose every call carries `token`.
  std::unique_ptr<Service> As(const char* token) {
    grpc::SslCredentialsOptions tls;
    tls.pem_root_certs = certificates_->ca;
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(64 << 20);
    return v1::ReconstructionService::NewStub(grpc::CreateCustomChannel(
        server_->target(),
        grpc::CompositeChannelCredentials(grpc::SslCredentials(tls),
                                          grpc::AccessTokenCredentials(token)),
        args));
  }

  // The ids ListSessions gives `service`.
  static std::set<std::string> Listed(Service& service) {
    grpc::ClientContext context;
    v1::ListSessionsResponse response;
    const grpc::Status status = service.ListSessions(&context, {}, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    std::set<std::string> ids;
    for (const v1::Session& s : response.sessions()) ids.insert(s.session_id());
    return ids;
  }

  static grpc::Status GetMesh(Service& service, const std::string& id) {
    grpc::ClientContext context;
    v1::GetMeshRequest request;
    request.set_session_id(id);
    v1::MeshUpdate update;
    return service.GetMesh(&context, request, &update);
  }

  // Every call that needs a session, with its status: the session is one `service` may not
  // see at all (see_too) or may only see.
  static std::vector<std::pair<std::string, grpc::Status>> Refusals(Service& service,
                                                                    const std::string& id,
                                                                    bool see_too) {
    std::vector<std::pair<std::string, grpc::Status>> refusals;
    v1::UploadPointsResponse uploaded;
    refusals.emplace_back("UploadPoints",
                          testing::Upload(service, id, testing::SpherePoints(100, 1), 1, &uploaded));
    refusals.emplace_back("FinishSession", testing::Finish(service, id));
    refusals.emplace_back("CancelSession", testing::Cancel(service, id));
    refusals.emplace_back("DeleteSession", testing::Delete(service, id));
    grpc::ClientContext context;
    auto stream = service.Reconstruct(&context);
    v1::ReconstructRequest attach;
    attach.mutable_start()->set_session_id(id);
    stream->Write(attach);
    stream->WritesDone();
    v1::ReconstructResponse ignored;
    while (stream->Read(&ignored)) {
    }
    refusals.emplace_back("Reconstruct (attach)", stream->Finish());
    if (see_too) {
      grpc::Status got;
      testing::GetSession(service, id, &got);
      refusals.emplace_back("GetSession", got);
      std::vector<v1::MeshUpdate> updates;
      refusals.emplace_back("WatchSession", testing::WatchAll(service, id, &updates));
      refusals.emplace_back("GetMesh", GetMesh(service, id));
    }
    return refusals;
  }

  static neuralmesh::testing::TestCertificates* certificates_;
  testing::CapturedEvents events_;
  std::unique_ptr<ReconstructionServer> server_;
  std::unique_ptr<Service> alice_, bob_, wall_, ops_, unnamed_;
};

neuralmesh::testing::TestCertificates* SessionAccessTest::certificates_ = nullptr;

TEST_F(SessionAccessTest, UsersSeeOnlyTheirOwnSessionsReadersAndAdminsSeeAll) {
  const std::string a = MustCreate(*alice_, CreateRequest(200));
  const std::string b = MustCreate(*bob_, CreateRequest(200));
  const std::string o = MustCreate(*unnamed_, CreateRequest(200));
  EXPECT_EQ(Listed(*alice_), (std::set<std::string>{a}));
  EXPECT_EQ(Listed(*bob_), (std::set<std::string>{b}));
  EXPECT_EQ(Listed(*wall_), (std::set<std::string>{a, b, o}));
  EXPECT_EQ(Listed(*ops_), (std::set<std::string>{a, b, o}));
  EXPECT_EQ(Listed(*unnamed_), (std::set<std::string>{a, b, o}));
  EXPECT_EQ(testing::GetSession(*wall_, a).owner(), "alice");
  EXPECT_EQ(testing::GetSession(*ops_, b).owner(), "bob");
  EXPECT_EQ(testing::GetSession(*ops_, o).owner(), "") << "an unnamed token owns nothing";
  EXPECT_TRUE(absl::StrContains(events_.Await("\"test\""), "created by client alice at ipv4:"))
      << events_.Await("\"test\"");
}

TEST_F(SessionAccessTest, AUserCanNeitherSeeNorChangeAnotherUsersSession) {
  const std::string a = MustCreate(*alice_, CreateRequest(200));
  for (const auto& [call, status] : Refusals(*bob_, a, /*see_too=*/true)) {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << call;
    EXPECT_TRUE(absl::StrContains(
        status.error_message(), absl::StrCat("session ", a, " belongs to another client; client "
                                             "bob may use only the sessions it created")))
        << call << ": " << status.error_message();
  }
  grpc::Status got;
  const v1::Session kept = testing::GetSession(*alice_, a, &got);
  ASSERT_TRUE(got.ok()) << got.error_message();
  EXPECT_EQ(kept.state(), v1::SESSION_STATE_COLLECTING) << "bob finished or cancelled nothing";
  EXPECT_EQ(kept.points_taken(), 0u) << "bob's upload added nothing";
}

TEST_F(SessionAccessTest, AReaderWatchesEverySessionButChangesNone) {
  grpc::ClientContext context;
  v1::Session created;
  const grpc::Status create = wall_->CreateSession(&context, CreateRequest(200), &created);
  EXPECT_EQ(create.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(absl::StrContains(create.error_message(),
                                "client wall is a reader: it may list, get and watch sessions "
                                "but not create one"))
      << create.error_message();
  {
    grpc::ClientContext reconstruct_context;
    auto stream = wall_->Reconstruct(&reconstruct_context);
    v1::ReconstructRequest start;
    *start.mutable_start()->mutable_create() = CreateRequest(200);
    stream->Write(start);
    stream->WritesDone();
    v1::ReconstructResponse ignored;
    while (stream->Read(&ignored)) {
    }
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::PERMISSION_DENIED);
  }
  EXPECT_TRUE(Listed(*ops_).empty()) << "the reader created no session";

  const std::string a = MustCreate(*alice_, CreateRequest(300));
  for (const auto& [call, status] : Refusals(*wall_, a, /*see_too=*/false)) {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << call;
    EXPECT_TRUE(absl::StrContains(status.error_message(), "is a reader: it may not upload "))
        << call << ": " << status.error_message();
  }
  // Alice learns her sphere while the reader watches it to the end.
  std::vector<v1::MeshUpdate> watched;
  grpc::Status watch;
  std::thread watcher([&] { watch = testing::WatchAll(*wall_, a, &watched); });
  v1::UploadPointsResponse uploaded;
  ASSERT_TRUE(testing::Upload(*alice_, a, testing::SpherePoints(6000, 4), 3, &uploaded).ok());
  ASSERT_TRUE(testing::Finish(*alice_, a).ok());
  watcher.join();
  ASSERT_TRUE(watch.ok()) << watch.error_message();
  ASSERT_FALSE(watched.empty());
  EXPECT_EQ(watched.back().kind(), v1::UPDATE_KIND_FINAL);
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(watched.back().draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions.size(), 300u);
  absl::StatusOr<std::unique_ptr<ImplicitSurface>> sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  ASSERT_TRUE(sphere.ok());
  EXPECT_LT(testing::MaxVertexDistance(*mesh, **sphere), 0.05);
  EXPECT_TRUE(GetMesh(*wall_, a).ok());
}

TEST_F(SessionAccessTest, AnAdminChangesEverySession) {
  const std::string a = MustCreate(*alice_, CreateRequest(200));
  const std::string b = MustCreate(*bob_, CreateRequest(200));
  v1::UploadPointsResponse uploaded;
  EXPECT_TRUE(testing::Upload(*ops_, a, testing::SpherePoints(1000, 2), 1, &uploaded).ok());
  EXPECT_EQ(testing::GetSession(*alice_, a).points_taken(), 1000u);
  EXPECT_TRUE(testing::Cancel(*ops_, a).ok());
  EXPECT_TRUE(testing::Delete(*unnamed_, b).ok());
  EXPECT_EQ(Listed(*ops_), (std::set<std::string>{a}));
}

TEST_F(SessionAccessTest, AClientHoldsAtMostItsShareOfSessions) {
  StartServer(/*max_sessions_per_client=*/2);
  const std::string first = MustCreate(*alice_, CreateRequest(200));
  MustCreate(*alice_, CreateRequest(200));
  grpc::ClientContext context;
  v1::Session refused;
  const grpc::Status third = alice_->CreateSession(&context, CreateRequest(200), &refused);
  EXPECT_EQ(third.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(absl::StrContains(third.error_message(), "client alice holds its maximum of 2"))
      << third.error_message();
  MustCreate(*bob_, CreateRequest(200));
  MustCreate(*unnamed_, CreateRequest(200));
  MustCreate(*unnamed_, CreateRequest(200));
  MustCreate(*unnamed_, CreateRequest(200));  // Unnamed tokens have no share of their own.
  ASSERT_TRUE(testing::Delete(*alice_, first).ok());
  EXPECT_FALSE(MustCreate(*alice_, CreateRequest(200)).empty()) << "room again";
}

TEST_F(SessionAccessTest, SessionsAreHandedToAnotherClientByTheirOwnerOrAnAdmin) {
  const auto transfer = [](Service& service, const std::string& id, const std::string& to,
                           v1::Session* session = nullptr) {
    grpc::ClientContext context;
    v1::TransferSessionRequest request;
    request.set_session_id(id);
    request.set_new_owner(to);
    v1::Session ignored;
    return service.TransferSession(&context, request, session != nullptr ? session : &ignored);
  };
  const std::string a = MustCreate(*alice_, CreateRequest(200));
  const grpc::Status by_bob = transfer(*bob_, a, "bob");
  EXPECT_EQ(by_bob.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(absl::StrContains(by_bob.error_message(), "belongs to another client"))
      << by_bob.error_message();
  const grpc::Status by_reader = transfer(*wall_, a, "wall");
  EXPECT_EQ(by_reader.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(
      absl::StrContains(by_reader.error_message(), "may not upload into, finish, hand over"))
      << by_reader.error_message();
  EXPECT_EQ(transfer(*alice_, a, "").error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(transfer(*alice_, "s-0000000000000000", "bob").error_code(),
            grpc::StatusCode::NOT_FOUND);

  // Alice hands her session to bob: from then on it is his, and no longer hers.
  v1::Session handed;
  const grpc::Status by_alice = transfer(*alice_, a, "bob", &handed);
  ASSERT_TRUE(by_alice.ok()) << by_alice.error_message();
  EXPECT_EQ(handed.owner(), "bob");
  EXPECT_EQ(Listed(*alice_), std::set<std::string>{});
  EXPECT_EQ(Listed(*bob_), (std::set<std::string>{a}));
  for (const auto& [call, status] : Refusals(*alice_, a, /*see_too=*/true)) {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << call;
  }
  v1::UploadPointsResponse uploaded;
  EXPECT_TRUE(testing::Upload(*bob_, a, testing::SpherePoints(1000, 2), 1, &uploaded).ok());
  EXPECT_EQ(testing::GetSession(*wall_, a).owner(), "bob");
  EXPECT_EQ(testing::GetSession(*ops_, a).points_taken(), 1000u);
  EXPECT_TRUE(absl::StrContains(events_.Await("handed"),
                                absl::StrCat("session ", a, " handed from client alice to client "
                                             "bob by client alice at ipv4:")))
      << events_.Await("handed");

  // An admin hands any session over, here back to alice.
  ASSERT_TRUE(transfer(*ops_, a, "alice", &handed).ok());
  EXPECT_EQ(handed.owner(), "alice");
  EXPECT_TRUE(testing::Finish(*alice_, a).ok());
}

// Under mutual TLS without tokens, --client_certificate_role names clients by their
// certificates' common names.
TEST_F(SessionAccessTest, ClientCertificatesNameTheirClientsUnderMutualTls) {
  const auto start = [](AccessRole role) {
    ServerOptions options;
    options.security.tls.certificate_chain = certificates_->server_chain;
    options.security.tls.private_key = certificates_->server_key;
    options.security.tls.client_ca_certificates = certificates_->ca;
    options.security.client_certificate_role = role;
    return testing::StartServer(/*listen=*/true, options);
  };
  std::unique_ptr<ReconstructionServer> users = start(AccessRole::kUser);
  ASSERT_NE(users, nullptr);
  auto first = Presenting(*users, certificates_->client_chain, certificates_->client_key);
  auto second =
      Presenting(*users, certificates_->second_client_chain, certificates_->second_client_key);
  const std::string id = MustCreate(*first, CreateRequest(200));
  ASSERT_FALSE(id.empty());
  EXPECT_EQ(testing::GetSession(*first, id).owner(), "neuralmesh-test-client");
  EXPECT_EQ(Listed(*first), (std::set<std::string>{id}));
  EXPECT_TRUE(Listed(*second).empty());
  grpc::Status got;
  testing::GetSession(*second, id, &got);
  EXPECT_EQ(got.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(absl::StrContains(got.error_message(), "belongs to another client"))
      << got.error_message();

  std::unique_ptr<ReconstructionServer> readers = start(AccessRole::kReader);
  ASSERT_NE(readers, nullptr);
  auto reader = Presenting(*readers, certificates_->client_chain, certificates_->client_key);
  grpc::ClientContext context;
  v1::Session refused;
  const grpc::Status create = reader->CreateSession(&context, CreateRequest(200), &refused);
  EXPECT_EQ(create.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(absl::StrContains(create.error_message(),
                                "client neuralmesh-test-client is a reader"))
      << create.error_message();
}

// --client_roles_file gives each common name a role of its own; common names it does not
// list get --client_certificate_role, or are refused without one; SIGHUP replaces the roles.
TEST_F(SessionAccessTest, ClientRolesByCommonName) {
  const auto start = [](ClientRoles roles, std::optional<AccessRole> others) {
    ServerOptions options;
    options.security.tls.certificate_chain = certificates_->server_chain;
    options.security.tls.private_key = certificates_->server_key;
    options.security.tls.client_ca_certificates = certificates_->ca;
    options.security.client_roles = std::move(roles);
    options.security.client_certificate_role = others;
    return testing::StartServer(/*listen=*/true, options);
  };
  const auto create = [](v1::ReconstructionService::Stub& stub) {
    grpc::ClientContext context;
    v1::Session session;
    return stub.CreateSession(&context, CreateRequest(200), &session);
  };

  std::unique_ptr<ReconstructionServer> server =
      start({{"neuralmesh-test-client", AccessRole::kUser}}, std::nullopt);
  ASSERT_NE(server, nullptr);
  auto listed = Presenting(*server, certificates_->client_chain, certificates_->client_key);
  auto unlisted =
      Presenting(*server, certificates_->second_client_chain, certificates_->second_client_key);
  EXPECT_TRUE(create(*listed).ok());
  const grpc::Status refused = create(*unlisted);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(absl::StrContains(refused.error_message(),
                                "common name \"neuralmesh-test-second_client\" has no role"))
      << refused.error_message();

  // The second client listed as a reader: it sees, and still creates nothing.
  ASSERT_TRUE(server
                  ->ReplaceClientRoles({{"neuralmesh-test-client", AccessRole::kUser},
                                        {"neuralmesh-test-second_client", AccessRole::kReader}})
                  .ok());
  EXPECT_EQ(Listed(*unlisted).size(), 1u);
  const grpc::Status reader = create(*unlisted);
  EXPECT_EQ(reader.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(absl::StrContains(reader.error_message(), "is a reader")) << reader.error_message();
  EXPECT_TRUE(absl::IsInvalidArgument(server->ReplaceClientRoles({})));

  // Others as users: the unlisted client creates sessions of its own.
  std::unique_ptr<ReconstructionServer> others_users =
      start({{"neuralmesh-test-client", AccessRole::kReader}}, AccessRole::kUser);
  ASSERT_NE(others_users, nullptr);
  auto reader_now =
      Presenting(*others_users, certificates_->client_chain, certificates_->client_key);
  auto user_now = Presenting(*others_users, certificates_->second_client_chain,
                             certificates_->second_client_key);
  EXPECT_EQ(create(*reader_now).error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(create(*user_now).ok());

  // A server that names no clients by certificate has no roles to replace.
  std::unique_ptr<ReconstructionServer> plain = testing::StartServer(/*listen=*/true);
  ASSERT_NE(plain, nullptr);
  EXPECT_TRUE(absl::IsFailedPrecondition(
      plain->ReplaceClientRoles({{"neuralmesh-test-client", AccessRole::kUser}})));
}

TEST(ParseClientRolesTest, CommonNamesMayHoldSpacesAndTheRoleComesLast) {
  absl::StatusOr<ClientRoles> roles = ParseClientRoles(
      "# scanners\nscanner-01 user\n  Jane Doe\treader  \n\nops admin\n");
  ASSERT_TRUE(roles.ok()) << roles.status();
  EXPECT_EQ(*roles, (ClientRoles{{"scanner-01", AccessRole::kUser},
                                 {"Jane Doe", AccessRole::kReader},
                                 {"ops", AccessRole::kAdmin}}));
  const struct {
    const char* text;
    const char* message;
  } bad[] = {
      {"scanner-01\n", "line 1: expected COMMON_NAME ROLE"},
      {"a user\nb owner\n", "line 2: unknown role"},
      {"a user\na reader\n", "line 2: the common name \"a\" is listed twice"},
      {"# nobody\n\n", "no client in it"},
  };
  for (const auto& b : bad) {
    const absl::Status status = ParseClientRoles(b.text).status();
    EXPECT_TRUE(absl::IsInvalidArgument(status)) << b.text;
    EXPECT_TRUE(absl::StrContains(status.message(), b.message)) << status;
  }
}

}  // namespace
}  // namespace neuralmesh::server
