// neuralmesh-server --metrics_port (server/metrics_http.h): what a scraper reads after real
// calls over 127.0.0.1, sessions learning, ending, deleted, reaped and restored.
#include "server/metrics_http.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
#include "core/version.h"
#include "http/http_server.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/http_client.h"
#include "tests/testing/https_client.h"
#include "tests/testing/shapes.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::server {
namespace {

using ::neuralmesh::testing::HttpGet;
using ::neuralmesh::testing::HttpReply;
using ::neuralmesh::testing::HttpsGet;
using ::neuralmesh::testing::HttpsTarget;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

constexpr char kService[] = "grpc_service=\"neuralmesh.v1.ReconstructionService\"";

// The samples of a /metrics page, by "name{labels}" as written.
std::map<std::string, double> Scrape(const ReconstructionServer& server) {
  const HttpReply reply = HttpGet(server.metrics_port(), "/metrics");
  EXPECT_EQ(reply.status, 200);
  EXPECT_EQ(reply.Header("content-type"), "text/plain; version=0.0.4; charset=utf-8");
  std::map<std::string, double> samples;
  for (absl::string_view line : absl::StrSplit(reply.body, '\n', absl::SkipEmpty())) {
    if (line.front() == '#') continue;
    const size_t space = line.rfind(' ');
    double value = 0;
    EXPECT_TRUE(absl::SimpleAtod(line.substr(space + 1), &value)) << line;
    samples[std::string(line.substr(0, space))] = value;
  }
  return samples;
}

std::string Handled(absl::string_view method, absl::string_view type, absl::string_view code) {
  return absl::StrCat("grpc_server_handled_total{", kService, ",grpc_method=\"", method,
                      "\",grpc_type=\"", type, "\",grpc_code=\"", code, "\"}");
}

std::unique_ptr<ReconstructionServer> StartWithMetrics(ServerOptions options = {}) {
  options.metrics_port = 0;
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true, options);
  if (server != nullptr) {
    EXPECT_GT(server->metrics_port(), 0);
  }
  return server;
}

// A server whose metrics page speaks HTTPS and asks for a client certificate of the client
// CA (--metrics_tls, --metrics_client_certificate).
ServerOptions MetricsForClientCertificates(const neuralmesh::testing::TestCertificates& tls) {
  ServerOptions options;
  options.security.tls.certificate_chain = tls.server_chain;
  options.security.tls.private_key = tls.server_key;
  options.security.tls.client_ca_certificates = tls.ca;
  options.metrics_tls = true;
  options.metrics_client_certificate = true;
  return options;
}

