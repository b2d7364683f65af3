// End-to-end tests of the remote subcommands of build/bin/neuralmesh against a real
// neuralmesh-server on 127.0.0.1, both run as subprocesses.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numeric>
#include <regex>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
#include "client/inputs.h"
#include "client/point_upload.h"
#include "client/reconstruction_client.h"
#include "core/io/internal/laz.h"
#include "core/io/mapped_point_file.h"
#include "core/io/mesh_io.h"
#include "core/io/point_cloud_io.h"
#include "core/io/spread_order.h"
#include "core/learning/learner_options.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/client/subprocess.h"
#include "tests/client/tcp_proxy.h"
#include "tests/client/test_server.h"
#include "tests/testing/las_file.h"
#include "tests/testing/shapes.h"

namespace neuralmesh::testing {
namespace {

// The vertex counts of the table rows whose first column is `kind`.
std::vector<uint64_t> RowVertices(const std::string& out, absl::string_view kind) {
  std::vector<uint64_t> vertices;
  for (absl::string_view line : absl::StrSplit(out, '\n')) {
    std::vector<absl::string_view> columns = absl::StrSplit(line, ' ', absl::SkipEmpty());
    uint64_t v = 0;
    if (columns.size() > 2 && columns[0] == kind && absl::SimpleAtoi(columns[1], &v)) {
      vertices.push_back(v);
    }
  }
  return vertices;
}

// The number that follows `prefix` in `text`, up to the next space or comma; -1 when `text`
// has no such number.
double NumberAfter(const std::string& text, const std::string& prefix) {
  const size_t at = text.find(prefix);
  if (at == std::string::npos) return -1;
  const size_t begin = at + prefix.size();
  double value = 0;
  return absl::SimpleAtod(text.substr(begin, text.find_first_of(" ,", begin) - begin), &value)
             ? value
             : -1;
}

// The Hausdorff distance `neuralmesh eval` measures between `mesh` and the unit sphere; -1
// when the command fails.
double HausdorffToTheUnitSphere(const std::string& mesh) {
  const RunResult eval = RunNeuralmesh({"eval", mesh, "--reference", "builtin:sphere", "--json"});
  EXPECT_EQ(eval.exit_code, 0) << eval.Describe();
  return NumberAfter(eval.out, "\"hausdorff\": ");
}

// The largest distance of a vertex of `mesh`, in its file's coordinates (origin added), from
// the unit sphere around `centre`.
double FarthestFromTheUnitSphere(const TriangleMesh& mesh, const double centre[3]) {
  double farthest = 0;
  for (const Vec3f& v : mesh.positions) {
    double squared = 0;
    for (int i = 0; i < 3; ++i) squared += std::pow(mesh.origin[i] + v[i] - centre[i], 2);
    farthest = std::max(farthest, std::fabs(std::sqrt(squared) - 1));
  }
  return farthest;
}

class RemoteCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string error;
    server_ = TestServer::Start({}, &error).release();
    *start_error_ = error;
    dir_ = new std::string(MakeTempDir("cli_remote"));
    if (server_ != nullptr) {
      reconstruct_ = new RunResult(
          RunNeuralmesh({"reconstruct", "builtin:sphere", "--server", server_->address(),
                         "--out-dir", *dir_ + "/out", "--vertices", "400", "--points", "4000",
                         "--lod", "100,200", "--batch-size", "500", "--ply"}));
    }
  }
  static void TearDownTestSuite() {
    delete server_;
    delete reconstruct_;
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }

  void SetUp() override {
    ASSERT_NE(server_, nullptr) << *start_error_;
    ASSERT_NE(reconstruct_, nullptr);
  }

  static TestServer* server_;
  static std::string* start_error_;
  static std::string* dir_;
  static RunResult* reconstruct_;
};

TestServer* RemoteCliTest::server_ = nullptr;
std::string* RemoteCliTest::start_error_ = new std::string;
std::string* RemoteCliTest::dir_ = nullptr;
RunResult* RemoteCliTest::reconstruct_ = nullptr;

TEST_F(RemoteCliTest, ReconstructWritesIncreasingLodsAndTheFinalMesh) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const std::vector<uint64_t> lods = RowVertices(reconstruct_->out, "lod");
  ASSERT_FALSE(lods.empty()) << reconstruct_->out;
  for (size_t i = 1; i < lods.size(); ++i) {
    EXPECT_GT(lods[i], lods[i - 1]) << "LOD rows out of order:\n" << reconstruct_->out;
  }
  EXPECT_EQ(RowVertices(reconstruct_->out, "final"), std::vector<uint64_t>{400})
      << reconstruct_->out;
  for (uint64_t v : lods) {
    const std::string base = *dir_ + "/out/sphere_lod" + std::to_string(v);
    EXPECT_TRUE(std::filesystem::exists(base + ".drc")) << base << ".drc missing";
    EXPECT_TRUE(std::filesystem::exists(base + ".ply")) << base << ".ply missing";
  }
  EXPECT_TRUE(std::filesystem::exists(*dir_ + "/out/sphere.drc"));
  EXPECT_TRUE(std::filesystem::exists(*dir_ + "/out/sphere.ply"));
}

// The first `count` points `upload` sends, as a cloud: what a first run that lost its
// connection had sent.
PointCloud FirstPointsOf(client::PointUpload& upload, size_t count) {
  absl::StatusOr<v1::PointBatch> batch = upload.Batch(0, count);
  EXPECT_TRUE(batch.ok()) << batch.status();
  const std::string& bytes = batch->packed().positions();
  EXPECT_EQ(bytes.size(), sizeof(Vec3f) * count);
  PointCloud points;
  points.positions.resize(bytes.size() / sizeof(Vec3f));
  std::memcpy(points.positions.data(), bytes.data(), bytes.size());
  return points;
}

TEST_F(RemoteCliTest, ResumeGoesOnFromThePointsTheSessionHasTaken) {
  // The first run: part of the input in the command's order, then the connection was lost.
  absl::StatusOr<PointCloud> cloud =
      client::LoadPointsForUpload({"builtin:sphere"}, 4000, LearnerOptions().seed);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  client::CloudUpload order(*cloud, client::CloudUpload::Order::kSpread);
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(server_->address());
  ASSERT_TRUE(service.ok()) << service.status();
  auto upload_first = [&](size_t points, const v1::UploadOrder& upload_order) {
    v1::SessionConfig config;
    config.set_target_vertices(400);
    *config.mutable_upload_order() = upload_order;
    absl::StatusOr<v1::Session> created = (*service)->CreateSession(config, "sphere");
    EXPECT_TRUE(created.ok()) << created.status();
    EXPECT_TRUE(
        (*service)->UploadPoints(created->session_id(), FirstPointsOf(order, points), 500).ok());
    return created->session_id();
  };
  absl::StatusOr<v1::UploadOrder> described = order.DescribeOrder();
  ASSERT_TRUE(described.ok()) << described.status();
  const std::string id = upload_first(1500, *described);
  const std::vector<std::string> resume = {"reconstruct",  "builtin:sphere",
                                           "--server",     server_->address(),
                                           "--out-dir",    *dir_ + "/resumed",
                                           "--points",     "4000",
                                           "--batch-size", "500",
                                           "--resume",     id};
  const RunResult resumed = RunNeuralmesh(resume);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.Describe();
  EXPECT_THAT(resumed.out, ::testing::HasSubstr("resuming at point 1500"));
  EXPECT_TRUE(std::filesystem::exists(*dir_ + "/resumed/sphere.drc"));
  absl::StatusOr<v1::Session> session = (*service)->GetSession(id);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->state(), v1::SESSION_STATE_FINISHED);
  EXPECT_EQ(session->points_taken(), 4000u);
  EXPECT_EQ(session->learning().points_received(), 4000u) << "every point once";

  const RunResult finished = RunNeuralmesh(resume);
  EXPECT_NE(finished.exit_code, 0);
  EXPECT_THAT(finished.err, ::testing::HasSubstr("only a session that still takes points"));
  EXPECT_THAT(finished.err, ::testing::HasSubstr("neuralmesh watch " + id));
  // Every point was taken, but the finish never reached the server.
  const std::string whole = upload_first(4000, *described);
  const RunResult finish_only =
      RunNeuralmesh({"reconstruct", "builtin:sphere", "--server", server_->address(), "--out-dir",
                     *dir_ + "/whole", "--points", "4000", "--resume", whole});
  ASSERT_EQ(finish_only.exit_code, 0) << finish_only.Describe();
  EXPECT_THAT(finish_only.out, ::testing::HasSubstr("resuming at point 4000"));
  EXPECT_TRUE(std::filesystem::exists(*dir_ + "/whole/sphere.drc"));
  const RunResult smaller = RunNeuralmesh(
      {"reconstruct", "builtin:sphere", "--server", server_->address(), "--out-dir",
       *dir_ + "/smaller", "--points", "1000", "--resume", upload_first(1500, v1::UploadOrder())});
  EXPECT_NE(smaller.exit_code, 0);
  EXPECT_THAT(smaller.err, ::testing::HasSubstr("more than the 1000 of this input"));
  // A session uploaded in another order (a file read where it lies) is not resumed in this one.
  const std::string other =
      upload_first(1500, client::MakeUploadOrder("file-records-spread-256", 4000));
  const RunResult reordered =
      RunNeuralmesh({"reconstruct", "builtin:sphere", "--server", server_->address(), "--out-dir",
                     *dir_ + "/other", "--points", "4000", "--resume", other});
  EXPECT_EQ(reordered.exit_code, 1) << reordered.Describe();
  EXPECT_THAT(reordered.err,
              ::testing::HasSubstr(absl::StrCat(
                  "session ", other,
                  " was uploaded in the order 'file-records-spread-256' of "
                  "4000 items, this input goes in the order 'points-spread-256' of 4000: resume "
                  "with the input (and its flags, --off_core among them) of the first run")));
  absl::StatusOr<v1::Session> untouched = (*service)->GetSession(other);
  ASSERT_TRUE(untouched.ok()) << untouched.status();
  EXPECT_EQ(untouched->points_taken(), 1500u) << "nothing sent";
  const RunResult local =
      RunNeuralmesh({"reconstruct", "builtin:sphere", "-o", *dir_ + "/local.ply", "--vertices",
                     "100", "--resume", id});
  EXPECT_NE(local.exit_code, 0);
  EXPECT_THAT(local.err, ::testing::HasSubstr("--resume needs --server"));
}

