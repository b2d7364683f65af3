// The live viewer in a real browser: headless Chromium (software WebGL) opens the page that
// `neuralmesh view` serves while a session learns on a neuralmesh server, and
// viewer_browser_driver.py reads what the page shows through the DevTools protocol. Checks
// that the page decodes every Draco mesh it gets to the server's counts, refines coarse to
// fine, ends on the final mesh, and draws it, in its vertices' colours once points with colours
// came.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "tests/client/subprocess.h"
#include "tests/client/web/viewer_test_support.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/shapes.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::client::web {
namespace {

namespace st = ::neuralmesh::server::testing;
using ::neuralmesh::testing::BackgroundProcess;
using ::neuralmesh::testing::WaitForViewerPort;

struct ShownMesh {
  uint64_t sequence = 0;
  std::string kind;
  uint64_t vertices = 0, faces = 0, server_vertices = 0, server_faces = 0, frames = 0;
  uint64_t draco_bytes = 0, delay_ms = 0;
  std::string colors;  // "true" when drawn in its vertices' colours.
};

TEST(ViewerBrowserTest, ThePageShowsALiveSessionCoarseToFineAndDrawsTheFinalMesh) {
  if (std::system("command -v chromium > /dev/null && /usr/bin/python3 -c 'import websocket'") !=
      0) {
    FAIL() << "chromium and Debian's python3-websocket are required (scripts/install-deps.sh)";
  }
  std::unique_ptr<server::ReconstructionServer> server = st::StartServer(/*listen=*/true);
  ASSERT_NE(server, nullptr);
  auto service = st::NetworkService(*server);
  v1::CreateSessionRequest request = st::CreateRequest(8000, /*refresh_ms=*/100);
  request.set_name("browser");
  const std::string id = st::MustCreate(*service, request);

  BackgroundProcess viewer("neuralmesh",
                           {"view", "--server=" + server->target(), "--listen=127.0.0.1:0"});
  const int port = WaitForViewerPort(viewer);
  ASSERT_NE(port, 0) << "neuralmesh view did not start: " << viewer.Stderr();

  const std::string dir = testing::MakeTempDir("browser");
  const std::string ready = dir + "/ready", out = dir + "/out", err = dir + "/err";
  const std::string command =
      absl::StrCat("/usr/bin/python3 tests/client/web/viewer_browser_driver.py --timeout=90 --url=",
                   "'http://127.0.0.1:", port, "/?session=", id, "' --ready_file=", ready, " > ",
                   out, " 2> ", err);
  int driver_exit = -1;
  std::thread driver([&] { driver_exit = std::system(command.c_str()); });

  // Points go in only once the page watches, in batches, so that it sees the mesh grow.
  for (int i = 0; i < 600 && !std::filesystem::exists(ready); ++i) {
    absl::SleepFor(absl::Milliseconds(50));
  }
  EXPECT_TRUE(std::filesystem::exists(ready)) << "the page never started watching";
  // The first half without colours, the second with.
  PointCloud points = st::TorusPoints(40000, 11);
  for (const Vec3f& p : points.positions) points.colors.push_back(testing::ColorOfPosition(p));
  for (size_t part = 0; part < 8; ++part) {
    PointCloud batch = PointRange(points, part * 5000, (part + 1) * 5000);
    if (part < 4) batch.colors.clear();
    v1::UploadPointsResponse response;
    ASSERT_TRUE(st::Upload(*service, id, batch, 1, &response).ok());
    absl::SleepFor(absl::Milliseconds(250));
  }
  ASSERT_TRUE(st::Finish(*service, id).ok());
  driver.join();

  const std::string output = testing::ReadWholeFile(out);
  ASSERT_EQ(driver_exit, 0) << "the browser driver failed:\n"
                            << output << testing::ReadWholeFile(err);
  std::vector<ShownMesh> shown;
  std::string end_line;
  double coverage = -1;
  std::string download_href, download_status, download_magic;
  size_t download_bytes = 0;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "mesh") {
      ShownMesh m;
      words >> m.sequence >> m.kind >> m.vertices >> m.faces >> m.server_vertices >>
          m.server_faces >> m.frames >> m.draco_bytes >> m.delay_ms >> m.colors;
      shown.push_back(m);
    } else if (word == "end") {
      end_line = line;
    } else if (word == "coverage") {
      words >> coverage;
    } else if (word == "download") {
      words >> download_href >> download_status >> download_bytes >> download_magic;
    }
  }
  SCOPED_TRACE(output);
  ASSERT_GE(shown.size(), 2u) << "the page showed the mesh as it learned, not only the end";
  for (size_t i = 0; i < shown.size(); ++i) {
    EXPECT_EQ(shown[i].vertices, shown[i].server_vertices) << "decoded in the browser";
    EXPECT_EQ(shown[i].faces, shown[i].server_faces);
    EXPECT_GT(shown[i].draco_bytes, 0u);
    EXPECT_LT(shown[i].delay_ms, 30000u) << "the page got each mesh while it was recent";
    if (i > 0) {
      EXPECT_GT(shown[i].sequence, shown[i - 1].sequence);
    }
  }
  EXPECT_LT(shown.front().vertices, shown.back().vertices) << "coarse to fine";
  EXPECT_EQ(shown.front().colors, "false") << "a mesh of points without colours";
  EXPECT_EQ(shown.back().colors, "true") << "drawn in the colours of the last points";
  for (size_t i = 1; i < shown.size(); ++i) {
    if (shown[i - 1].colors == "true") {
      EXPECT_EQ(shown[i].colors, "true") << "colours went away";
    }
  }
  EXPECT_EQ(shown.back().kind, "final");
  EXPECT_EQ(shown.back().vertices, 8000u);
  EXPECT_GT(shown.back().frames, 0u) << "the final mesh was drawn";
  std::istringstream end(end_line);
  std::string word, ended, webgl, error;
  size_t meshes = 0;
  end >> word >> ended >> webgl >> meshes >> error;
  EXPECT_EQ(ended, "gone") << "the stream ended after the final mesh";
  EXPECT_EQ(webgl, "true");
  EXPECT_EQ(error, "\"\"") << "no error on the page";
  // The driver looks every 50 ms, so it may miss a mesh the page showed between two looks.
  EXPECT_GE(meshes, shown.size());
  EXPECT_GT(coverage, 0.05) << "the coloured torus covers part of the canvas";
  EXPECT_EQ(download_href, absl::StrCat("/api/sessions/", id, "/download?format=glb"));
  EXPECT_EQ(download_status, "200") << "the page's save link gives the mesh";
  EXPECT_EQ(download_magic, "glTF");
  EXPECT_GT(download_bytes, 8000u * 12) << "the final mesh's positions at least";

  EXPECT_EQ(viewer.SignalAndWait(SIGTERM), 0) << "Ctrl-C stops the viewer cleanly";
}

