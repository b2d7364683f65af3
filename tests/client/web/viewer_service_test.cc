// Tests of the live viewer's HTTP side (client/web/viewer_service.h, http_server.h) against an
// in-process neuralmesh server, through real HTTP on 127.0.0.1.
#include "client/web/viewer_service.h"

#include <gmock/gmock.h>
#include <grpcpp/server_builder.h>
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "client/web/run_view.h"
#include "client/web/viewer_key.h"
#include "core/io/draco_codec.h"
#include "core/io/mesh_io.h"
#include "core/sampling/implicit_surfaces.h"
#include "http/http_server.h"
#include "tests/client/web/viewer_test_support.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/shapes.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::client::web {

using ::neuralmesh::http::HttpRequest;
using ::neuralmesh::http::HttpResponse;
using ::neuralmesh::http::HttpServer;
using ::neuralmesh::http::kMaxRequestHeadBytes;

namespace {

using ::neuralmesh::testing::HttpGet;
using ::neuralmesh::testing::HttpReply;
using ::neuralmesh::testing::SendRawHttp;
using ::testing::HasSubstr;
namespace st = ::neuralmesh::server::testing;

uint64_t HeaderNumber(const HttpReply& reply, const std::string& name) {
  uint64_t value = 0;
  auto it = reply.headers.find(name);
  EXPECT_TRUE(it != reply.headers.end() && absl::SimpleAtoi(it->second, &value))
      << name << " is missing or not a number";
  return value;
}

class ViewerServiceTest : public ::testing::Test {
 protected:
  void SetUp() override { StartViewer(absl::Milliseconds(300)); }
  void TearDown() override { StopViewer(); }

  void StartViewer(absl::Duration poll_timeout,
                   absl::Duration relay_idle_timeout = absl::Seconds(60),
                   const std::string& key = "") {
    server_ = st::StartServer(/*listen=*/false);
    ASSERT_NE(server_, nullptr);
    service_ = st::InProcessService(*server_);
    ViewerOptions options;
    options.web_root = DefaultWebRoot();
    options.poll_timeout = poll_timeout;
    options.relay_idle_timeout = relay_idle_timeout;
    options.key = key;
    viewer_ = std::make_unique<ViewerService>(
        std::make_unique<ReconstructionClient>(server_->InProcessChannel(), ClientOptions{}),
        options);
    absl::StatusOr<std::unique_ptr<HttpServer>> http = HttpServer::Start(
        "127.0.0.1", 0, [this](const HttpRequest& r) { return viewer_->Handle(r); });
    ASSERT_TRUE(http.ok()) << http.status();
    http_ = *std::move(http);
    port_ = http_->port();
  }

  void StopViewer() {
    if (viewer_ != nullptr) viewer_->Stop();
    http_.reset();
    viewer_.reset();
    service_.reset();
    server_.reset();
  }

  std::string MeshTarget(const std::string& id, uint64_t after) {
    return absl::StrCat("/api/sessions/", id, "/mesh?after=", after);
  }