// The final 400-vertex sphere sent back as the start of a finer session: the table's first
// row is the start mesh, the final mesh has the new target and lies on the sphere, and
// --start_mesh with --resume is refused.
TEST_F(RemoteCliTest, AStartMeshIsRefinedOnTheServer) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const std::string out = *dir_ + "/refined";
  const RunResult run =
      RunNeuralmesh({"reconstruct", "builtin:sphere", "--server", server_->address(), "--out-dir",
                     out, "--vertices", "1500", "--points", "6000", "--lod", "1000", "--start_mesh",
                     *dir_ + "/out/sphere.ply"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_EQ(RowVertices(run.out, "refresh").front(), 400u) << run.out;
  EXPECT_EQ(RowVertices(run.out, "lod"), std::vector<uint64_t>{1000}) << run.out;
  EXPECT_EQ(RowVertices(run.out, "final"), std::vector<uint64_t>{1500}) << run.out;
  // About 110,000 Basic Steps from 400 vertices; about 150,000 from the tetrahedron.
  const double basic_steps = NumberAfter(run.out, "valence 6, ");
  EXPECT_GT(basic_steps, 0) << run.out;
  EXPECT_LT(basic_steps, 130000) << run.out;
  EXPECT_LT(HausdorffToTheUnitSphere(out + "/sphere.drc"), 0.02);

  const RunResult resumed =
      RunNeuralmesh({"reconstruct", "builtin:sphere", "--server", server_->address(), "--out-dir",
                     out, "--resume", "s-0", "--start_mesh", *dir_ + "/out/sphere.ply"});
  EXPECT_EQ(resumed.exit_code, 1) << resumed.Describe();
  EXPECT_THAT(resumed.err, ::testing::HasSubstr("--start_mesh applies to a new session"));
}

// By default the command rides out a lost connection: the upload goes on from the points the
// session took, and the watch from its last mesh, without a second command.
TEST_F(RemoteCliTest, ALostConnectionIsRiddenOutAndEveryPointArrivesOnce) {
  const std::string& address = server_->address();
  TcpProxy proxy(std::stoi(address.substr(address.rfind(':') + 1)),
                 /*cut_after_client_bytes=*/300 * 1000);
  const RunResult run =
      RunNeuralmesh({"reconstruct", "builtin:sphere", "--server",
                     absl::StrCat("127.0.0.1:", proxy.port()), "--out-dir", *dir_ + "/ridden",
                     "--points", "60000", "--batch-size", "1000", "--vertices", "400"});
  ASSERT_TRUE(proxy.cut()) << "the upload of 720 KB passed the 300 KB mark";
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_THAT(run.err, ::testing::HasSubstr("lost (UploadPoints")) << run.Describe();
  std::smatch match;
  ASSERT_TRUE(std::regex_search(
      run.err, match,
      std::regex("reconnected: the upload into session (s-[0-9a-f]+) goes on at point [0-9]+ "
                 "of 60000")))
      << run.Describe();
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(address);
  ASSERT_TRUE(service.ok()) << service.status();
  absl::StatusOr<v1::Session> done = (*service)->GetSession(match[1]);
  ASSERT_TRUE(done.ok()) << done.status();
  EXPECT_EQ(done->state(), v1::SESSION_STATE_FINISHED);
  EXPECT_EQ(done->learning().points_received(), 60000u) << "every point once";
  EXPECT_LT(HausdorffToTheUnitSphere(*dir_ + "/ridden/sphere.drc"), 0.05);
}

// With --reconnect_for=0 the first lost connection ends the command; the session keeps its
// points, and --resume goes on with them.
TEST_F(RemoteCliTest, ALostConnectionKeepsTheSessionAndResumeFinishesIt) {
  const std::string& address = server_->address();
  TcpProxy proxy(std::stoi(address.substr(address.rfind(':') + 1)),
                 /*cut_after_client_bytes=*/300 * 1000);
  std::vector<std::string> args = {"reconstruct",     "builtin:sphere",
                                   "--server",        absl::StrCat("127.0.0.1:", proxy.port()),
                                   "--out-dir",       *dir_ + "/lost",
                                   "--points",        "60000",
                                   "--batch-size",    "1000",
                                   "--vertices",      "400",
                                   "--reconnect_for", "0"};
  const RunResult lost = RunNeuralmesh(args);
  ASSERT_TRUE(proxy.cut()) << "the upload of 720 KB passed the 300 KB mark";
  EXPECT_NE(lost.exit_code, 0) << lost.Describe();
  std::smatch match;
  ASSERT_TRUE(std::regex_search(lost.err, match,
                                std::regex("run this command again with --resume (s-[0-9a-f]+)")))
      << lost.Describe();
  const std::string id = match[1];
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(address);
  ASSERT_TRUE(service.ok()) << service.status();
  absl::StatusOr<v1::Session> kept = (*service)->GetSession(id);
  ASSERT_TRUE(kept.ok()) << kept.status() << ": the session was not cancelled";
  EXPECT_TRUE(kept->state() == v1::SESSION_STATE_COLLECTING ||
              kept->state() == v1::SESSION_STATE_LEARNING)
      << v1::SessionState_Name(kept->state());
  // Whole batches, as many as reached the server before the cut (none, when the proxy's
  // buffers still held them all).
  EXPECT_LT(kept->points_taken(), 60000u);
  EXPECT_EQ(kept->points_taken() % 1000, 0u);

  args.insert(args.end(), {"--resume", id});
  const RunResult resumed = RunNeuralmesh(args);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.Describe();
  EXPECT_THAT(resumed.out,
              ::testing::HasSubstr(absl::StrCat("resuming at point ", kept->points_taken())));
  absl::StatusOr<v1::Session> done = (*service)->GetSession(id);
  ASSERT_TRUE(done.ok()) << done.status();
  EXPECT_EQ(done->state(), v1::SESSION_STATE_FINISHED);
  EXPECT_EQ(done->learning().points_received(), 60000u) << "every point once";
  EXPECT_TRUE(std::filesystem::exists(*dir_ + "/lost/sphere.drc"));
}

TEST_F(RemoteCliTest, TheServerPrintsTheSessionsEvents) {
  const std::string out = server_->Stdout();
  EXPECT_TRUE(std::regex_search(
      out, std::regex("Z session s-[0-9a-f]{16} created by ipv4:127\\.0\\.0\\.1:[0-9]+: "
                      "\"sphere\", target 400 vertices\n")))
      << out;
  EXPECT_TRUE(std::regex_search(out, std::regex("Z session s-[0-9a-f]{16} finished: 400 "
                                                "vertices, [0-9]+ faces, genus 0, 0 boundaries")))
      << out;
}

TEST_F(RemoteCliTest, TheFinalMeshIsAClosedSphere) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const RunResult stats = RunNeuralmesh({"stats", *dir_ + "/out/sphere.drc", "--json"});
  ASSERT_EQ(stats.exit_code, 0) << stats.Describe();
  EXPECT_TRUE(absl::StrContains(stats.out, "\"closed\": true")) << stats.out;
  EXPECT_TRUE(absl::StrContains(stats.out, "\"genus\": 0")) << stats.out;
}