TEST(ViewerBrowserTest, ThePageOpensOnTheNewestSessionStillLearning) {
  std::unique_ptr<server::ReconstructionServer> server = st::StartServer(/*listen=*/true);
  ASSERT_NE(server, nullptr);
  auto service = st::NetworkService(*server);
  const std::string finished = st::MustCreate(*service, st::CreateRequest(500));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(st::Upload(*service, finished, st::SpherePoints(2000, 1), 1, &response).ok());
  ASSERT_TRUE(st::Finish(*service, finished).ok());
  const std::string older = st::MustCreate(*service, st::CreateRequest(500));
  // A session whose learner stalls on its first points, waiting for more: listed as such.
  const std::string stalled = st::MustCreate(*service, st::StallingRequest());
  ASSERT_TRUE(st::Upload(*service, stalled, st::TorusPoints(2000, 9), 1, &response).ok());
  const std::string newest = st::MustCreate(*service, st::CreateRequest(500));
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(st::WaitFinal(*service, finished, &final_mesh).ok());
  const std::string newer_finished = st::MustCreate(*service, st::CreateRequest(500));
  ASSERT_TRUE(st::Cancel(*service, newer_finished).ok());

  bool paused = false;
  for (int i = 0; i < 600 && !paused; ++i) {
    absl::SleepFor(absl::Milliseconds(50));
    paused = st::GetSession(*service, stalled).learning().stalled();
  }
  ASSERT_TRUE(paused) << "the stalling session did not stall";

  BackgroundProcess viewer("neuralmesh",
                           {"view", "--server=" + server->target(), "--listen=127.0.0.1:0"});
  const int port = WaitForViewerPort(viewer);
  ASSERT_NE(port, 0) << "neuralmesh view did not start: " << viewer.Stderr();
  const std::string dir = testing::MakeTempDir("browser_newest");
  const std::string command = absl::StrCat(
      "/usr/bin/python3 tests/client/web/viewer_browser_driver.py --timeout=60 "
      "--stop_when_watching --print_sessions --url=http://127.0.0.1:",
      port, "/ --ready_file=", dir, "/ready > ", dir, "/out 2> ", dir, "/err");
  ASSERT_EQ(std::system(command.c_str()), 0) << testing::ReadWholeFile(dir + "/err");
  const std::string out = testing::ReadWholeFile(dir + "/out");
  EXPECT_THAT(out, ::testing::StartsWith(absl::StrCat("watching ", newest, "\n")))
      << "not the older live ones (" << older << ", " << stalled
      << "), nor the finished or cancelled ones";
  EXPECT_THAT(out, ::testing::HasSubstr(absl::StrCat(
                       "listed ", stalled, " test (learning, stalled: waiting for points)\n")));
  EXPECT_THAT(out, ::testing::HasSubstr(absl::StrCat("listed ", older, " test (collecting)\n")));
}