TEST(MetricsHttpTest, CountsASessionsWorkAndTheCallsByStatus) {
  std::unique_ptr<ReconstructionServer> server = StartWithMetrics();
  ASSERT_NE(server, nullptr);
  auto stub = testing::NetworkService(*server);

  std::map<std::string, double> before = Scrape(*server);
  EXPECT_EQ(before["neuralmesh_sessions_created_total"], 0);
  EXPECT_EQ(before["neuralmesh_sessions{state=\"learning\"}"], 0);
  EXPECT_EQ(before[absl::StrCat("neuralmesh_build_info{version=\"", NeuralmeshVersion(), "\"}")],
            1);

  const std::string id = testing::MustCreate(*stub, testing::CreateRequest(300));
  v1::UploadPointsResponse uploaded;
  // With colours: the meshes are painted.
  const PointCloud colored = neuralmesh::testing::ColoredUnitSpherePoints(3000, 1);
  ASSERT_TRUE(testing::Upload(*stub, id, colored, 3, &uploaded).ok());
  grpc::Status missing;
  testing::GetSession(*stub, "s-nosuchsession", &missing);
  ASSERT_EQ(missing.error_code(), grpc::StatusCode::NOT_FOUND);
  ASSERT_TRUE(testing::Finish(*stub, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(testing::WaitFinal(*stub, id, &final_mesh).ok());
  const v1::Session finished = testing::GetSession(*stub, id);

  std::map<std::string, double> after = Scrape(*server);
  EXPECT_EQ(after["neuralmesh_sessions_created_total"], 1);
  EXPECT_EQ(after["neuralmesh_points_accepted_total"], 3000);
  EXPECT_EQ(after["neuralmesh_points"], 3000);
  EXPECT_EQ(after["neuralmesh_sessions{state=\"finished\"}"], 1);
  EXPECT_EQ(after["neuralmesh_sessions{state=\"learning\"}"], 0);
  EXPECT_EQ(after["neuralmesh_sessions_ended_total{state=\"finished\"}"], 1);
  EXPECT_EQ(after["neuralmesh_mesh_vertices"], 300);
  // Every Basic Step of the session, as the session itself counts them.
  EXPECT_EQ(after["neuralmesh_basic_steps_total"], finished.learning().basic_steps());
  EXPECT_GT(after["neuralmesh_learning_seconds_total"], 0);
  EXPECT_GE(after["neuralmesh_meshes_published_total"], 1);
  EXPECT_GE(after["neuralmesh_mesh_bytes_published_total"], final_mesh.draco_mesh().size());
  EXPECT_EQ(before["neuralmesh_meshes_painted_total"], 0);
  EXPECT_GE(after["neuralmesh_meshes_painted_total"], after["neuralmesh_meshes_published_total"]);
  EXPECT_GT(after["neuralmesh_painting_seconds_total"], 0);
  EXPECT_EQ(after[Handled("CreateSession", "unary", "OK")], 1);
  EXPECT_EQ(after[Handled("UploadPoints", "client_stream", "OK")], 1);
  EXPECT_EQ(after[Handled("GetSession", "unary", "NotFound")], 1);
  EXPECT_EQ(after[Handled("GetSession", "unary", "OK")], 1);
  EXPECT_EQ(after[Handled("GetMesh", "unary", "OK")], 1);
  EXPECT_EQ(after[absl::StrCat("grpc_server_started_total{", kService,
                               ",grpc_method=\"GetSession\",grpc_type=\"unary\"}")],
            2);
  EXPECT_EQ(after[absl::StrCat("grpc_server_handling_seconds_count{", kService,
                               ",grpc_method=\"GetSession\",grpc_type=\"unary\"}")],
            2);
  EXPECT_EQ(after[absl::StrCat("grpc_server_handling_seconds_bucket{", kService,
                               ",grpc_method=\"GetSession\",grpc_type=\"unary\",le=\"+Inf\"}")],
            2);

  ASSERT_TRUE(testing::Delete(*stub, id).ok());
  std::map<std::string, double> deleted = Scrape(*server);
  EXPECT_EQ(deleted["neuralmesh_sessions_deleted_total{reason=\"call\"}"], 1);
  EXPECT_EQ(deleted["neuralmesh_sessions{state=\"finished\"}"], 0);
  EXPECT_EQ(deleted["neuralmesh_points"], 0);
  // Counters never go back.
  EXPECT_EQ(deleted["neuralmesh_points_accepted_total"], 3000);
  EXPECT_EQ(deleted["neuralmesh_sessions_ended_total{state=\"finished\"}"], 1);
}

TEST(MetricsHttpTest, CountsCancelledFailedAndIdleSessions) {
  ServerOptions options;
  options.limits.idle_timeout = absl::Milliseconds(300);
  std::unique_ptr<ReconstructionServer> server = StartWithMetrics(options);
  ASSERT_NE(server, nullptr);
  auto stub = testing::NetworkService(*server);

  const std::string cancelled = testing::MustCreate(*stub, testing::CreateRequest(300));
  ASSERT_TRUE(testing::Cancel(*stub, cancelled).ok());
  // Learning stalls and the finishing session fails (session.h).
  const std::string failed = testing::MustCreate(*stub, testing::StallingRequest());
  v1::UploadPointsResponse uploaded;
  ASSERT_TRUE(testing::Upload(*stub, failed, testing::TorusPoints(2000, 9), 1, &uploaded).ok());
  ASSERT_TRUE(testing::Finish(*stub, failed).ok());

  std::map<std::string, double> samples;
  const absl::Time deadline = absl::Now() + absl::Seconds(60);
  while (absl::Now() < deadline) {
    samples = Scrape(*server);
    if (samples["neuralmesh_sessions_deleted_total{reason=\"idle\"}"] == 2) break;
    absl::SleepFor(absl::Milliseconds(100));
  }
  EXPECT_EQ(samples["neuralmesh_sessions_ended_total{state=\"cancelled\"}"], 1);
  EXPECT_EQ(samples["neuralmesh_sessions_ended_total{state=\"failed\"}"], 1);
  EXPECT_EQ(samples["neuralmesh_sessions_deleted_total{reason=\"idle\"}"], 2);
  EXPECT_EQ(samples["neuralmesh_sessions_deleted_total{reason=\"call\"}"], 0);
  EXPECT_EQ(samples["neuralmesh_sessions{state=\"cancelled\"}"], 0);
  EXPECT_EQ(samples[Handled("CancelSession", "unary", "OK")], 1);
}

TEST(MetricsHttpTest, ARestoredSessionsPointsAreHeldButNotAcceptedAgain) {
  const std::string state_dir = neuralmesh::testing::MakeTempDir("metrics_state");
  ServerOptions options;
  options.state_dir = state_dir;
  options.state_sync = false;
  {
    std::unique_ptr<ReconstructionServer> server = StartWithMetrics(options);
    ASSERT_NE(server, nullptr);
    auto stub = testing::NetworkService(*server);
    const std::string id = testing::MustCreate(*stub, testing::CreateRequest(5000));
    v1::UploadPointsResponse uploaded;
    ASSERT_TRUE(testing::Upload(*stub, id, testing::SpherePoints(2000, 2), 2, &uploaded).ok());
    EXPECT_EQ(Scrape(*server)["neuralmesh_points_accepted_total"], 2000);
  }
  std::unique_ptr<ReconstructionServer> server = StartWithMetrics(options);
  ASSERT_NE(server, nullptr);
  EXPECT_EQ(server->WaitForRestore().sessions, 1u);
  std::map<std::string, double> samples = Scrape(*server);
  EXPECT_EQ(samples["neuralmesh_sessions_to_restore"], 0);
  EXPECT_EQ(samples["neuralmesh_points"], 2000);
  EXPECT_EQ(samples["neuralmesh_points_accepted_total"], 0);
  EXPECT_EQ(samples["neuralmesh_sessions_created_total"], 0);
  EXPECT_EQ(samples["neuralmesh_sessions{state=\"collecting\"}"] +
                samples["neuralmesh_sessions{state=\"learning\"}"],
            1);
}

TEST(MetricsHttpTest, HealthAndOtherPages) {
  std::unique_ptr<ReconstructionServer> server = StartWithMetrics();
  ASSERT_NE(server, nullptr);
  const HttpReply health = HttpGet(server->metrics_port(), "/healthz");
  EXPECT_EQ(health.status, 200);
  EXPECT_EQ(health.body, "serving\n");
  const HttpReply index = HttpGet(server->metrics_port(), "/");
  EXPECT_EQ(index.status, 200);
  EXPECT_THAT(index.body, HasSubstr("/metrics"));
  const HttpReply missing = HttpGet(server->metrics_port(), "/metric");
  EXPECT_EQ(missing.status, 404);
  EXPECT_THAT(missing.body, HasSubstr("no page /metric; this server has /metrics and /healthz"));

  MetricsSources stopping;
  stopping.serving = [] { return false; };
  http::HttpRequest request;
  request.method = "GET";
  request.path = "/healthz";
  const http::HttpResponse answer = AnswerMetricsRequest(request, stopping);
  EXPECT_EQ(answer.status, 503);
  EXPECT_EQ(answer.body, "shutting down\n");
}

TEST(MetricsHttpTest, NoPageWithoutAPortAndClearErrorsForBadOnes) {
  std::unique_ptr<ReconstructionServer> plain = testing::StartServer(/*listen=*/true);
  ASSERT_NE(plain, nullptr);
  EXPECT_EQ(plain->metrics_port(), -1);

  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.metrics_port = 65536;
  absl::StatusOr<std::unique_ptr<ReconstructionServer>> out_of_range =
      ReconstructionServer::Start(options);
  ASSERT_FALSE(out_of_range.ok());
  EXPECT_EQ(out_of_range.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(out_of_range.status().message(), HasSubstr("metrics_port is 65536"));

  absl::StatusOr<std::unique_ptr<http::HttpServer>> taken = http::HttpServer::Start(
      "127.0.0.1", 0, [](const http::HttpRequest&) { return http::TextResponse(200, ""); });
  ASSERT_TRUE(taken.ok());
  options.metrics_port = (*taken)->port();
  absl::StatusOr<std::unique_ptr<ReconstructionServer>> in_use =
      ReconstructionServer::Start(options);
  ASSERT_FALSE(in_use.ok());
  EXPECT_EQ(in_use.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(in_use.status().message(), HasSubstr("metrics page: cannot listen on 127.0.0.1:"));
}

constexpr char kMetricsToken[] = "metrics-token-0123456789";

TEST(MetricsHttpTest, OverTlsWithATokenOnlyTheTokensHolderReadsTheMetrics) {
  absl::StatusOr<neuralmesh::testing::TestCertificates> certificates =
      neuralmesh::testing::MakeTestCertificates(neuralmesh::testing::MakeTempDir("metrics_tls"));
  ASSERT_TRUE(certificates.ok()) << certificates.status();
  ServerOptions options;
  options.security.tls.certificate_chain = certificates->named_server_chain;
  options.security.tls.private_key = certificates->named_server_key;
  options.metrics_tls = true;
  options.metrics_token = kMetricsToken;
  std::unique_ptr<ReconstructionServer> server = StartWithMetrics(options);
  ASSERT_NE(server, nullptr);
  EXPECT_EQ(server->metrics_url(),
            absl::StrCat("https://127.0.0.1:", server->metrics_port(), "/metrics"));
  HttpsTarget target;
  target.port = server->metrics_port();
  target.ca = certificates->ca;
  target.host = "scans.example.test";

  std::string error;
  const HttpReply granted = HttpsGet(target, "/metrics", kMetricsToken, &error);
  EXPECT_EQ(granted.status, 200) << error;
  EXPECT_THAT(granted.body, HasSubstr("neuralmesh_sessions{state=\"learning\"} 0"));
  const HttpReply bare = HttpsGet(target, "/metrics");
  EXPECT_EQ(bare.status, 401);
  EXPECT_EQ(bare.Header("www-authenticate"), "Bearer realm=\"neuralmesh metrics\"");
  EXPECT_THAT(bare.body, HasSubstr("/metrics needs the token of --metrics_token_file"));
  EXPECT_THAT(bare.body, Not(HasSubstr("neuralmesh_")));
  const HttpReply wrong = HttpsGet(target, "/metrics", "metrics-token-9876543210");
  EXPECT_EQ(wrong.status, 401);
  EXPECT_THAT(wrong.body, HasSubstr("refused the token"));
  // Probes need no token.
  EXPECT_EQ(HttpsGet(target, "/healthz").status, 200);
  // Plain HTTP is not served.
  const HttpReply plain = HttpGet(server->metrics_port(), "/metrics");
  EXPECT_EQ(plain.status, 400);
  EXPECT_THAT(plain.body, HasSubstr("speaks HTTPS only"));

  // A new token takes over from the next request; a bad one leaves the old in place.
  EXPECT_EQ(server->ReplaceMetricsToken("short").code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(HttpsGet(target, "/metrics", kMetricsToken).status, 200);
  ASSERT_TRUE(server->ReplaceMetricsToken("another-metrics-token").ok());
  EXPECT_EQ(HttpsGet(target, "/metrics", kMetricsToken).status, 401);
  EXPECT_EQ(HttpsGet(target, "/metrics", "another-metrics-token").status, 200);

  // A renewed certificate (here for 127.0.0.1) serves the metrics page too.
  HttpsTarget at_address = target;
  at_address.host = "127.0.0.1";
  EXPECT_EQ(HttpsGet(at_address, "/healthz").status, 0);
  ServerTls renewed;
  renewed.certificate_chain = certificates->server_chain;
  renewed.private_key = certificates->server_key;
  ASSERT_TRUE(server->ReplaceTls(renewed).ok());
  EXPECT_EQ(HttpsGet(at_address, "/healthz", "", &error).status, 200) << error;
  // A key of another certificate is refused, and the page keeps the renewed one.
  renewed.private_key = certificates->client_key;
  EXPECT_EQ(server->ReplaceTls(renewed).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(HttpsGet(at_address, "/healthz").status, 200);

  // Without a token from the start, none can be added.
  std::unique_ptr<ReconstructionServer> open = StartWithMetrics();
  ASSERT_NE(open, nullptr);
  EXPECT_EQ(open->metrics_url(),
            absl::StrCat("http://127.0.0.1:", open->metrics_port(), "/metrics"));
  EXPECT_EQ(open->ReplaceMetricsToken(kMetricsToken).code(), absl::StatusCode::kFailedPrecondition);
}

// --metrics_client_certificate: /metrics for clients with a certificate of the server's client
// CAs only; probes without one still reach /healthz; a renewed CA takes over on ReplaceTls.
TEST(MetricsHttpTest, WithClientCertificatesOnlyAClientOfTheClientCaReadsTheMetrics) {
  absl::StatusOr<neuralmesh::testing::TestCertificates> certificates =
      neuralmesh::testing::MakeTestCertificates(neuralmesh::testing::MakeTempDir("metrics_mtls"));
  ASSERT_TRUE(certificates.ok()) << certificates.status();
  ServerOptions options = MetricsForClientCertificates(*certificates);
  std::unique_ptr<ReconstructionServer> server = StartWithMetrics(options);
  ASSERT_NE(server, nullptr);
  HttpsTarget target;
  target.port = server->metrics_port();
  target.ca = certificates->ca;

  std::string error;
  const HttpReply bare = HttpsGet(target, "/metrics", "", &error);
  EXPECT_EQ(bare.status, 403) << error;
  EXPECT_EQ(bare.body,
            "/metrics needs a client certificate signed by the server's client CA "
            "(--tls_client_ca_file)\n");
  EXPECT_EQ(HttpsGet(target, "/healthz").status, 200) << "probes need no certificate";

  HttpsTarget client = target;
  client.client_chain = certificates->client_chain;
  client.client_key = certificates->client_key;
  const HttpReply scraped = HttpsGet(client, "/metrics", "", &error);
  EXPECT_EQ(scraped.status, 200) << error;
  EXPECT_THAT(scraped.body, HasSubstr("neuralmesh_sessions{state=\"learning\"} 0"));
  HttpsTarget stranger = target;
  stranger.client_chain = certificates->other_client_chain;
  stranger.client_key = certificates->other_client_key;
  EXPECT_EQ(HttpsGet(stranger, "/metrics").status, 0) << "another CA's client was let in";

  // The client CAs renewed with the certificate: the other CA's clients now, not the first's.
  ServerTls renewed = options.security.tls;
  renewed.client_ca_certificates = certificates->other_ca;
  ASSERT_TRUE(server->ReplaceTls(renewed).ok());
  EXPECT_EQ(HttpsGet(stranger, "/metrics", "", &error).status, 200) << error;
  EXPECT_EQ(HttpsGet(client, "/metrics").status, 0);

  // It needs the page over TLS, and client CAs.
  options.metrics_client_certificate = true;
  options.security.tls.client_ca_certificates.clear();
  options.address = "127.0.0.1:0";
  options.metrics_port = 0;
  absl::Status status = ReconstructionServer::Start(options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("it needs metrics_tls and client CAs"));
}

// With client roles by certificate (--client_roles_file), /metrics answers only clients whose
// certificate's common name has a role, as the roles stand after a renewal (SIGHUP).
TEST(MetricsHttpTest, WithClientRolesOnlyACommonNameWithARoleReadsTheMetrics) {
  absl::StatusOr<neuralmesh::testing::TestCertificates> certificates =
      neuralmesh::testing::MakeTestCertificates(neuralmesh::testing::MakeTempDir("metrics_roles"));
  ASSERT_TRUE(certificates.ok()) << certificates.status();
  ServerOptions options = MetricsForClientCertificates(*certificates);
  options.security.client_roles = {{"neuralmesh-test-client", AccessRole::kReader}};
  std::unique_ptr<ReconstructionServer> server = StartWithMetrics(options);
  ASSERT_NE(server, nullptr);
  HttpsTarget client;
  client.port = server->metrics_port();
  client.ca = certificates->ca;
  client.client_chain = certificates->client_chain;
  client.client_key = certificates->client_key;
  HttpsTarget second = client;
  second.client_chain = certificates->second_client_chain;
  second.client_key = certificates->second_client_key;

  std::string error;
  EXPECT_EQ(HttpsGet(client, "/metrics", "", &error).status, 200) << error;
  const HttpReply refused = HttpsGet(second, "/metrics", "", &error);
  EXPECT_EQ(refused.status, 403) << error;
  EXPECT_EQ(refused.body,
            "the client certificate's common name \"neuralmesh-test-second_client\" has no role "
            "on this server (--client_roles_file)\n");
  EXPECT_EQ(HttpsGet(second, "/healthz").status, 200) << "probes need no role";

  ASSERT_TRUE(
      server->ReplaceClientRoles({{"neuralmesh-test-second_client", AccessRole::kUser}}).ok());
  EXPECT_EQ(HttpsGet(second, "/metrics", "", &error).status, 200) << error;
  EXPECT_EQ(HttpsGet(client, "/metrics").status, 403);
}

TEST(MetricsHttpTest, TlsAndATokenNeedAMetricsPageAndTlsNeedsACertificate) {
  ServerOptions options;
  options.address = "127.0.0.1:0";
  options.metrics_tls = true;
  absl::Status status = ReconstructionServer::Start(options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("there is none (metrics_port)"));
  options.metrics_port = 0;
  status = ReconstructionServer::Start(options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("the server's TLS certificate, and there is none"));
  options.metrics_tls = false;
  options.metrics_token = "short";
  status = ReconstructionServer::Start(options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), StartsWith("the metrics token has 5 characters"));
  options.metrics_port = -1;
  options.metrics_token = kMetricsToken;
  status = ReconstructionServer::Start(options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  std::unique_ptr<ReconstructionServer> without = testing::StartServer(/*listen=*/true);
  ASSERT_NE(without, nullptr);
  EXPECT_EQ(without->metrics_url(), "");
}

}  // namespace
}  // namespace neuralmesh::server