// --remove_outliers works on what is uploaded: a stray point 100 radii away never reaches the
// server, and the final mesh stays on the sphere.
TEST_F(RemoteCliTest, RemoveOutliersFiltersTheUpload) {
  const std::string cloud = *dir_ + "/sphere_and_stray.ply";
  ASSERT_TRUE(WritePointCloud(UnitSpherePointsAndAStray(4000, 9, Vec3f(100, 0, 0)), cloud).ok());
  const RunResult run =
      RunNeuralmesh({"reconstruct", cloud, "--server", server_->address(), "--out-dir",
                     *dir_ + "/filtered", "--vertices", "400", "--remove_outliers"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "outliers removed: 1 of 4001 points")) << run.out;
  const double hausdorff = HausdorffToTheUnitSphere(*dir_ + "/filtered/sphere_and_stray.drc");
  EXPECT_GE(hausdorff, 0);
  EXPECT_LT(hausdorff, 0.05) << "a spike toward the stray point is left";
}

// --las_classes uploads the points of the classes asked for only: the building (class 6, a unit
// sphere), not the ground under it (class 2, 3 m below).
TEST_F(RemoteCliTest, LasClassesChooseThePointsUploaded) {
  testing::LasLayout layout;
  layout.format = 1;
  for (double& s : layout.scale) s = 0.0001;
  std::vector<testing::LasPoint> points;
  for (const Vec3f& p : ColoredUnitSpherePoints(4000, 12).positions) {
    testing::LasPoint building{static_cast<int32_t>(std::lround(p[0] / 0.0001)),
                               static_cast<int32_t>(std::lround(p[1] / 0.0001)),
                               static_cast<int32_t>(std::lround(p[2] / 0.0001))};
    building.classification = 6;
    points.push_back(building);
    testing::LasPoint ground{building.x * 3, building.y * 3, -30000};
    ground.classification = 2;
    points.push_back(ground);
  }
  const std::string las = *dir_ + "/site.las";
  std::ofstream(las, std::ios::binary) << testing::LasFile(layout, points);
  const RunResult run =
      RunNeuralmesh({"reconstruct", las, "--server", server_->address(), "--out-dir",
                     *dir_ + "/building", "--vertices", "400", "--las_classes", "6"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "left out 4000 points of other classes")) << run.out;
  const double hausdorff = HausdorffToTheUnitSphere(*dir_ + "/building/site.drc");
  EXPECT_GE(hausdorff, 0);
  EXPECT_LT(hausdorff, 0.05) << "the ground was learned too";
}