// A keyed viewer (neuralmesh view --view_key_file) of a server with one live session, over
// HTTPS with `https`'s server certificate when given: headless Chromium, trusting that
// certificate's key only, opens the URL with the key and must end up watching the session.
void ExpectTheKeyedPageWatchesTheLiveSession(const std::string& dir_name,
                                             const testing::TestCertificates* https) {
  std::unique_ptr<server::ReconstructionServer> server = st::StartServer(/*listen=*/true);
  ASSERT_NE(server, nullptr);
  auto service = st::NetworkService(*server);
  const std::string live = st::MustCreate(*service, st::CreateRequest(500));
  const std::string dir = testing::MakeTempDir(dir_name);
  const std::string key = "browser-key-0123456789";
  std::ofstream(dir + "/key") << key << "\n";

  std::vector<std::string> args = {"view", "--server=" + server->target(), "--listen=127.0.0.1:0",
                                   "--view_key_file=" + dir + "/key"};
  std::string driver_flags;
  if (https != nullptr) {
    args.push_back("--view_tls_cert_file=" + https->Path("server.pem"));
    args.push_back("--view_tls_key_file=" + https->Path("server.key"));
    driver_flags = " --trust_certificate=" + https->Path("server.pem");
  }
  const std::string scheme = https != nullptr ? "https" : "http";
  BackgroundProcess viewer("neuralmesh", args);
  const int port = WaitForViewerPort(viewer, scheme);
  ASSERT_NE(port, 0) << "neuralmesh view did not start: " << viewer.Stderr();
  const std::string command = absl::StrCat(
      "/usr/bin/python3 tests/client/web/viewer_browser_driver.py --timeout=60 "
      "--stop_when_watching",
      driver_flags, " --url=", scheme, "://127.0.0.1:", port, "/?key=", key, " --ready_file=", dir,
      "/ready > ", dir, "/out 2> ", dir, "/err");
  ASSERT_EQ(std::system(command.c_str()), 0) << testing::ReadWholeFile(dir + "/err");
  EXPECT_EQ(testing::ReadWholeFile(dir + "/out"), absl::StrCat("watching ", live, "\n"));
}

// neuralmesh view --view_key_file: the browser opens the URL with the key once, the viewer
// keeps the key in a cookie and sends the browser on to the page, whose requests (scripts,
// three.js, the API) all bring the cookie: the page shows the learning session.
TEST(ViewerBrowserTest, AKeyedViewerShowsTheSessionsToTheBrowserGivenTheKey) {
  ExpectTheKeyedPageWatchesTheLiveSession("browser_key", nullptr);
}

// The same over HTTPS (--view_tls_cert_file): the browser, trusting the test certificate's key,
// takes the key's cookie, which is Secure, and brings it with every request of the page.
TEST(ViewerBrowserTest, AKeyedViewerOverHttpsShowsTheSessionsToTheBrowserGivenTheKey) {
  if (std::system("command -v chromium > /dev/null && /usr/bin/python3 -c 'import websocket'") !=
      0) {
    FAIL() << "chromium and Debian's python3-websocket are required (scripts/install-deps.sh)";
  }
  absl::StatusOr<testing::TestCertificates> certificates =
      testing::MakeTestCertificates(testing::MakeTempDir("browser_https_certificates"));
  ASSERT_TRUE(certificates.ok()) << certificates.status();
  ExpectTheKeyedPageWatchesTheLiveSession("browser_https", &*certificates);
}

}  // namespace
}  // namespace neuralmesh::client::web