  std::unique_ptr<server::ReconstructionServer> server_;
  std::unique_ptr<v1::ReconstructionService::Stub> service_;
  std::unique_ptr<ViewerService> viewer_;
  std::unique_ptr<HttpServer> http_;
  int port_ = 0;
};

TEST_F(ViewerServiceTest, ServesThePageAndItsScriptsOnly) {
  ASSERT_TRUE(CheckWebRoot(DefaultWebRoot()).ok())
      << CheckWebRoot(DefaultWebRoot()) << " (scripts/install-deps.sh installs three.js)";
  const HttpReply page = HttpGet(port_, "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_EQ(page.Header("content-type"), "text/html; charset=utf-8");
  EXPECT_THAT(page.body, HasSubstr("/static/viewer.js"));
  EXPECT_EQ(HttpGet(port_, "/static/viewer.js").Header("content-type"),
            "text/javascript; charset=utf-8");
  const HttpReply wasm = HttpGet(port_, "/vendor/three/examples/jsm/libs/draco/draco_decoder.wasm");
  EXPECT_EQ(wasm.status, 200);
  EXPECT_EQ(wasm.Header("content-type"), "application/wasm");
  EXPECT_EQ(wasm.body.substr(0, 4), std::string("\0asm", 4)) << "a WebAssembly module";
  EXPECT_EQ(HttpGet(port_, "/vendor/three/build/three.module.js").status, 200);

  for (const std::string target :
       {"/static/../CMakeLists.txt", "/static/%2e%2e/CMakeLists.txt", "/static/.gitignore",
        "/static/sub/x.js", "/vendor/three/package.json", "/vendor/three/build/../../../x",
        "/vendor/three/examples/jsm/.x", "/static/", "/nowhere", "/api/nothing"}) {
    const HttpReply reply = HttpGet(port_, target);
    EXPECT_EQ(reply.status, 404) << target;
    EXPECT_EQ(reply.Header("content-type"), "application/json") << target;
    EXPECT_THAT(reply.body, HasSubstr("\"error\":\"no such ")) << target;
  }
}

// --view_key_file: nothing without the key; the page opened with ?key= once sends the browser
// on with a cookie, and the cookie or a bearer header lets every later request in.
TEST_F(ViewerServiceTest, AKeyedViewerAnswersOnlyRequestsThatBringTheKey) {
  StopViewer();
  const std::string key = "0123456789-abcdef";
  StartViewer(absl::Milliseconds(300), absl::Seconds(60), key);
  const std::string id = st::MustCreate(*service_, st::CreateRequest(500));
  for (const std::string& target : std::vector<std::string>{
           "/", "/static/viewer.js", "/api/sessions", "/api/sessions/" + id + "/mesh?after=0",
           "/?key=0123456789-abcdeF"}) {
    const HttpReply refused = HttpGet(port_, target);
    EXPECT_EQ(refused.status, 401) << target;
    EXPECT_THAT(refused.body, HasSubstr("this viewer needs its key")) << target;
  }
  const HttpReply opened = HttpGet(port_, "/?key=" + key + "&session=" + id);
  EXPECT_EQ(opened.status, 303);
  EXPECT_EQ(opened.Header("location"), "/?session=" + id);
  const std::string cookie = opened.Header("set-cookie");
  EXPECT_THAT(cookie, HasSubstr(ViewerKeyCookieName(key) + "=" + key + ";"));
  const std::string with_cookie =
      absl::StrCat("GET /api/sessions HTTP/1.1\r\nHost: 127.0.0.1\r\nCookie: ",
                   cookie.substr(0, cookie.find(';')), "\r\n\r\n");
  const HttpReply listed = SendRawHttp(port_, with_cookie);
  EXPECT_EQ(listed.status, 200);
  EXPECT_THAT(listed.body, HasSubstr(id));
  const HttpReply page = SendRawHttp(
      port_, "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + key + "\r\n\r\n");
  EXPECT_EQ(page.status, 200);
  EXPECT_THAT(page.body, HasSubstr("/static/viewer.js"));
}

TEST_F(ViewerServiceTest, AnswersMalformedRequestsWithTheirStatus) {
  HttpReply reply = SendRawHttp(port_, "NONSENSE\r\n\r\n");
  EXPECT_EQ(reply.status, 400);
  EXPECT_THAT(reply.body, HasSubstr("malformed request line"));
  reply = SendRawHttp(port_, "GET / HTTP/1.1\r\nContent-Length: 3\r\n\r\nabc");
  EXPECT_EQ(reply.status, 400);
  reply = SendRawHttp(port_, "POST /api/sessions HTTP/1.1\r\nContent-Length: 0\r\n\r\n");
  EXPECT_EQ(reply.status, 405);
  EXPECT_EQ(reply.Header("allow"), "GET, HEAD");
  reply = SendRawHttp(port_,
                      "GET /" + std::string(kMaxRequestHeadBytes + 10, 'a') + " HTTP/1.1\r\n\r\n");
  EXPECT_EQ(reply.status, 431);
  reply = SendRawHttp(port_, "HEAD / HTTP/1.1\r\n\r\n");
  EXPECT_EQ(reply.status, 200);
  EXPECT_TRUE(reply.body.empty()) << "a HEAD response has no body";
  EXPECT_GT(HeaderNumber(reply, "content-length"), 0u);
  // The server still answers after all that.
  EXPECT_EQ(HttpGet(port_, "/api/sessions").status, 200);
}

TEST_F(ViewerServiceTest, ListsTheSessionsAsJson) {
  EXPECT_EQ(HttpGet(port_, "/api/sessions").body, "[]");
  v1::CreateSessionRequest request = st::CreateRequest(500);
  request.set_name("scan \"7\"");
  const std::string id = st::MustCreate(*service_, request);
  const HttpReply list = HttpGet(port_, "/api/sessions");
  EXPECT_EQ(list.status, 200);
  EXPECT_EQ(list.Header("content-type"), "application/json");
  EXPECT_THAT(list.body, HasSubstr(absl::StrCat("\"session_id\":\"", id, "\"")));
  EXPECT_THAT(list.body, HasSubstr("\"name\":\"scan \\\"7\\\"\"")) << "escaped";
  EXPECT_THAT(list.body, HasSubstr("\"target_vertices\":500"));
  const HttpReply one = HttpGet(port_, "/api/sessions/" + id);
  EXPECT_EQ(one.status, 200);
  EXPECT_THAT(one.body, HasSubstr("\"state\":\"collecting\""));
  EXPECT_THAT(one.body, HasSubstr("\"stalled\":false"));
  // A session whose learner stalls on its first points says so while it waits for more.
  const std::string stalled_id = st::MustCreate(*service_, st::StallingRequest());
  v1::UploadPointsResponse response;
  ASSERT_TRUE(st::Upload(*service_, stalled_id, st::TorusPoints(2000, 9), 1, &response).ok());
  std::string body;
  for (int i = 0; i < 500 && !absl::StrContains(body, "\"stalled\":true"); ++i) {
    absl::SleepFor(absl::Milliseconds(20));
    body = HttpGet(port_, "/api/sessions/" + stalled_id).body;
  }
  EXPECT_THAT(body, HasSubstr("\"stalled\":true"));
  EXPECT_THAT(body, HasSubstr("\"state\":\"learning\""));
  const HttpReply unknown = HttpGet(port_, "/api/sessions/s-unknown");
  EXPECT_EQ(unknown.status, 404);
  EXPECT_THAT(unknown.body, HasSubstr("s-unknown"));
}

TEST_F(ViewerServiceTest, LongPollsFollowALiveSessionCoarseToFineToItsFinalMesh) {
  v1::CreateSessionRequest request = st::CreateRequest(2000, /*refresh_ms=*/50);
  for (uint64_t lod : {250, 500, 1000}) request.mutable_config()->add_lod_milestones(lod);
  request.mutable_config()->add_lod_milestones(2000);
  const std::string id = st::MustCreate(*service_, request);

  const HttpReply early = HttpGet(port_, MeshTarget(id, 0));
  EXPECT_EQ(early.status, 204) << "no mesh before the first points, within the poll timeout";
  EXPECT_TRUE(early.body.empty());

  const PointCloud points = st::TorusPoints(40000, 3);
  std::thread upload([&] {
    v1::UploadPointsResponse response;
    for (size_t part = 0; part < 4; ++part) {
      const PointCloud quarter = PointRange(points, part * 10000, (part + 1) * 10000);
      ASSERT_TRUE(st::Upload(*service_, id, quarter, 5, &response).ok());
      absl::SleepFor(absl::Milliseconds(100));
    }
    ASSERT_TRUE(st::Finish(*service_, id).ok());
  });

  std::vector<uint64_t> sequences;
  std::vector<uint64_t> vertex_counts;
  HttpReply last_mesh;
  uint64_t after = 0;
  const absl::Time deadline = absl::Now() + absl::Seconds(60);
  while (absl::Now() < deadline) {
    const HttpReply reply = HttpGet(port_, MeshTarget(id, after));
    if (reply.status == 204) continue;
    if (reply.status == 410) {
      EXPECT_THAT(reply.body, HasSubstr(absl::StrCat("its last mesh was sequence ", after)));
      break;
    }
    ASSERT_EQ(reply.status, 200) << reply.body;
    EXPECT_EQ(reply.Header("content-type"), "application/x-draco");
    const uint64_t sequence = HeaderNumber(reply, "x-neuralmesh-sequence");
    EXPECT_GT(sequence, after) << "only newer meshes";
    const uint64_t taken = HeaderNumber(reply, "x-neuralmesh-snapshot-time-us");
    EXPECT_LE(taken, static_cast<uint64_t>(absl::ToUnixMicros(absl::Now())));
    EXPECT_GT(taken, static_cast<uint64_t>(absl::ToUnixMicros(absl::Now() - absl::Minutes(1))));
    absl::StatusOr<TriangleMesh> mesh = DecodeMesh(reply.body);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    EXPECT_EQ(mesh->positions.size(), HeaderNumber(reply, "x-neuralmesh-vertices"));
    EXPECT_EQ(mesh->faces.size(), HeaderNumber(reply, "x-neuralmesh-faces"));
    sequences.push_back(sequence);
    vertex_counts.push_back(mesh->positions.size());
    after = sequence;
    last_mesh = reply;
  }
  upload.join();
  ASSERT_GE(sequences.size(), 2u) << "the browser sees the mesh refine, not only the end";
  EXPECT_LT(vertex_counts.front(), vertex_counts.back()) << "coarse to fine";
  EXPECT_EQ(last_mesh.Header("x-neuralmesh-kind"), "final");
  EXPECT_EQ(last_mesh.Header("x-neuralmesh-state"), "finished");
  EXPECT_EQ(HeaderNumber(last_mesh, "x-neuralmesh-genus"), 1u);
  EXPECT_EQ(HeaderNumber(last_mesh, "x-neuralmesh-points-received"), 40000u);
  absl::StatusOr<TriangleMesh> final_mesh = DecodeMesh(last_mesh.body);
  ASSERT_TRUE(final_mesh.ok());
  EXPECT_EQ(final_mesh->positions.size(), 2000u);
  absl::StatusOr<std::unique_ptr<ImplicitSurface>> torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.4);
  ASSERT_TRUE(torus.ok());
  EXPECT_LT(st::MaxVertexDistance(*final_mesh, **torus), 0.02)
      << "the bytes a browser gets are the learned torus";

  // A page opened later gets the final mesh first, then the end.
  const HttpReply late = HttpGet(port_, MeshTarget(id, 0));
  EXPECT_EQ(late.status, 200);
  EXPECT_EQ(HeaderNumber(late, "x-neuralmesh-sequence"), sequences.back());
  EXPECT_EQ(HttpGet(port_, MeshTarget(id, sequences.back())).status, 410);
}

TEST_F(ViewerServiceTest, ACancelledSessionEndsThePollWithGoneAndSaysWhy) {
  const std::string id = st::MustCreate(*service_, st::CreateRequest(20000, 50));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(st::Upload(*service_, id, st::SpherePoints(20000, 4), 2, &response).ok());
  HttpReply reply = HttpGet(port_, MeshTarget(id, 0));
  ASSERT_EQ(reply.status, 200) << "a mesh exists once points are in";
  ASSERT_TRUE(st::Cancel(*service_, id).ok());
  uint64_t after = HeaderNumber(reply, "x-neuralmesh-sequence");
  for (int i = 0; i < 50; ++i) {
    reply = HttpGet(port_, MeshTarget(id, after));
    if (reply.status != 200 && reply.status != 204) break;
    if (reply.status == 200) after = HeaderNumber(reply, "x-neuralmesh-sequence");
  }
  EXPECT_EQ(reply.status, 410);
  EXPECT_THAT(reply.body, HasSubstr("cancelled"));
}

TEST_F(ViewerServiceTest, RejectsUnknownSessionsAndMalformedSequenceNumbers) {
  HttpReply reply = HttpGet(port_, MeshTarget("s-missing", 0));
  EXPECT_EQ(reply.status, 404);
  EXPECT_THAT(reply.body, HasSubstr("s-missing"));
  const std::string id = st::MustCreate(*service_, st::CreateRequest(500));
  for (const std::string after : {"x", "-1", "1.5", "99999999999999999999999"}) {
    reply = HttpGet(port_, absl::StrCat("/api/sessions/", id, "/mesh?after=", after));
    EXPECT_EQ(reply.status, 400) << after;
    EXPECT_THAT(reply.body, HasSubstr("is not a sequence number")) << after;
  }
}

// /api/sessions/ID/download: the latest mesh as a file in the format asked, named after the
// session, with its colours; the Draco bytes as the server published them.
TEST_F(ViewerServiceTest, DownloadsTheLatestMeshInTheFormatAsked) {
  v1::CreateSessionRequest request = st::CreateRequest(500);
  request.set_name("my scan/1");
  const std::string id = st::MustCreate(*service_, request);
  const std::string target = absl::StrCat("/api/sessions/", id, "/download");
  HttpReply reply = HttpGet(port_, target);
  EXPECT_EQ(reply.status, 409);
  EXPECT_THAT(reply.body, HasSubstr("has published no mesh yet"));

  v1::UploadPointsResponse response;
  ASSERT_TRUE(
      st::Upload(*service_, id, testing::ColoredUnitSpherePoints(4000, 8), 2, &response).ok());
  ASSERT_TRUE(st::Finish(*service_, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(st::WaitFinal(*service_, id, &final_mesh).ok());

  const std::string dir = testing::MakeTempDir("downloads");
  for (const std::string format : {"glb", "gltf", "ply", "obj", "off", "stl", "drc"}) {
    SCOPED_TRACE(format);
    reply = HttpGet(port_, absl::StrCat(target, "?format=", format));
    ASSERT_EQ(reply.status, 200) << reply.body;
    const std::string name = absl::StrCat("my_scan_1-", final_mesh.sequence(), ".", format);
    EXPECT_EQ(reply.Header("content-disposition"),
              absl::StrCat("attachment; filename=\"", name, "\""));
    if (format == "drc") {
      EXPECT_EQ(reply.body, final_mesh.draco_mesh());
    }
    const std::string path = dir + "/" + name;
    {
      std::ofstream out(path, std::ios::binary);
      out << reply.body;
    }
    const absl::StatusOr<TriangleMesh> mesh = ReadMesh(path);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    EXPECT_EQ(mesh->positions.size(), 500u);
    EXPECT_EQ(mesh->colors.empty(), format == "stl") << "colours in every format but STL";
  }
  reply = HttpGet(port_, target);
  EXPECT_EQ(reply.status, 200);
  EXPECT_EQ(reply.Header("content-type"), "model/gltf-binary") << "glb unless asked";
  EXPECT_EQ(reply.body.substr(0, 4), "glTF");

  reply = HttpGet(port_, target + "?format=xyz");
  EXPECT_EQ(reply.status, 400);
  EXPECT_THAT(reply.body, HasSubstr("format=xyz is not one of glb, gltf, ply, obj, off, stl, drc"));
  reply = HttpGet(port_, "/api/sessions/s-missing/download");
  EXPECT_EQ(reply.status, 404);
  EXPECT_THAT(reply.body, HasSubstr("s-missing"));
}

TEST_F(ViewerServiceTest, StopWakesAWaitingPollAtOnce) {
  StopViewer();
  StartViewer(absl::Seconds(30));
  const std::string id = st::MustCreate(*service_, st::CreateRequest(500));
  HttpReply reply;
  absl::Time answered;
  std::thread poll([&] {
    reply = HttpGet(port_, MeshTarget(id, 0));
    answered = absl::Now();
  });
  absl::SleepFor(absl::Milliseconds(300));
  const absl::Time stopped = absl::Now();
  viewer_->Stop();
  poll.join();
  EXPECT_EQ(reply.status, 503);
  EXPECT_THAT(reply.body, HasSubstr("shutting down"));
  EXPECT_LT(answered - stopped, absl::Seconds(5)) << "not after the 30 s poll timeout";
}

TEST_F(ViewerServiceTest, BrowsersShareOneWatchPerSessionAndIdleWatchesAreDropped) {
  StopViewer();
  StartViewer(absl::Milliseconds(300), /*relay_idle_timeout=*/absl::Milliseconds(500));
  const std::string id = st::MustCreate(*service_, st::CreateRequest(20000, 50));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(st::Upload(*service_, id, st::SpherePoints(20000, 4), 2, &response).ok());
  auto watchers = [&] { return st::GetSession(*service_, id).watchers(); };

  // The upload's call may still be counted for a moment after it returned.
  for (int i = 0; i < 100 && watchers() != 0; ++i) absl::SleepFor(absl::Milliseconds(20));
  ASSERT_EQ(watchers(), 0u);
  for (int page = 0; page < 3; ++page) EXPECT_EQ(HttpGet(port_, MeshTarget(id, 0)).status, 200);
  EXPECT_EQ(watchers(), 1u) << "three pages, one WatchSession stream";

  absl::SleepFor(absl::Milliseconds(700));
  viewer_->DropIdleRelays();
  uint32_t left = 1;
  for (int i = 0; i < 100 && left != 0; ++i) {
    absl::SleepFor(absl::Milliseconds(20));
    left = watchers();
  }
  EXPECT_EQ(left, 0u) << "the stream of a session nobody looks at is closed";
  EXPECT_EQ(HttpGet(port_, MeshTarget(id, 0)).status, 200) << "and opened again on demand";
  EXPECT_EQ(watchers(), 1u);
  ASSERT_TRUE(st::Cancel(*service_, id).ok());
}

TEST(ViewerServiceWithoutServerTest, AnUnreachableServerIsABadGateway) {
  ClientOptions options;
  options.call_timeout = absl::Seconds(2);
  ViewerOptions viewer_options;
  viewer_options.web_root = DefaultWebRoot();
  ViewerService viewer(
      std::make_unique<ReconstructionClient>(
          grpc::CreateChannel("127.0.0.1:1", grpc::InsecureChannelCredentials()), options),
      viewer_options);
  HttpRequest request;
  request.method = "GET";
  request.path = "/api/sessions";
  const HttpResponse response = viewer.Handle(request);
  EXPECT_EQ(response.status, 502);
  EXPECT_THAT(response.body, HasSubstr("ListSessions"));
  request.path = "/api/sessions/s-1/mesh";
  EXPECT_EQ(viewer.Handle(request).status, 502);
}

// A server that is up but answers every session call with UNAVAILABLE, as one restoring its
// sessions after a restart does (server/session_manager.h).
class RestoringService final : public v1::ReconstructionService::Service {
 public:
  grpc::Status ListSessions(grpc::ServerContext*, const v1::ListSessionsRequest*,
                            v1::ListSessionsResponse*) override {
    return Restoring();
  }
  grpc::Status GetSession(grpc::ServerContext*, const v1::GetSessionRequest*,
                          v1::Session*) override {
    return Restoring();
  }

 private:
  static grpc::Status Restoring() {
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        "the server is restoring its sessions after a restart (1 of 3 done)");
  }
};

TEST(ViewerServiceWithoutServerTest, AServerThatIsRestoringIsUnavailableForAMoment) {
  RestoringService service;
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  ASSERT_NE(server, nullptr);
  absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
      ReconstructionClient::Connect(absl::StrCat("127.0.0.1:", port));
  ASSERT_TRUE(client.ok()) << client.status();
  ViewerOptions viewer_options;
  viewer_options.web_root = DefaultWebRoot();
  ViewerService viewer(*std::move(client), viewer_options);

  HttpRequest request;
  request.method = "GET";
  for (const char* path : {"/api/sessions", "/api/sessions/s-1", "/api/sessions/s-1/mesh"}) {
    request.path = path;
    const HttpResponse response = viewer.Handle(request);
    EXPECT_EQ(response.status, 503) << path;
    EXPECT_THAT(response.body, HasSubstr("restoring its sessions after a restart (1 of 3 done)"))
        << path;
    EXPECT_THAT(response.headers,
                ::testing::Contains(std::make_pair(std::string("Retry-After"), std::string("1"))))
        << path;
  }
  server->Shutdown();
}

}  // namespace
}  // namespace neuralmesh::client::web