// --outliers_on_server leaves the stray to the session, which holds it back as the batches
// arrive and drops it at the finish; the command reports what the server removed.
TEST_F(RemoteCliTest, RemoveOutliersOnTheServer) {
  const std::string cloud = *dir_ + "/sphere_and_far_stray.ply";
  ASSERT_TRUE(WritePointCloud(UnitSpherePointsAndAStray(4000, 10, Vec3f(0, 0, 100)), cloud).ok());
  const RunResult run = RunNeuralmesh(
      {"reconstruct", cloud, "--server", server_->address(), "--out-dir", *dir_ + "/on_server",
       "--vertices", "400", "--remove_outliers", "--outliers_on_server", "--batch-size", "500"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_FALSE(absl::StrContains(run.out, "outliers removed: ")) << "nothing filtered here";
  const double removed = NumberAfter(run.out, "outliers removed by the server: ");
  EXPECT_GE(removed, 1) << run.out;
  EXPECT_LE(removed, 1 + 12) << "at most 0.3% of the sphere: " << run.out;
  EXPECT_TRUE(absl::StrContains(run.out, " of 4001 points (")) << run.out;
  const double hausdorff = HausdorffToTheUnitSphere(*dir_ + "/on_server/sphere_and_far_stray.drc");
  EXPECT_GE(hausdorff, 0);
  EXPECT_LT(hausdorff, 0.05) << "a spike toward the stray point is left";
}

// A coloured point cloud's colours go up with its points, and the meshes that come back (Draco
// and PLY) carry the colours of their vertices' positions; --nocolors uploads none.
TEST_F(RemoteCliTest, ColouredPointsComeBackAsColouredMeshes) {
  const std::string cloud = *dir_ + "/colored_sphere.ply";
  ASSERT_TRUE(WritePointCloud(ColoredUnitSpherePoints(8000, 12), cloud).ok());
  for (const bool colors : {true, false}) {
    SCOPED_TRACE(colors ? "colours" : "--nocolors");
    const std::string out_dir = *dir_ + (colors ? "/colored" : "/uncolored");
    std::vector<std::string> args = {
        "reconstruct", cloud,   "--server",           server_->address(),
        "--out-dir",   out_dir, "--vertices",         "600",
        "--ply",       "--glb", "--color_neighbours", "4"};
    if (!colors) args.push_back("--nocolors");
    const RunResult run = RunNeuralmesh(args);
    ASSERT_EQ(run.exit_code, 0) << run.Describe();
    for (const char* name : {"/colored_sphere.drc", "/colored_sphere.ply", "/colored_sphere.glb"}) {
      const absl::StatusOr<TriangleMesh> mesh = ReadMesh(out_dir + name);
      ASSERT_TRUE(mesh.ok()) << mesh.status();
      if (!colors) {
        EXPECT_TRUE(mesh->colors.empty()) << name;
        continue;
      }
      const int worst = WorstColorErrorOnTheUnitSphere(*mesh);
      EXPECT_GE(worst, 0) << name << " has no colours";
      EXPECT_LE(worst, 8) << name;
    }
  }
  // The same points as LAS, LAZ, PLY and PCD, uploaded from where they lie: their colours go
  // too.
  testing::LasLayout layout;
  layout.format = 3;
  for (double& s : layout.scale) s = 0.0001;
  std::vector<testing::LasPoint> records;
  const PointCloud colored = ColoredUnitSpherePoints(8000, 12);
  for (size_t i = 0; i < colored.size(); ++i) {
    testing::LasPoint p{static_cast<int32_t>(std::lround(colored.positions[i][0] / 0.0001)),
                        static_cast<int32_t>(std::lround(colored.positions[i][1] / 0.0001)),
                        static_cast<int32_t>(std::lround(colored.positions[i][2] / 0.0001))};
    p.red = colored.colors[i][0] * 257;
    p.green = colored.colors[i][1] * 257;
    p.blue = colored.colors[i][2] * 257;
    records.push_back(p);
  }
  const std::string las = *dir_ + "/colored_scan.las";
  std::ofstream(las, std::ios::binary) << testing::LasFile(layout, records);
  const std::string laz = *dir_ + "/colored_scan_laz.laz";
  const std::string ply = *dir_ + "/colored_scan_ply.ply";
  const std::string pcd = *dir_ + "/colored_scan_pcd.pcd";
  for (const std::string& converted : {laz, ply, pcd}) {
    ASSERT_EQ(RunNeuralmesh({"convert", las, "-o", converted}).exit_code, 0);
  }
  for (const std::string& input : {las, laz, ply, pcd}) {
    SCOPED_TRACE(input);
    const std::string out_dir = *dir_ + "/colored_off_core";
    const RunResult run =
        RunNeuralmesh({"reconstruct", input, "--server", server_->address(), "--out-dir", out_dir,
                       "--vertices", "600", "--off_core", "--color_neighbours", "4"});
    ASSERT_EQ(run.exit_code, 0) << run.Describe();
    EXPECT_THAT(run.out, ::testing::HasSubstr("of them points; with colours)"));
    const absl::StatusOr<TriangleMesh> mesh =
        ReadMesh(out_dir + "/" + client::InputStem(input) + ".drc");
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    const int worst = WorstColorErrorOnTheUnitSphere(*mesh);
    EXPECT_GE(worst, 0) << "no colours";
    EXPECT_LE(worst, 8);
  }
  // --color_neighbours went to the coloured session's configuration.
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(server_->address());
  ASSERT_TRUE(service.ok()) << service.status();
  absl::StatusOr<std::vector<client::v1::Session>> sessions = (*service)->ListSessions();
  ASSERT_TRUE(sessions.ok()) << sessions.status();
  std::vector<uint32_t> neighbours;
  for (const client::v1::Session& session : *sessions) {
    if (session.name() == "colored_sphere") {
      neighbours.push_back(session.config().color_neighbours().value());
    }
  }
  EXPECT_THAT(neighbours, ::testing::UnorderedElementsAre(4u, 8u));
}

// A georeferenced scan (a unit sphere at UTM (500123.5, 4100456.25, 80), in XYZ text) is
// uploaded relative to the origin its reader chose; the session carries that origin, and the
// meshes come back in the scan's coordinates: the Draco files' metadata and the PLY files'
// doubles both place the mesh on the sphere.
TEST_F(RemoteCliTest, GeoreferencedScansComeBackInTheirCoordinates) {
  const PointCloud unit = ColoredUnitSpherePoints(6000, 8);
  const double centre[3] = {500123.5, 4100456.25, 80};
  // The scan in two files, as two stations would leave it; uploaded as one.
  std::string xyz[2];
  for (size_t i = 0; i < unit.size(); ++i) {
    const Vec3f& p = unit.positions[i];
    xyz[i % 2] +=
        absl::StrFormat("%.4f %.4f %.4f\n", centre[0] + p[0], centre[1] + p[1], centre[2] + p[2]);
  }
  const std::string scan = *dir_ + "/utm_scan.xyz";
  const std::string second = *dir_ + "/utm_scan_2.xyz";
  std::ofstream(scan) << xyz[0];
  std::ofstream(second) << xyz[1];
  const std::string out_dir = *dir_ + "/utm";
  const RunResult run = RunNeuralmesh({"reconstruct", scan, second, "--server", server_->address(),
                                       "--out-dir", out_dir, "--vertices", "500", "--ply"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "coordinates taken relative to (500000, 4100000, 0)"))
      << run.out;
  for (const char* name : {"/utm_scan.drc", "/utm_scan.ply"}) {
    SCOPED_TRACE(name);
    const absl::StatusOr<TriangleMesh> mesh = ReadMesh(out_dir + name);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    EXPECT_EQ(mesh->origin, (std::array<double, 3>{500000, 4100000, 0}));
    EXPECT_LT(FarthestFromTheUnitSphere(*mesh, centre), 0.05) << "a vertex off the sphere";
  }
  // Resuming a session of points in another frame would mix the two: refused.
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(server_->address());
  ASSERT_TRUE(service.ok()) << service.status();
  v1::SessionConfig config;
  config.set_target_vertices(400);
  absl::StatusOr<v1::Session> local = (*service)->CreateSession(config, "local");
  ASSERT_TRUE(local.ok()) << local.status();
  const RunResult resume = RunNeuralmesh({"reconstruct", scan, "--server", server_->address(),
                                          "--out-dir", out_dir, "--resume", local->session_id()});
  EXPECT_EQ(resume.exit_code, 1) << resume.Describe();
  EXPECT_THAT(resume.err, ::testing::HasSubstr(
                              "holds points relative to (0, 0, 0), this input is read relative "
                              "to (500000, 4100000, 0): resume with the input of the first run"));

  const RunResult sessions = RunNeuralmesh({"sessions", "--server", server_->address(), "--json"});
  ASSERT_EQ(sessions.exit_code, 0) << sessions.Describe();
  EXPECT_TRUE(std::regex_search(sessions.out,
                                std::regex("\"origin\": \\[\\s*5e\\+05,\\s*4100000,\\s*0\\s*\\]")))
      << sessions.out;
  EXPECT_TRUE(absl::StrContains(sessions.out, "\"points_taken\": 6000")) << sessions.out;
}

// --off_core with --server: a georeferenced LAS scan, its building (class 6, a unit sphere)
// stored bottom to top among ground points (class 2), uploaded from where it lies, and again
// as LAZ. The session takes the building's every point once and learns it in the scan's
// coordinates; --resume goes on from the points the session has taken.
TEST_F(RemoteCliTest, OffCoreUploadsAScanFromWhereItLies) {
  const double centre[3] = {500123.5, 4100456.25, 80};
  testing::LasLayout layout;
  layout.format = 1;
  for (double& s : layout.scale) s = 0.0001;
  layout.offset[0] = 500000;
  layout.offset[1] = 4100000;
  std::vector<Vec3f> sphere = ColoredUnitSpherePoints(4000, 21).positions;
  std::sort(sphere.begin(), sphere.end(),
            [](const Vec3f& a, const Vec3f& b) { return a[2] < b[2]; });
  std::vector<testing::LasPoint> points;
  for (const Vec3f& p : sphere) {
    testing::LasPoint building{};
    int32_t* fields[3] = {&building.x, &building.y, &building.z};
    for (int i = 0; i < 3; ++i) {
      *fields[i] =
          static_cast<int32_t>(std::lround((centre[i] + p[i] - layout.offset[i]) / 0.0001));
    }
    building.classification = 6;
    points.push_back(building);
    testing::LasPoint ground{building.x + 40000, building.y, 700000};
    ground.classification = 2;
    points.push_back(ground);
  }
  const std::string las = *dir_ + "/strips.las";
  std::ofstream(las, std::ios::binary) << testing::LasFile(layout, points);

  const std::string out_dir = *dir_ + "/off_core";
  const std::vector<std::string> upload = {"reconstruct",
                                           las,
                                           "--server",
                                           server_->address(),
                                           "--out-dir",
                                           out_dir,
                                           "--vertices",
                                           "400",
                                           "--las_classes",
                                           "6",
                                           "--off_core",
                                           "--batch-size",
                                           "500"};
  const RunResult run = RunNeuralmesh(upload);
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_THAT(run.out, ::testing::HasSubstr(absl::StrCat(
                           "INPUT '", las, "': 8000 records read where they lie (off-core; ")));
  EXPECT_THAT(run.out, ::testing::HasSubstr("coordinates taken relative to (500000, 4100000, 0)"));
  std::smatch id;
  ASSERT_TRUE(std::regex_search(run.out, id, std::regex("session (s-[0-9a-f]+) on .*: about ")))
      << run.out;
  const absl::StatusOr<TriangleMesh> mesh = ReadMesh(out_dir + "/strips.drc");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->origin, (std::array<double, 3>{500000, 4100000, 0}));
  EXPECT_EQ(mesh->positions.size(), 400u);
  EXPECT_LT(FarthestFromTheUnitSphere(*mesh, centre), 0.05) << "a vertex off the building";
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(server_->address());
  ASSERT_TRUE(service.ok()) << service.status();
  absl::StatusOr<v1::Session> session = (*service)->GetSession(id[1]);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->points_taken(), 4000u);
  EXPECT_EQ(session->learning().points_received(), 4000u) << "every point once";

  // The first 1,500 points of the same order in a session, then the command resumes it.
  absl::StatusOr<MappedPointFile> file = MappedPointFile::Open(las, LasClasses().set(6));
  ASSERT_TRUE(file.ok()) << file.status();
  client::FileRecordsUpload order(*file);
  v1::SessionConfig config;
  config.set_target_vertices(400);
  config.mutable_origin()->set_x(500000);
  config.mutable_origin()->set_y(4100000);
  absl::StatusOr<v1::UploadOrder> described = order.DescribeOrder();
  ASSERT_TRUE(described.ok()) << described.status();
  *config.mutable_upload_order() = *described;
  absl::StatusOr<v1::Session> created = (*service)->CreateSession(config, "strips");
  ASSERT_TRUE(created.ok()) << created.status();
  ASSERT_TRUE(
      (*service)->UploadPoints(created->session_id(), FirstPointsOf(order, 1500), 500).ok());
  // Without --off_core the file would be read whole and sent in another order: refused.
  std::vector<std::string> read_whole = upload;
  read_whole.erase(std::find(read_whole.begin(), read_whole.end(), "--off_core"));
  read_whole.insert(read_whole.end(), {"--resume", created->session_id()});
  const RunResult reordered = RunNeuralmesh(read_whole);
  EXPECT_EQ(reordered.exit_code, 1) << reordered.Describe();
  EXPECT_THAT(
      reordered.err,
      ::testing::HasSubstr("was uploaded in the order 'file-records-spread-256' of 8000 "
                           "items, this input goes in the order 'points-spread-256' of 4000"));
  // Other classes of the same file go in the same order over as many records, but are other
  // points: refused, by the fingerprint of the first points.
  std::vector<std::string> ground = upload;
  *std::find(ground.begin(), ground.end(), "6") = "2";
  ground.insert(ground.end(), {"--resume", created->session_id()});
  const RunResult other_classes = RunNeuralmesh(ground);
  EXPECT_EQ(other_classes.exit_code, 1) << other_classes.Describe();
  EXPECT_THAT(other_classes.err, ::testing::HasSubstr(absl::StrCat(
                                     "session ", created->session_id(),
                                     " was uploaded from other points: the first 1024 "
                                     "it took differ from this input's (fingerprints ")));
  EXPECT_THAT(other_classes.err, ::testing::HasSubstr("--las_classes among them"));
  std::vector<std::string> resume = upload;
  resume[5] = *dir_ + "/off_core_resumed";
  resume.insert(resume.end(), {"--resume", created->session_id()});
  const RunResult resumed = RunNeuralmesh(resume);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.Describe();
  EXPECT_THAT(resumed.out, ::testing::HasSubstr("resuming at point 1500"));
  session = (*service)->GetSession(created->session_id());
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->state(), v1::SESSION_STATE_FINISHED);
  EXPECT_EQ(session->points_taken(), 4000u);
  EXPECT_EQ(session->learning().points_received(), 4000u) << "every point once";

  // The same scan as LAZ, decoded a chunk at a time.
  const std::string laz = *dir_ + "/strips.laz";
  ASSERT_EQ(RunNeuralmesh({"convert", las, "-o", laz}).exit_code, 0);
  std::vector<std::string> from_laz = upload;
  from_laz[1] = laz;
  from_laz[5] = *dir_ + "/off_core_laz";
  const RunResult laz_run = RunNeuralmesh(from_laz);
  ASSERT_EQ(laz_run.exit_code, 0) << laz_run.Describe();
  EXPECT_THAT(laz_run.out, ::testing::HasSubstr(absl::StrCat(
                               "INPUT '", laz,
                               "': 8000 records decoded where they lie, a LAZ chunk at a time (1 "
                               "chunk) (off-core; 50.0% of them points)")));
  ASSERT_TRUE(std::regex_search(laz_run.out, id, std::regex("session (s-[0-9a-f]+) on ")))
      << laz_run.out;
  session = (*service)->GetSession(id[1]);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->points_taken(), 4000u);
  const absl::StatusOr<TriangleMesh> from_laz_mesh = ReadMesh(from_laz[5] + "/strips.drc");
  ASSERT_TRUE(from_laz_mesh.ok()) << from_laz_mesh.status();
  EXPECT_EQ(from_laz_mesh->origin, mesh->origin);
  EXPECT_LT(FarthestFromTheUnitSphere(*from_laz_mesh, centre), 0.05) << "a vertex off the building";

  // A LAZ file of 500-record chunks whose last chunk in the upload's order (past the probe's
  // wave) is corrupt: the upload stops there with the decoder's message, and the session is
  // cancelled.
  absl::StatusOr<std::string> chunked =
      io_internal::CompressLas(ReadWholeFile(las), io_internal::LazWriteOptions{500});
  ASSERT_TRUE(chunked.ok()) << chunked.status();
  absl::StatusOr<io_internal::LazChunks> chunks = io_internal::LazChunks::Open(*chunked);
  ASSERT_TRUE(chunks.ok()) << chunks.status();
  ASSERT_EQ(chunks->size(), 16u);
  const io_internal::LazChunks::ChunkSpan& last = chunks->chunk(SpreadOrder(16, 1)[15]);
  std::string corrupt_bytes = *chunked;
  for (size_t i = last.at + 30; i < last.at + last.size; ++i) {
    corrupt_bytes[i] = static_cast<char>(i * 7);
  }
  const std::string corrupt = *dir_ + "/corrupt.laz";
  std::ofstream(corrupt, std::ios::binary) << corrupt_bytes;
  std::vector<std::string> from_corrupt = upload;
  from_corrupt[1] = corrupt;
  from_corrupt[5] = *dir_ + "/off_core_corrupt";
  const RunResult broken = RunNeuralmesh(from_corrupt);
  EXPECT_EQ(broken.exit_code, 1) << broken.Describe();
  EXPECT_THAT(broken.err, ::testing::HasSubstr("'" + corrupt + "': LAZ: chunk "))
      << broken.Describe();
  ASSERT_TRUE(std::regex_search(broken.out, id, std::regex("session (s-[0-9a-f]+) on ")))
      << broken.out;
  session = (*service)->GetSession(id[1]);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->state(), v1::SESSION_STATE_CANCELLED);

  std::vector<std::string> filtered = upload;
  filtered.push_back("--remove_outliers");
  const RunResult refused = RunNeuralmesh(filtered);
  EXPECT_NE(refused.exit_code, 0) << refused.Describe();
  EXPECT_THAT(refused.err, ::testing::HasSubstr("reads the file whole: not with --off_core"));
}

// Whether `process` ended within 30 s.
bool Ended(BackgroundProcess& process) {
  for (int i = 0; i < 600 && process.Running(); ++i) absl::SleepFor(absl::Milliseconds(50));
  return !process.Running();
}

// INPUT '-': points streamed from standard input as a scanner's pipeline sends them. The
// lower half of a georeferenced sphere arrives first, and a mesh of it is published before the
// upper half comes; at the end of the stream the session is finished, and its final mesh is
// the whole sphere in the scan's coordinates, from every point once.
TEST_F(RemoteCliTest, PointsStreamedFromStandardInputAreLearnedAsTheyArrive) {
  const double centre[3] = {500123.5, 4100456.25, 80};
  const PointCloud colored = ColoredUnitSpherePoints(4000, 31);
  std::vector<size_t> bottom_up(colored.size());
  std::iota(bottom_up.begin(), bottom_up.end(), 0);
  std::sort(bottom_up.begin(), bottom_up.end(), [&colored](size_t a, size_t b) {
    return colored.positions[a][2] < colored.positions[b][2];
  });
  std::vector<Vec3f> sphere;
  for (size_t i : bottom_up) sphere.push_back(colored.positions[i]);
  std::string lower, upper;
  for (size_t k = 0; k < sphere.size(); ++k) {
    const Rgb& color = colored.colors[bottom_up[k]];
    (k < 2000 ? lower : upper) += absl::StrFormat(
        "%.4f,%.4f,%.4f,%d,%d,%d\n", centre[0] + sphere[k][0], centre[1] + sphere[k][1],
        centre[2] + sphere[k][2], color[0], color[1], color[2]);
  }
  // The largest difference of a channel between a vertex's colour and that of the sphere's
  // point nearest it; -1 without colours.
  const auto worst_color_error = [&centre](const TriangleMesh& mesh) {
    if (mesh.colors.size() != mesh.positions.size()) return -1;
    int worst = 0;
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      Vec3f on_sphere;
      for (int c = 0; c < 3; ++c) {
        on_sphere[c] = static_cast<float>(mesh.origin[c] + mesh.positions[v][c] - centre[c]);
      }
      worst = std::max(worst, ColorError(mesh.colors[v], on_sphere.normalized()));
    }
    return worst;
  };
  const std::string out_dir = *dir_ + "/streamed";
  BackgroundProcess run("neuralmesh",
                        {"reconstruct", "-", "--server", server_->address(), "--out-dir", out_dir,
                         "--vertices", "400", "--lod", "100", "--batch-size", "500"},
                        /*stdin_pipe=*/true);
  ASSERT_TRUE(run.WriteStdin("# a scan\n# x,y,z,r,g,b\n" + lower));
  ASSERT_TRUE(run.AwaitStdout("lod ")) << "no mesh before the stream went on\n"
                                       << run.Stdout() << run.Stderr();
  // The half that arrived is an open cap: the mesh published so far lies on the lower half.
  ASSERT_TRUE(run.WriteStdin(upper.substr(0, 10)));  // A line split across two writes.
  absl::SleepFor(absl::Milliseconds(150));
  ASSERT_TRUE(run.WriteStdin(upper.substr(10)));
  run.CloseStdin();
  ASSERT_TRUE(Ended(run));
  ASSERT_EQ(run.exit_code(), 0) << run.Stdout() << run.Stderr();
  const std::string out = run.Stdout();
  EXPECT_THAT(out, ::testing::HasSubstr("INPUT '-': points streamed from standard input"));
  EXPECT_THAT(out, ::testing::HasSubstr("coordinates taken relative to (500000, 4100000, 0)"));
  const absl::StatusOr<TriangleMesh> lod = ReadMesh(out_dir + "/stdin_lod100.drc");
  ASSERT_TRUE(lod.ok()) << lod.status();
  double highest = -INFINITY;
  for (const Vec3f& v : lod->positions) highest = std::max(highest, lod->origin[2] + v[2]);
  EXPECT_LT(highest, centre[2] + 0.5) << "the first mesh reaches the half not yet sent";
  const absl::StatusOr<TriangleMesh> mesh = ReadMesh(out_dir + "/stdin.drc");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->origin, (std::array<double, 3>{500000, 4100000, 0}));
  EXPECT_EQ(mesh->positions.size(), 400u);
  EXPECT_LT(FarthestFromTheUnitSphere(*mesh, centre), 0.05) << "a vertex off the sphere";
  const int text_color_error = worst_color_error(*mesh);
  EXPECT_GE(text_color_error, 0) << "the colours the header names were not sent";
  EXPECT_LE(text_color_error, 8) << "a vertex's colour is not its place's";
  std::smatch id;
  ASSERT_TRUE(std::regex_search(out, id, std::regex("session (s-[0-9a-f]+) on "))) << out;
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(server_->address());
  ASSERT_TRUE(service.ok()) << service.status();
  absl::StatusOr<v1::Session> session = (*service)->GetSession(id[1]);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->state(), v1::SESSION_STATE_FINISHED);
  EXPECT_EQ(session->points_taken(), 4000u);

  // The same sphere as a LAS file piped in (a converter's `-stdout`): its records as they come,
  // of the classes asked for, with their colours (16-bit levels).
  testing::LasLayout layout;
  layout.format = 3;
  for (double& s : layout.scale) s = 0.0001;
  layout.offset[0] = 500000;
  layout.offset[1] = 4100000;
  std::vector<testing::LasPoint> records;
  for (size_t i : bottom_up) {
    const Vec3f& p = colored.positions[i];
    testing::LasPoint record{
        static_cast<int32_t>(std::lround((centre[0] + p[0] - 500000) / 0.0001)),
        static_cast<int32_t>(std::lround((centre[1] + p[1] - 4100000) / 0.0001)),
        static_cast<int32_t>(std::lround((centre[2] + p[2]) / 0.0001))};
    record.red = colored.colors[i][0] * 257;
    record.green = colored.colors[i][1] * 257;
    record.blue = colored.colors[i][2] * 257;
    record.classification = 2;
    records.push_back(record);
  }
  records[7].classification = 7;  // Noise, not asked for.
  records[8].classification = 6;  // A building, not asked for.
  records[9].classification = 1;
  const std::string las = testing::LasFile(layout, records);
  // And compressed (`laszip -stdout`): its chunks decoded as each comes whole.
  const absl::StatusOr<std::string> laz = io_internal::CompressLas(las, {1000});
  ASSERT_TRUE(laz.ok()) << laz.status();
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::string>{"streamed_las", las}, {"streamed_laz", *laz}}) {
    SCOPED_TRACE(name);
    BackgroundProcess piped(
        "neuralmesh",
        {"reconstruct", "-", "--server", server_->address(), "--out-dir", *dir_ + "/" + name,
         "--vertices", "400", "--batch-size", "500", "--las_classes", "1-2"},
        /*stdin_pipe=*/true);
    // The header split across writes; for LAZ, the first chunk too.
    const size_t first_write = name == "streamed_las" ? 100 : 5000;
    ASSERT_TRUE(piped.WriteStdin(bytes.substr(0, first_write)));
    absl::SleepFor(absl::Milliseconds(150));
    ASSERT_TRUE(piped.WriteStdin(bytes.substr(first_write)));
    piped.CloseStdin();
    ASSERT_TRUE(Ended(piped));
    ASSERT_EQ(piped.exit_code(), 0) << piped.Stdout() << piped.Stderr();
    const absl::StatusOr<TriangleMesh> streamed = ReadMesh(*dir_ + "/" + name + "/stdin.drc");
    ASSERT_TRUE(streamed.ok()) << streamed.status();
    EXPECT_EQ(streamed->positions.size(), 400u);
    EXPECT_LT(FarthestFromTheUnitSphere(*streamed, centre), 0.05) << "a vertex off the sphere";
    const int las_color_error = worst_color_error(*streamed);
    EXPECT_GE(las_color_error, 0) << "the colours were not sent";
    EXPECT_LE(las_color_error, 8) << "a vertex's colour is not its place's";
    const std::string piped_out = piped.Stdout();
    EXPECT_THAT(piped_out, ::testing::HasSubstr("from standard input with their colours"));
    ASSERT_TRUE(std::regex_search(piped_out, id, std::regex("session (s-[0-9a-f]+) on ")));
    session = (*service)->GetSession(id[1]);
    ASSERT_TRUE(session.ok()) << session.status();
    EXPECT_EQ(session->points_taken(), 3998u) << "every record of classes 1 and 2";
  }

  // Classes choose among LAS records: a stream of text has none.
  BackgroundProcess classes_of_text("neuralmesh",
                                    {"reconstruct", "-", "--server", server_->address(),
                                     "--out-dir", *dir_ + "/streamed_text", "--las_classes", "2"},
                                    /*stdin_pipe=*/true);
  ASSERT_TRUE(classes_of_text.WriteStdin("1 2 3\n"));  // One write: it cannot fail before.
  classes_of_text.CloseStdin();
  ASSERT_TRUE(Ended(classes_of_text));
  EXPECT_EQ(classes_of_text.exit_code(), 1);
  EXPECT_THAT(classes_of_text.Stderr(),
              ::testing::HasSubstr("standard input: text, whose points have no LAS classes to "
                                   "choose from"));

  // A line that is not a point ends the upload, naming it; the session is cancelled.
  BackgroundProcess bad("neuralmesh",
                        {"reconstruct", "-", "--server", server_->address(), "--out-dir",
                         *dir_ + "/streamed_bad", "--batch-size", "2"},
                        /*stdin_pipe=*/true);
  ASSERT_TRUE(bad.WriteStdin("1 2 3\n4 5 6\n7 8 9\n10 11 12\n13 14 15\n1.5 2.5 oops\n"));
  bad.CloseStdin();
  for (int i = 0; i < 200 && bad.Running(); ++i) absl::SleepFor(absl::Milliseconds(50));
  ASSERT_FALSE(bad.Running());
  EXPECT_EQ(bad.exit_code(), 1);
  EXPECT_THAT(bad.Stderr(),
              ::testing::HasSubstr("standard input, line 6: '1.5 2.5 oops' does not start with "
                                   "a point's x, y and z"));
  BackgroundProcess empty(
      "neuralmesh",
      {"reconstruct", "-", "--server", server_->address(), "--out-dir", *dir_ + "/streamed_empty"},
      /*stdin_pipe=*/true);
  ASSERT_TRUE(empty.WriteStdin("# nothing\n\n"));
  empty.CloseStdin();
  for (int i = 0; i < 200 && empty.Running(); ++i) absl::SleepFor(absl::Milliseconds(50));
  EXPECT_EQ(empty.exit_code(), 1);
  EXPECT_THAT(empty.Stderr(),
              ::testing::HasSubstr("standard input ended before its first point (2 lines read)"));
  const std::vector<std::pair<std::vector<std::string>, std::string>> refused = {
      {{"reconstruct", "-", "-o", *dir_ + "/local.ply", "--vertices", "100"}, "it needs --server"},
      {{"reconstruct", "-", "--server", server_->address(), "--out-dir", out_dir, "--resume",
        "s-0"},
       "standard input ('-') cannot be read again"},
      {{"reconstruct", "-", "a.xyz", "--server", server_->address(), "--out-dir", out_dir},
       "streamed alone"},
  };
  for (const auto& [args, why] : refused) {
    const RunResult result = RunNeuralmesh(args);
    EXPECT_NE(result.exit_code, 0) << result.Describe();
    EXPECT_THAT(result.err, ::testing::HasSubstr(why)) << result.Describe();
  }
}

TEST_F(RemoteCliTest, SessionsListsTheFinishedSession) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const RunResult sessions = RunNeuralmesh({"sessions", "--server", server_->address()});
  ASSERT_EQ(sessions.exit_code, 0) << sessions.Describe();
  EXPECT_TRUE(absl::StrContains(sessions.out, "sphere")) << sessions.out;
  EXPECT_TRUE(absl::StrContains(sessions.out, "finished")) << sessions.out;

  const RunResult json = RunNeuralmesh({"sessions", "--server", server_->address(), "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.Describe();
  EXPECT_TRUE(absl::StrContains(json.out, "\"state\": \"finished\"")) << json.out;
  EXPECT_TRUE(absl::StrContains(json.out, "\"points_taken\": 4000")) << json.out;
}

// A session whose learner stalls on its first points waits for more, and `sessions` says so.
TEST_F(RemoteCliTest, SessionsSaysWhichSessionsWaitForPointsToGrow) {
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(server_->address());
  ASSERT_TRUE(service.ok()) << service.status();
  v1::SessionConfig config;
  config.set_target_vertices(100);
  config.mutable_learner()->mutable_c_ec()->set_value(0.01);  // Collapses win over splits.
  config.mutable_learner()->mutable_c_vs()->set_value(10);
  absl::StatusOr<v1::Session> created = (*service)->CreateSession(config, "stalling");
  ASSERT_TRUE(created.ok()) << created.status();
  absl::StatusOr<PointCloud> torus = client::LoadPointsForUpload({"builtin:torus"}, 2000, 9);
  ASSERT_TRUE(torus.ok()) << torus.status();
  ASSERT_TRUE((*service)->UploadPoints(created->session_id(), *torus, 1000).ok());
  bool stalled = false;
  for (int i = 0; i < 500 && !stalled; ++i) {
    absl::SleepFor(absl::Milliseconds(20));
    absl::StatusOr<v1::Session> session = (*service)->GetSession(created->session_id());
    ASSERT_TRUE(session.ok()) << session.status();
    stalled = session->learning().stalled();
  }
  ASSERT_TRUE(stalled) << "the learner did not stall";
  const RunResult table = RunNeuralmesh({"sessions", "--server", server_->address()});
  ASSERT_EQ(table.exit_code, 0) << table.Describe();
  EXPECT_TRUE(std::regex_search(table.out,
                                std::regex(created->session_id() + " +stalling +stalled +2000 ")))
      << table.out;
  EXPECT_THAT(table.out, ::testing::HasSubstr("stalled: learning, but the mesh stopped growing "
                                              "with the points so far; waiting for more"));
  const RunResult json = RunNeuralmesh({"sessions", "--server", server_->address(), "--json"});
  EXPECT_THAT(json.out, ::testing::HasSubstr("\"stalled\": true")) << json.out;
  EXPECT_TRUE((*service)->Delete(created->session_id()).ok());
}

TEST_F(RemoteCliTest, WatchingAFinishedSessionSavesItsFinalMesh) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const std::string out = reconstruct_->out;
  const size_t at = out.find("session ");
  ASSERT_NE(at, std::string::npos) << out;
  const std::string id = out.substr(at + 8, out.find(' ', at + 8) - (at + 8));
  const RunResult watch =
      RunNeuralmesh({"watch", id, "--server", server_->address(), "--out-dir", *dir_ + "/w"});
  ASSERT_EQ(watch.exit_code, 0) << watch.Describe();
  EXPECT_TRUE(std::filesystem::exists(*dir_ + "/w/" + id + ".drc")) << watch.Describe();
}

// get, finish, cancel and delete on sessions made through the client library: the latest
// mesh while points arrive, the final one once `finish` has told the session that all have,
// a cancelled session, and a deleted one that is gone.
TEST_F(RemoteCliTest, SessionCommandsGetFinishCancelTransferAndDelete) {
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(server_->address());
  ASSERT_TRUE(service.ok()) << service.status();
  v1::SessionConfig config;
  config.set_target_vertices(400);
  const std::string id = (*service)->CreateSession(config, "managed").value().session_id();
  const std::string address = server_->address();
  const std::string out = *dir_ + "/managed";
  std::filesystem::create_directories(out);

  const RunResult too_early =
      RunNeuralmesh({"get", id, "--server", address, "-o", out + "/early.ply"});
  EXPECT_EQ(too_early.exit_code, 1) << too_early.Describe();
  EXPECT_THAT(too_early.err, ::testing::HasSubstr("has published no mesh yet"));
  EXPECT_FALSE(std::filesystem::exists(out + "/early.ply"));

  absl::StatusOr<PointCloud> cloud = client::LoadPointsForUpload({"builtin:sphere"}, 4000, 5);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  ASSERT_TRUE((*service)->UploadPoints(id, *cloud, 1000).ok());
  const RunResult latest =
      RunNeuralmesh({"get", id, "--server", address, "-o", out + "/latest.ply", "--wait", "30s"});
  ASSERT_EQ(latest.exit_code, 0) << latest.Describe();
  absl::StatusOr<TriangleMesh> latest_mesh = ReadMesh(out + "/latest.ply");
  ASSERT_TRUE(latest_mesh.ok()) << latest_mesh.status();
  EXPECT_GE(latest_mesh->positions.size(), 4u);
  EXPECT_THAT(latest.out, ::testing::HasSubstr(out + "/latest.ply"));
  const RunResult as_gltf =
      RunNeuralmesh({"get", id, "--server", address, "-o", out + "/latest.glb", "--gltf_draco"});
  ASSERT_EQ(as_gltf.exit_code, 0) << as_gltf.Describe();
  absl::StatusOr<TriangleMesh> gltf_mesh = ReadMesh(out + "/latest.glb");
  ASSERT_TRUE(gltf_mesh.ok()) << gltf_mesh.status();
  EXPECT_GE(gltf_mesh->positions.size(), 4u);
  const RunResult no_final =
      RunNeuralmesh({"get", id, "--server", address, "--final", "-o", out + "/final.drc"});
  EXPECT_EQ(no_final.exit_code, 1) << no_final.Describe();
  EXPECT_THAT(no_final.err, ::testing::HasSubstr("has no final mesh"));

  const RunResult finish = RunNeuralmesh({"finish", id, "--server", address});
  ASSERT_EQ(finish.exit_code, 0) << finish.Describe();
  EXPECT_THAT(finish.out, ::testing::HasSubstr("session " + id + ": finish"));
  EXPECT_THAT(finish.out, ::testing::HasSubstr("4000 points"));
  const RunResult final_mesh = RunNeuralmesh(
      {"get", id, "--server", address, "--final", "--wait", "60s", "-o", out + "/final.drc"});
  ASSERT_EQ(final_mesh.exit_code, 0) << final_mesh.Describe();
  EXPECT_EQ(RowVertices(final_mesh.out, "final"), std::vector<uint64_t>{400}) << final_mesh.out;
  EXPECT_LT(HausdorffToTheUnitSphere(out + "/final.drc"), 0.05);
  const RunResult late_cancel = RunNeuralmesh({"cancel", id, "--server", address});
  EXPECT_EQ(late_cancel.exit_code, 1) << late_cancel.Describe();
  EXPECT_THAT(late_cancel.err, ::testing::HasSubstr("cannot be cancelled"));

  const std::string other = (*service)->CreateSession(config, "dropped").value().session_id();
  const RunResult transfer = RunNeuralmesh({"transfer", other, "--to", "bob", "--server", address});
  ASSERT_EQ(transfer.exit_code, 0) << transfer.Describe();
  EXPECT_EQ(transfer.out, "session " + other + ": collecting, 0 points, 0 of 400 vertices, " +
                              "owned by client bob\n");
  EXPECT_EQ((*service)->GetSession(other).value().owner(), "bob");
  const RunResult nobody = RunNeuralmesh({"transfer", other, "--server", address});
  EXPECT_EQ(nobody.exit_code, 1) << nobody.Describe();
  EXPECT_THAT(nobody.err, ::testing::HasSubstr("--to CLIENT is required"));
  const RunResult cancel = RunNeuralmesh({"cancel", other, "--server", address});
  ASSERT_EQ(cancel.exit_code, 0) << cancel.Describe();
  EXPECT_THAT(cancel.out, ::testing::HasSubstr("session " + other + ": cancelled, 0 points"));
  for (const std::string& gone : {id, other}) {
    const RunResult deleted = RunNeuralmesh({"delete", gone, "--server", address});
    ASSERT_EQ(deleted.exit_code, 0) << deleted.Describe();
    EXPECT_EQ(deleted.out, "session " + gone + " deleted\n");
    const RunResult after = RunNeuralmesh({"get", gone, "--server", address, "-o", out + "/x.drc"});
    EXPECT_EQ(after.exit_code, 1) << after.Describe();
    EXPECT_THAT(after.err, ::testing::HasSubstr("no session with id"));
  }

  const RunResult bad_format =
      RunNeuralmesh({"get", id, "--server", address, "-o", out + "/mesh.txt"});
  EXPECT_EQ(bad_format.exit_code, 1) << bad_format.Describe();
  EXPECT_THAT(bad_format.err,
              ::testing::HasSubstr("use one of .ply, .obj, .off, .stl, .drc, .glb, .gltf"));
  const RunResult bad_wait =
      RunNeuralmesh({"get", id, "--server", address, "-o", out + "/m.ply", "--wait", "-1s"});
  EXPECT_EQ(bad_wait.exit_code, 1) << bad_wait.Describe();
  EXPECT_THAT(bad_wait.err, ::testing::HasSubstr("--wait must be a finite duration >= 0"));
  const RunResult no_session = RunNeuralmesh({"finish", "--server", address});
  EXPECT_NE(no_session.exit_code, 0) << no_session.Describe();
  const RunResult no_server = RunNeuralmesh({"delete", id});
  EXPECT_EQ(no_server.exit_code, 1) << no_server.Describe();
  EXPECT_THAT(no_server.err, ::testing::HasSubstr("--server HOST:PORT is required"));
}

TEST_F(RemoteCliTest, WatchingAnUnknownSessionFails) {
  const RunResult watch = RunNeuralmesh(
      {"watch", "no-such-session", "--server", server_->address(), "--out-dir", *dir_ + "/x"});
  EXPECT_NE(watch.exit_code, 0) << watch.Describe();
  EXPECT_TRUE(absl::StrContains(watch.err, "no-such-session")) << watch.err;
}

// Ctrl-C while the server does not answer: the command ends the upload and the watch at once,
// tries to cancel the session for a few seconds, and says that the session may go on.
TEST(RemoteCliInterruptTest, AnInterruptEndsTheCommandEvenWhenTheServerIsFrozen) {
  std::string error;
  std::unique_ptr<TestServer> server = TestServer::Start({}, &error);
  ASSERT_NE(server, nullptr) << error;
  const std::string dir = MakeTempDir("cli_interrupt");
  BackgroundProcess cli(
      "neuralmesh", {"reconstruct", "builtin:sphere", "--server", server->address(), "--out-dir",
                     dir, "--vertices", "50000", "--points", "200000"});
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> observer =
      client::ReconstructionClient::Connect(server->address());
  ASSERT_TRUE(observer.ok()) << observer.status();
  bool learning = false;
  for (int i = 0; i < 200 && !learning && cli.Running(); ++i) {
    absl::StatusOr<std::vector<client::v1::Session>> sessions = (*observer)->ListSessions();
    learning = sessions.ok() && !sessions->empty() && sessions->front().vertex_count() > 0;
    if (!learning) usleep(50 * 1000);
  }
  ASSERT_TRUE(learning) << "the session did not start learning: " << cli.Stderr();

  server->Signal(SIGSTOP);
  cli.Signal(SIGINT);
  const absl::Time interrupted = absl::Now();
  while (cli.Running() && absl::Now() - interrupted < absl::Seconds(30)) usleep(50 * 1000);
  const absl::Duration took = absl::Now() - interrupted;
  const bool ended = !cli.Running();
  server->Signal(SIGCONT);
  ASSERT_TRUE(ended) << "the command did not end within 30 s of Ctrl-C: " << cli.Stderr();
  EXPECT_LT(took, absl::Seconds(15)) << "the cancel should give up after about 5 s";
  EXPECT_EQ(cli.exit_code(), 1) << cli.Stderr();
  EXPECT_TRUE(absl::StrContains(cli.Stderr(), "interrupted; session") &&
              absl::StrContains(cli.Stderr(), "may go on"))
      << cli.Stderr();
  std::filesystem::remove_all(dir);
}

// A watch whose server goes away for longer than --reconnect_for ends, saying how to go on.
TEST(RemoteCliWatchTest, AWatchWhoseServerStaysAwaySaysHowToGoOn) {
  std::string error;
  std::unique_ptr<TestServer> server = TestServer::Start({}, &error);
  ASSERT_NE(server, nullptr) << error;
  absl::StatusOr<std::unique_ptr<client::ReconstructionClient>> service =
      client::ReconstructionClient::Connect(server->address());
  ASSERT_TRUE(service.ok()) << service.status();
  client::v1::SessionConfig config;
  config.set_target_vertices(100);
  absl::StatusOr<client::v1::Session> session = (*service)->CreateSession(config, "waiting");
  ASSERT_TRUE(session.ok()) << session.status();
  const std::string dir = MakeTempDir("cli_watch_away");
  BackgroundProcess watch(
      "neuralmesh", {"watch", session->session_id(), "--server", server->address(), "--out-dir",
                     dir, "--reconnect_for", "1s"});
  usleep(500 * 1000);  // The watch is open on a session without points.
  server->Signal(SIGKILL);
  const absl::Time killed = absl::Now();
  while (watch.Running() && absl::Now() - killed < absl::Seconds(30)) usleep(50 * 1000);
  ASSERT_FALSE(watch.Running()) << "the watch did not give up: " << watch.Stderr();
  EXPECT_NE(watch.exit_code(), 0);
  const std::string err = watch.Stderr();
  EXPECT_THAT(err, ::testing::HasSubstr("lost (WatchSession")) << err;
  EXPECT_THAT(err, ::testing::HasSubstr("did not answer again within 1s")) << err;
  EXPECT_THAT(err, ::testing::HasSubstr(absl::StrCat("neuralmesh watch ", session->session_id(),
                                                     " saves the session's meshes")))
      << err;
  std::filesystem::remove_all(dir);
}

TEST(RemoteCliUnreachableTest, AnUnreachableServerFailsClearly) {
  const std::string address = "127.0.0.1:" + std::to_string(PickFreePort());
  const std::string dir = MakeTempDir("cli_unreachable");
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"reconstruct", "builtin:sphere", "--server", address, "--out-dir",
                                 dir, "--connect_timeout", "1s"},
        std::vector<std::string>{"sessions", "--server", address, "--connect_timeout", "1s"}}) {
    const RunResult run = RunNeuralmesh(args);
    EXPECT_NE(run.exit_code, 0) << run.Describe();
    EXPECT_TRUE(absl::StrContains(run.err, "cannot reach") && absl::StrContains(run.err, address))
        << run.err;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace neuralmesh::testing
