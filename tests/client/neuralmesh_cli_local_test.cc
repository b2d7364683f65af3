// End-to-end tests of the local subcommands of build/bin/neuralmesh (client/main.cc), run as
// a subprocess: reconstruct, stats and eval on the built-in shapes.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "core/io/file_contents.h"
#include "core/io/mesh_io.h"
#include "core/io/point_cloud_io.h"
#include "core/random.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/client/subprocess.h"
#include "tests/testing/e57_file.h"
#include "tests/testing/las_file.h"
#include "tests/testing/shapes.h"

namespace neuralmesh::testing {
namespace {

// The value of "key": in the JSON `text` (numbers, booleans), or "" when absent.
std::string JsonValue(const std::string& text, const std::string& key) {
  const size_t at = text.find("\"" + key + "\":");
  if (at == std::string::npos) return "";
  size_t begin = at + key.size() + 3;
  while (begin < text.size() && text[begin] == ' ') ++begin;
  const size_t end = text.find_first_of(",\n}", begin);
  return text.substr(begin, end - begin);
}

class LocalCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(MakeTempDir("cli_local"));
    output_ = new std::string(*dir_ + "/sphere.ply");
    reconstruct_ =
        new RunResult(RunNeuralmesh({"reconstruct", "builtin:sphere", "-o", *output_, "--vertices",
                                     "500", "--lod", "100,250", "--seed", "3"}));
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete reconstruct_;
    delete output_;
    delete dir_;
  }

  static std::string* dir_;
  static std::string* output_;
  static RunResult* reconstruct_;
};

std::string* LocalCliTest::dir_ = nullptr;
std::string* LocalCliTest::output_ = nullptr;
RunResult* LocalCliTest::reconstruct_ = nullptr;

TEST_F(LocalCliTest, ReconstructWritesTheMeshAndEveryLod) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  for (const std::string& path :
       {*output_, *dir_ + "/sphere_lod100.ply", *dir_ + "/sphere_lod250.ply"}) {
    EXPECT_TRUE(std::filesystem::exists(path)) << path << " was not written";
    EXPECT_GT(std::filesystem::file_size(path), 0u) << path << " is empty";
  }
}

TEST_F(LocalCliTest, ReconstructPrintsOneRowPerLevelAndASummary) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  int rows = 0;
  for (absl::string_view line : absl::StrSplit(reconstruct_->out, '\n')) {
    const bool lod = absl::StartsWith(line, "lod ") || absl::StartsWith(line, "final ");
    if (!lod) continue;
    ++rows;
    EXPECT_TRUE(absl::StrContains(line, "sphere")) << "row without its file: " << line;
  }
  EXPECT_EQ(rows, 3) << "expected rows for 100, 250 and 500 vertices:\n" << reconstruct_->out;
  EXPECT_TRUE(absl::StrContains(reconstruct_->out, "target reached: 500 vertices"))
      << "missing summary line:\n"
      << reconstruct_->out;
}

TEST_F(LocalCliTest, StatsReportsAClosedGenusZeroMeshOfTheRequestedSize) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const RunResult stats = RunNeuralmesh({"stats", *output_, "--json"});
  ASSERT_EQ(stats.exit_code, 0) << stats.Describe();
  EXPECT_EQ(JsonValue(stats.out, "vertices"), "500") << stats.out;
  EXPECT_EQ(JsonValue(stats.out, "closed"), "true") << stats.out;
  EXPECT_EQ(JsonValue(stats.out, "genus"), "0") << stats.out;
  EXPECT_EQ(JsonValue(stats.out, "boundary_loops"), "0") << stats.out;
}

// Issue 3's check through the command line: reconstructions of the torus and the genus-2
// surface at 5,000 vertices, whose stats must report their genus and no boundary. Seed 1 (the
// default); the acceptance scenarios in topology_learning_test cover seeds 1-10.
TEST_F(LocalCliTest, StatsReportsTheGenusOfTorusAndGenusTwoReconstructions) {
  for (const auto& [shape, genus] : {std::pair<std::string, std::string>{"torus", "1"},
                                     std::pair<std::string, std::string>{"genus2", "2"}}) {
    const std::string path = *dir_ + "/" + shape + ".ply";
    const RunResult run =
        RunNeuralmesh({"reconstruct", "builtin:" + shape, "-o", path, "--vertices", "5000"});
    ASSERT_EQ(run.exit_code, 0) << run.Describe();
    const RunResult stats = RunNeuralmesh({"stats", path, "--json"});
    ASSERT_EQ(stats.exit_code, 0) << stats.Describe();
    EXPECT_EQ(JsonValue(stats.out, "genus"), genus) << shape << ":\n" << stats.out;
    EXPECT_EQ(JsonValue(stats.out, "boundary_loops"), "0") << shape << ":\n" << stats.out;
    EXPECT_EQ(JsonValue(stats.out, "components"), "1") << shape << ":\n" << stats.out;
  }
}

// An earlier OUTPUT refined with --start_mesh: the run starts at its 500 vertices (the LOD
// row counts the Basic Steps from there), keeps the genus and lands on the sphere; a start
// mesh that is not a manifold, or not below --vertices, is refused before any learning.
TEST_F(LocalCliTest, AStartMeshIsRefinedToTheTarget) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const std::string refined = *dir_ + "/refined.ply";
  const RunResult run =
      RunNeuralmesh({"reconstruct", "builtin:sphere", "-o", refined, "--vertices", "1500",
                     "--start_mesh", *output_, "--seed", "4"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "from " + *output_ + " (500 vertices)")) << run.out;
  // From 500 to 1,500 vertices takes about C_vs = 100 steps per new vertex; from the
  // tetrahedron about 150,000.
  const size_t at = run.out.find("target reached: 1500 vertices");
  ASSERT_NE(at, std::string::npos) << run.out;
  uint64_t steps = 0;
  const std::string after_faces = run.out.substr(run.out.find("faces, ", at) + 7);
  ASSERT_TRUE(absl::SimpleAtoi(after_faces.substr(0, after_faces.find(' ')), &steps)) << run.out;
  EXPECT_LT(steps, 130000u) << run.out;
  const RunResult stats = RunNeuralmesh({"stats", refined, "--json"});
  ASSERT_EQ(stats.exit_code, 0) << stats.Describe();
  EXPECT_EQ(JsonValue(stats.out, "vertices"), "1500") << stats.out;
  EXPECT_EQ(JsonValue(stats.out, "genus"), "0") << stats.out;
  EXPECT_EQ(JsonValue(stats.out, "boundary_loops"), "0") << stats.out;
  const RunResult eval = RunNeuralmesh(
      {"eval", refined, "--reference", "builtin:sphere", "--json", "--samples", "20000"});
  ASSERT_EQ(eval.exit_code, 0) << eval.Describe();
  double hausdorff = -1;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(eval.out, "hausdorff"), &hausdorff)) << eval.out;
  EXPECT_LT(hausdorff, 0.01) << eval.out;

  const RunResult small = RunNeuralmesh({"reconstruct", "builtin:sphere", "-o", refined,
                                         "--vertices", "400", "--start_mesh", *output_});
  EXPECT_EQ(small.exit_code, 1) << small.Describe();
  EXPECT_TRUE(absl::StrContains(small.err, "more than 500 vertices (those of --start_mesh)"))
      << small.err;

  const std::string fin = *dir_ + "/fin.obj";  // Three faces on the edge 1-2.
  std::ofstream(fin) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nv 1 1 -1\n"
                        "f 1 2 3\nf 2 4 3\nf 2 3 5\n";
  const RunResult bad = RunNeuralmesh({"reconstruct", "builtin:sphere", "-o", refined,
                                       "--vertices", "1000", "--start_mesh", fin});
  EXPECT_EQ(bad.exit_code, 1) << bad.Describe();
  EXPECT_TRUE(absl::StrContains(bad.err, "--start_mesh '" + fin + "': face 2"))
      << bad.err;
}

TEST_F(LocalCliTest, StatsPrintsTextByDefault) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const RunResult stats = RunNeuralmesh({"stats", *dir_ + "/sphere_lod100.ply"});
  ASSERT_EQ(stats.exit_code, 0) << stats.Describe();
  EXPECT_TRUE(absl::StrContains(stats.out, "genus")) << stats.out;
  EXPECT_TRUE(absl::StrContains(stats.out, "100")) << stats.out;
}

// `stats` of a point cloud file: the points read and left out, their box, what they carry; for
// LAS and LAZ what the header, the records and the compression say.
TEST_F(LocalCliTest, StatsDescribesPointCloudFilesAndLazCompression) {
  testing::LasLayout layout;
  layout.version_minor = 4;
  layout.format = 7;
  layout.vlrs = testing::LasVariableLengthRecord("LASF_Projection", 2112, "PROJCS[\"UTM 32N\"]",
                                                 /*extended=*/false);
  layout.vlr_count = 1;
  std::vector<testing::LasPoint> points;
  for (int i = 0; i < 10; ++i) {
    testing::LasPoint p{100 * i, 200, -300 * i};
    p.classification = static_cast<uint8_t>(i < 7 ? 2 : 6);
    p.withheld = i == 9;
    p.red = 4000;
    points.push_back(p);
  }
  points[3].classification = 7;  // Noise.
  const std::string las = *dir_ + "/described.las", laz = *dir_ + "/described.laz";
  std::ofstream(las, std::ios::binary) << testing::LasFile(layout, points);
  ASSERT_EQ(RunNeuralmesh({"convert", las, "-o", laz}).exit_code, 0);

  const RunResult text = RunNeuralmesh({"stats", laz});
  ASSERT_EQ(text.exit_code, 0) << text.Describe();
  EXPECT_EQ(text.out,
            laz +
                "\n"
                "  LAS 1.4, point format 7: 10 records of 36 bytes (0 extra)\n"
                "  LAZ: LASzip 3.4 (revision 3), layered chunks, item version 3, 1 chunk of "
                "up to 50000 records; " +
                std::to_string(ReadFileContents(laz).value_or("").size()) +
                " bytes\n"
                "  scale 0.01 0.01 0.01, offset 0 0 0\n"
                "  coordinate system: WKT record; GPS time: week\n"
                "  classes: 2: 6, 6: 3, 7: 1 (1 withheld)\n"
                "  8 points read; left out 1 withheld point and 1 classified as noise\n"
                "  from (0, 2, -24) to (8, 2, 0)\n"
                "  with colours\n")
      << text.Describe();
  const RunResult json = RunNeuralmesh({"stats", las, "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.Describe();
  EXPECT_EQ(JsonValue(json.out, "points"), "8") << json.out;
  EXPECT_EQ(JsonValue(json.out, "point_format"), "7") << json.out;
  EXPECT_EQ(JsonValue(json.out, "coordinate_system"), "\"WKT\"") << json.out;
  EXPECT_EQ(JsonValue(json.out, "6"), "3") << json.out;
  EXPECT_EQ(JsonValue(json.out, "compression"), "") << "a LAS file is not compressed";

  // Other point cloud files: their points, box and attributes.
  const std::string xyz = *dir_ + "/described.xyz";
  std::ofstream(xyz) << "0 0 0\n1 2 3\n";
  const RunResult plain = RunNeuralmesh({"stats", xyz});
  ASSERT_EQ(plain.exit_code, 0) << plain.Describe();
  EXPECT_EQ(plain.out, xyz +
                           "\n  2 points read\n  from (0, 0, 0) to (1, 2, 3)\n  with positions "
                           "only\n");
  // Points in a mesh format: the same report.
  const std::string ply = *dir_ + "/described_points.ply";
  PointCloud two;
  two.positions = {{0, 0, 0}, {1, 2, 3}};
  ASSERT_TRUE(WritePointCloud(two, ply).ok());
  const RunResult ply_stats = RunNeuralmesh({"stats", ply});
  ASSERT_EQ(ply_stats.exit_code, 0) << ply_stats.Describe();
  EXPECT_EQ(ply_stats.out, ply +
                               "\n  2 points read\n  from (0, 0, 0) to (1, 2, 3)\n  with "
                               "positions only\n");
  const RunResult missing = RunNeuralmesh({"stats", *dir_ + "/missing.laz"});
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_THAT(missing.err, ::testing::HasSubstr("missing.laz"));
}

TEST_F(LocalCliTest, EvalAgainstTheBuiltinSphereGivesASmallChamferDistance) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  const RunResult eval = RunNeuralmesh(
      {"eval", *output_, "--reference", "builtin:sphere", "--json", "--samples", "20000"});
  ASSERT_EQ(eval.exit_code, 0) << eval.Describe();
  double chamfer = -1;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(eval.out, "chamfer_l1"), &chamfer)) << eval.out;
  // Relative to the diagonal (2 sqrt 3) of the unit sphere's box; 500 vertices land within
  // about 0.3% of it.
  EXPECT_GT(chamfer, 0.0) << eval.out;
  EXPECT_LT(chamfer, 0.01) << "the 500-vertex sphere is far from the unit sphere:\n" << eval.out;

  // Against points in a mesh format (a PLY without faces, with normals): the points' figures.
  PointCloud points = ColoredUnitSpherePoints(4000, 21);
  points.normals = points.positions;
  const std::string ply = *dir_ + "/sphere_points.ply";
  ASSERT_TRUE(WritePointCloud(points, ply).ok());
  const RunResult against_points = RunNeuralmesh({"eval", *output_, "--reference", ply});
  ASSERT_EQ(against_points.exit_code, 0) << against_points.Describe();
  EXPECT_TRUE(absl::StrContains(against_points.out, "against the 4000 points of " + ply))
      << against_points.out;
  EXPECT_TRUE(absl::StrContains(against_points.out, "normal_consistency  0.9"))
      << "the points' normals agree with the mesh's:\n" << against_points.out;
}

TEST_F(LocalCliTest, TheSameSeedGivesByteIdenticalFiles) {
  for (const std::string ext : {".ply", ".drc"}) {
    const std::string a = *dir_ + "/seeded_a" + ext;
    const std::string b = *dir_ + "/seeded_b" + ext;
    for (const std::string& path : {a, b}) {
      const RunResult run = RunNeuralmesh({"reconstruct", "builtin:torus", "-o", path, "--vertices",
                                           "300", "--lod", "120", "--seed", "11"});
      ASSERT_EQ(run.exit_code, 0) << run.Describe();
    }
    EXPECT_EQ(ReadWholeFile(a), ReadWholeFile(b)) << ext << " outputs of one seed differ";
    EXPECT_EQ(ReadWholeFile(*dir_ + "/seeded_a_lod120" + ext),
              ReadWholeFile(*dir_ + "/seeded_b_lod120" + ext))
        << ext << " LOD outputs of one seed differ";
  }
}

TEST_F(LocalCliTest, TheProgressBarIsDrawnOnlyOnATerminalOrWithProgress) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  EXPECT_TRUE(reconstruct_->err.empty()) << "stderr is a file here, so no bar:\n"
                                         << reconstruct_->err;
  const RunResult run = RunNeuralmesh({"reconstruct", "builtin:sphere", "-o",
                                       *dir_ + "/progress.ply", "--vertices", "200", "--progress"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.err, "learning [")) << run.err;
  EXPECT_TRUE(absl::StrContains(run.err, "200/200 vertices")) << run.err;
  EXPECT_FALSE(absl::StrContains(run.out, "learning [")) << "the bar belongs on stderr";
}

TEST_F(LocalCliTest, AStepBudgetStopsEarlyAndStillWritesTheOutput) {
  const std::string path = *dir_ + "/budget.off";
  const RunResult run = RunNeuralmesh(
      {"reconstruct", "builtin:sphere", "-o", path, "--vertices", "5000", "--max_steps", "20000"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(std::filesystem::exists(path)) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "--max_steps reached")) << run.out;
}

TEST_F(LocalCliTest, ReconstructsAPointCloudFileAndRemeshesAMesh) {
  ASSERT_EQ(reconstruct_->exit_code, 0) << reconstruct_->Describe();
  // The 500-vertex sphere serves as a point cloud (its vertices) and as a mesh to remesh.
  const std::string from_points = *dir_ + "/from_points.obj";
  const RunResult points =
      RunNeuralmesh({"reconstruct", *output_, "-o", from_points, "--vertices", "100"});
  EXPECT_EQ(points.exit_code, 0) << points.Describe();
  EXPECT_TRUE(std::filesystem::exists(from_points)) << points.Describe();

  const std::string remeshed = *dir_ + "/remeshed.stl";
  const RunResult remesh = RunNeuralmesh(
      {"reconstruct", *output_, "-o", remeshed, "--vertices", "200", "--sampling", "curvature"});
  EXPECT_EQ(remesh.exit_code, 0) << remesh.Describe();
  EXPECT_TRUE(std::filesystem::exists(remeshed)) << remesh.Describe();
}

// A stray point 100 radii from a sphere's 20,000: the learner pulls a spike out to it (README,
// Status); --remove_outliers takes it out first, and the mesh stays on the sphere.
TEST_F(LocalCliTest, RemoveOutliersTakesAStrayPointOutBeforeLearning) {
  const std::string cloud = *dir_ + "/sphere_and_stray.xyz";
  ASSERT_TRUE(WritePointCloud(UnitSpherePointsAndAStray(20000, 4, Vec3f(100, 0, 0)), cloud).ok());
  const std::string mesh = *dir_ + "/sphere_without_stray.ply";
  const RunResult run =
      RunNeuralmesh({"reconstruct", cloud, "-o", mesh, "--vertices", "1000", "--remove_outliers"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "outliers removed: 1)")) << run.out;
  const RunResult eval = RunNeuralmesh({"eval", mesh, "--reference", "builtin:sphere", "--json"});
  ASSERT_EQ(eval.exit_code, 0) << eval.Describe();
  double hausdorff = 0;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(eval.out, "hausdorff"), &hausdorff)) << eval.out;
  EXPECT_LT(hausdorff, 0.01) << "a spike toward the stray point is left: " << eval.out;
}

// WorstColorErrorOnTheUnitSphere of the mesh file at `path`.
int WorstColorError(const std::string& path) {
  const absl::StatusOr<TriangleMesh> mesh = ReadMesh(path);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  return mesh.ok() ? WorstColorErrorOnTheUnitSphere(*mesh) : -1;
}

// Points coloured by position give meshes (milestones too) whose vertices carry the colours of
// their positions; a coloured mesh remeshed keeps its colours; --nocolors drops them.
TEST_F(LocalCliTest, ColouredInputsGiveColouredMeshes) {
  const std::string cloud = *dir_ + "/colored.ply";
  ASSERT_TRUE(WritePointCloud(ColoredUnitSpherePoints(20000, 5), cloud).ok());
  const std::string mesh = *dir_ + "/colored_mesh.ply";
  const RunResult run =
      RunNeuralmesh({"reconstruct", cloud, "-o", mesh, "--vertices", "1000", "--lod", "300"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "with colours)")) << run.out;
  // Vertices lie near the sphere, their 8 nearest points within about 0.05 (6 levels); the
  // worst vertex was 3 levels off.
  for (const std::string& path : {mesh, *dir_ + "/colored_mesh_lod300.ply"}) {
    const int worst = WorstColorError(path);
    EXPECT_GE(worst, 0) << path << " has no colours";
    EXPECT_LE(worst, 6) << path;
  }

  const std::string plain = *dir_ + "/plain_mesh.obj";
  const RunResult off =
      RunNeuralmesh({"reconstruct", cloud, "-o", plain, "--vertices", "300", "--nocolors"});
  ASSERT_EQ(off.exit_code, 0) << off.Describe();
  EXPECT_EQ(WorstColorError(plain), -1) << "--nocolors wrote colours";

  // The 1,000-vertex mesh, coloured, remeshed by area into Draco.
  const std::string remeshed = *dir_ + "/colored_remesh.drc";
  const RunResult remesh = RunNeuralmesh(
      {"reconstruct", mesh, "-o", remeshed, "--vertices", "400", "--sampling", "area"});
  ASSERT_EQ(remesh.exit_code, 0) << remesh.Describe();
  const int worst = WorstColorError(remeshed);
  EXPECT_GE(worst, 0) << "the remeshed mesh has no colours";
  EXPECT_LE(worst, 6);

  const RunResult bad =
      RunNeuralmesh({"reconstruct", cloud, "-o", plain, "--vertices", "300", "--color_neighbours",
                     "0"});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(absl::StrContains(bad.err, "--color_neighbours is 0; it must be in [1, 64]"))
      << bad.Describe();
  const RunResult remote = RunNeuralmesh({"reconstruct", cloud, "--server", "127.0.0.1:1",
                                          "--out-dir", *dir_, "--color_neighbours", "65"});
  EXPECT_NE(remote.exit_code, 0);
  EXPECT_TRUE(absl::StrContains(remote.err, "--color_neighbours is 65; it must be in [1, 64]"))
      << "checked before connecting: " << remote.Describe();
}

// glTF both ways: learned meshes and their LODs written as .glb (plain and with Draco) and
// .gltf, read back by stats, eval and a remeshing; coloured points read from a .glb.
TEST_F(LocalCliTest, GltfFilesAreWrittenAndRead) {
  const std::string torus = *dir_ + "/torus.glb";
  const RunResult run = RunNeuralmesh(
      {"reconstruct", "builtin:torus", "-o", torus, "--vertices", "800", "--lod", "200"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(std::filesystem::exists(*dir_ + "/torus_lod200.glb"));
  const RunResult stats = RunNeuralmesh({"stats", torus, "--json"});
  ASSERT_EQ(stats.exit_code, 0) << stats.Describe();
  EXPECT_EQ(JsonValue(stats.out, "vertices"), "800") << stats.out;
  EXPECT_EQ(JsonValue(stats.out, "genus"), "1") << stats.out;
  EXPECT_EQ(JsonValue(stats.out, "closed"), "true") << stats.out;
  const RunResult eval = RunNeuralmesh({"eval", torus, "--reference", "builtin:torus", "--json"});
  ASSERT_EQ(eval.exit_code, 0) << eval.Describe();
  double chamfer = 1;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(eval.out, "chamfer_l1"), &chamfer)) << eval.out;
  EXPECT_LT(chamfer, 0.01);

  const std::string compressed = *dir_ + "/torus_draco.glb";
  const RunResult draco = RunNeuralmesh({"reconstruct", "builtin:torus", "-o", compressed,
                                         "--vertices", "800", "--gltf_draco"});
  ASSERT_EQ(draco.exit_code, 0) << draco.Describe();
  EXPECT_LT(std::filesystem::file_size(compressed) * 3, std::filesystem::file_size(torus));
  const absl::StatusOr<TriangleMesh> decoded = ReadMesh(compressed);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_EQ(decoded->positions.size(), 800u);

  // convert: the .glb to PLY and back to a Draco-compressed .gltf, same vertices and faces.
  const std::string converted = *dir_ + "/torus_converted.ply";
  const RunResult convert = RunNeuralmesh({"convert", torus, "-o", converted});
  ASSERT_EQ(convert.exit_code, 0) << convert.Describe();
  EXPECT_EQ(convert.out, converted + ": 800 vertices, 1600 faces\n");
  const RunResult back = RunNeuralmesh(
      {"convert", converted, "-o", *dir_ + "/torus_back.gltf", "--gltf_draco"});
  ASSERT_EQ(back.exit_code, 0) << back.Describe();
  const absl::StatusOr<TriangleMesh> from_ply = ReadMesh(converted);
  const absl::StatusOr<TriangleMesh> from_glb = ReadMesh(torus);
  ASSERT_TRUE(from_ply.ok() && from_glb.ok());
  EXPECT_EQ(from_ply->positions, from_glb->positions);
  EXPECT_EQ(from_ply->faces, from_glb->faces);
  const RunResult bad = RunNeuralmesh({"convert", torus, "-o", *dir_ + "/torus.abc"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(absl::StrContains(bad.err, "unsupported format; use one of")) << bad.err;
  const RunResult missing = RunNeuralmesh({"convert", *dir_ + "/none.glb", "-o", converted});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_TRUE(absl::StrContains(missing.err, "none.glb")) << missing.err;

  const std::string remeshed = *dir_ + "/torus_remeshed.gltf";
  const RunResult remesh = RunNeuralmesh(
      {"reconstruct", torus, "-o", remeshed, "--vertices", "400", "--sampling", "area"});
  ASSERT_EQ(remesh.exit_code, 0) << remesh.Describe();
  const RunResult remeshed_stats = RunNeuralmesh({"stats", remeshed, "--json"});
  EXPECT_EQ(JsonValue(remeshed_stats.out, "vertices"), "400") << remeshed_stats.Describe();

  // Coloured points as a .glb of vertices without faces.
  const PointCloud points = ColoredUnitSpherePoints(20000, 7);
  TriangleMesh vertices;
  vertices.positions = points.positions;
  vertices.colors = points.colors;
  const std::string cloud = *dir_ + "/points.glb";
  ASSERT_TRUE(WriteMesh(vertices, cloud).ok());
  const std::string colored = *dir_ + "/colored.gltf";
  const RunResult from_points =
      RunNeuralmesh({"reconstruct", cloud, "-o", colored, "--vertices", "800"});
  ASSERT_EQ(from_points.exit_code, 0) << from_points.Describe();
  EXPECT_TRUE(absl::StrContains(from_points.out, "with colours)")) << from_points.out;
  const int worst = WorstColorError(colored);
  EXPECT_GE(worst, 0) << "the .gltf has no colours";
  EXPECT_LE(worst, 6);

  const RunResult remote = RunNeuralmesh({"reconstruct", cloud, "--server", "127.0.0.1:1",
                                          "--out-dir", *dir_, "--gltf_draco"});
  EXPECT_NE(remote.exit_code, 0);
  EXPECT_TRUE(absl::StrContains(remote.err, "--gltf_draco applies to a local reconstruct only"))
      << remote.Describe();
}

// convert for points: normals, weights and colours kept by PLY, XYZ, Draco and glTF, positions
// and colours by LAS; outliers removed on the way; what cannot be done refused with a reason.
TEST_F(LocalCliTest, ConvertWritesPointCloudsWithWhatEachFormatHolds) {
  PointCloud cloud = ColoredUnitSpherePoints(5000, 11);
  cloud.normals = cloud.positions;  // The unit sphere's.
  cloud.weights.assign(cloud.size(), 2.0f);
  const std::string ply = *dir_ + "/points.ply";
  ASSERT_TRUE(WritePointCloud(cloud, ply).ok());

  // Each written from the one before, and each keeping all four.
  const std::string xyz = *dir_ + "/points.xyz";
  const std::string glb = *dir_ + "/points.glb";
  const std::string pcd = *dir_ + "/points.pcd";
  const std::string compressed = *dir_ + "/compressed.pcd";
  const std::string ascii = *dir_ + "/ascii.pcd";
  const std::pair<std::string, std::string> steps[] = {
      {ply, xyz}, {xyz, glb}, {glb, pcd}, {pcd, compressed}, {compressed, ascii}};
  for (const auto& [from, to] : steps) {
    SCOPED_TRACE(to);
    std::vector<std::string> args = {"convert", from, "-o", to};
    if (to == compressed) args.insert(args.end(), {"--pcd_data", "binary_compressed"});
    if (to == ascii) args.insert(args.end(), {"--pcd_data", "ascii"});
    const RunResult converted = RunNeuralmesh(args);
    ASSERT_EQ(converted.exit_code, 0) << converted.Describe();
    EXPECT_EQ(converted.out, to + ": 5000 points, with normals, weights, colours\n");
    const absl::StatusOr<PointCloud> kept = ReadPointCloud(to);
    ASSERT_TRUE(kept.ok()) << kept.status();
    EXPECT_EQ(kept->positions, cloud.positions);
    EXPECT_EQ(kept->normals, cloud.normals);
    EXPECT_EQ(kept->weights, cloud.weights);
    EXPECT_EQ(kept->colors, cloud.colors);
  }
  EXPECT_THAT(ReadFileContents(compressed).value_or(""),
              ::testing::HasSubstr("\nDATA binary_compressed\n"));
  EXPECT_THAT(ReadFileContents(ascii).value_or(""), ::testing::HasSubstr("\nDATA ascii\n"));

  const std::string drc = *dir_ + "/points.drc";
  const RunResult to_drc = RunNeuralmesh({"convert", xyz, "-o", drc});
  ASSERT_EQ(to_drc.exit_code, 0) << to_drc.Describe();
  absl::StatusOr<PointCloud> read = ReadPointCloud(drc);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->size(), cloud.size());
  EXPECT_EQ(read->colors.size(), cloud.size());
  EXPECT_EQ(read->weights.size(), cloud.size());

  // The formats that leave something out, and say what: LAS and E57 store scaled integers,
  // PTX exact text.
  struct Lossy {
    std::string from, to, line;
    float tolerance;
    bool normals;
  };
  const Lossy lossy[] = {
      {glb, *dir_ + "/points.las",
       ": 5000 points, with colours\nnote: LAS keeps positions and colours; the normals and "
       "weights were left out\n",
       2e-8f, false},
      {pcd, *dir_ + "/points.ptx",
       ": 5000 points, with colours\nnote: PTX keeps positions and colours; the normals and "
       "weights were left out\n",
       0, false},
      {pcd, *dir_ + "/points.e57",
       ": 5000 points, with normals, colours\nnote: E57 keeps positions, colours and normals; "
       "the weights were left out\n",
       2e-8f, true},
  };
  for (const Lossy& format : lossy) {
    SCOPED_TRACE(format.to);
    const RunResult converted = RunNeuralmesh({"convert", format.from, "-o", format.to});
    ASSERT_EQ(converted.exit_code, 0) << converted.Describe();
    EXPECT_EQ(converted.out, format.to + format.line);
    read = ReadPointCloud(format.to);
    ASSERT_TRUE(read.ok()) << read.status();
    ASSERT_EQ(read->size(), cloud.size());
    for (size_t i = 0; i < cloud.size(); ++i) {
      ASSERT_LE((read->positions[i] - cloud.positions[i]).norm(), format.tolerance) << i;
    }
    EXPECT_EQ(read->normals, format.normals ? cloud.normals : std::vector<Vec3f>{});
    EXPECT_EQ(read->colors, cloud.colors);
    EXPECT_TRUE(read->weights.empty());
  }

  // An organized cloud's empty pixels are left out, and counted.
  const std::string organized = *dir_ + "/organized.pcd";
  ASSERT_TRUE(WriteFileContents(organized,
                                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\n"
                                "DATA ascii\n0 0 0\nnan nan nan\n1 0 0\n0 1 0\n")
                  .ok());
  const RunResult from_organized =
      RunNeuralmesh({"convert", organized, "-o", *dir_ + "/organized.xyz"});
  ASSERT_EQ(from_organized.exit_code, 0) << from_organized.Describe();
  EXPECT_EQ(from_organized.out,
            *dir_ + "/organized.xyz: 3 points; left out 1 point without a position\n");

  // Strays at 100 and 1,000 radii, which hide one at 2 radii from a first pass: two passes
  // remove the three; the sphere's points stay.
  PointCloud strayed = cloud;
  for (const Vec3f& p : {Vec3f(100, 0, 0), Vec3f(0, 0, 1000), Vec3f(2, 0, 0)}) {
    strayed.positions.push_back(p);
    strayed.normals.push_back(Vec3f(1, 0, 0));
    strayed.weights.push_back(2.0f);
    strayed.colors.push_back({0, 0, 0});
  }
  const std::string stray_ply = *dir_ + "/strayed.ply";
  ASSERT_TRUE(WritePointCloud(strayed, stray_ply).ok());
  const std::string clean = *dir_ + "/clean.ply";
  const RunResult once = RunNeuralmesh({"convert", stray_ply, "-o", clean, "--remove_outliers"});
  ASSERT_EQ(once.exit_code, 0) << once.Describe();
  read = ReadPointCloud(clean);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->positions.back(), Vec3f(2, 0, 0)) << "one pass found the stray at 2 radii";
  const RunResult cleaned = RunNeuralmesh(
      {"convert", stray_ply, "-o", clean, "--remove_outliers", "--outlier_passes", "2"});
  ASSERT_EQ(cleaned.exit_code, 0) << cleaned.Describe();
  read = ReadPointCloud(clean);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_LT(read->size(), strayed.size());
  EXPECT_GT(read->size(), strayed.size() * 99 / 100);
  for (const Vec3f& p : read->positions) ASSERT_LT(p.norm(), 1.01f) << "a stray was kept";
  EXPECT_TRUE(absl::StrContains(cleaned.out, " outliers of 5003 removed)")) << cleaned.out;

  struct Refused {
    std::vector<std::string> args;
    std::string message;
  };
  const Refused refused[] = {
      {{"convert", xyz, "-o", *dir_ + "/points.obj"},
       "holds points without faces: OUTPUT '" + *dir_ + "/points.obj' must be a point cloud "
       "format (.ply, .xyz, .txt, .pts, .ptx, .las, .laz, .pcd, .e57, .drc, .glb, .gltf)"},
      {{"convert", "builtin:torus", "-o", *dir_ + "/torus.xyz"},
       "builtin:torus is a surface, not points"},
      {{"convert", xyz, "-o", glb, "--gltf_draco"}, "--gltf_draco compresses meshes"},
      {{"convert", "builtin:sphere", "-o", *dir_ + "/sphere.ply", "--remove_outliers"},
       "--remove_outliers removes points from point clouds; INPUT 'builtin:sphere' is a mesh"},
      {{"convert", xyz, "-o", clean, "--remove_outliers", "--outlier_neighbours", "0"},
       "--outlier_neighbours is 0"},
      {{"convert", xyz, "-o", clean, "--remove_outliers", "--outlier_passes", "17"},
       "--outlier_passes is 17; it must be in [1, 16]"},
      {{"convert", xyz, "-o", *dir_ + "/points.las", "--outliers_as_noise"},
       "--outliers_as_noise needs --remove_outliers"},
      {{"convert", xyz, "-o", clean, "--pcd_data", "ascii"},
       "--pcd_data applies to a .pcd OUTPUT"},
      {{"convert", xyz, "-o", *dir_ + "/points.pcd", "--pcd_data", "text"},
       "--pcd_data is 'text'; it must be binary, binary_compressed or ascii"},
      {{"convert", xyz, "-o", *dir_ + "/points.las", "--remove_outliers", "--outliers_as_noise"},
       "--outliers_as_noise classifies the outliers of .las/.laz INPUTs in a .las/.laz OUTPUT; "
       "INPUT '" +
           xyz + "' to OUTPUT '" + *dir_ + "/points.las' can only leave them out"},
      {{"reconstruct", xyz, "--server", "127.0.0.1:1", "--remove_outliers", "--outliers_on_server",
        "--outlier_passes", "2"},
       "--outlier_passes: the server's filter makes one pass"},
  };
  for (const Refused& r : refused) {
    const RunResult run = RunNeuralmesh(r.args);
    EXPECT_EQ(run.exit_code, 1) << run.Describe();
    EXPECT_TRUE(absl::StrContains(run.err, r.message)) << run.Describe();
  }
}

// A LiDAR scan in LAS, georeferenced (UTM, millimetres): a sphere of radius 10 m centred at
// (500123.5, 4100456.25, 80). The mesh is learned relative to the origin the reader chose,
// written in the scan's coordinates (PLY doubles) and lies on the sphere; both commands say
// where that origin is. STL, which holds only floats, stays relative to it, and says so.
// The centre of the sphere of GeoreferencedSphereLas.
constexpr double kSphereScanCentre[3] = {500123.5, 4100456.25, 80};

// A LAS 1.4 file of format 7 at `path`: 20,000 coloured points of a sphere of radius 10 m
// centred at kSphereScanCentre, in UTM millimetres.
void WriteGeoreferencedSphereLas(const std::string& path) {
  const PointCloud unit = ColoredUnitSpherePoints(20000, 5);
  const testing::LasLayout layout = testing::UtmMillimetreLayout(7);
  std::vector<testing::LasPoint> points;
  for (size_t i = 0; i < unit.size(); ++i) {
    testing::LasPoint p{};
    int32_t* fields[3] = {&p.x, &p.y, &p.z};
    for (int c = 0; c < 3; ++c) {
      *fields[c] = static_cast<int32_t>(std::lround(
          (kSphereScanCentre[c] + 10.0 * unit.positions[i][c] - layout.offset[c]) / 0.001));
    }
    p.red = unit.colors[i][0] * 257;
    p.green = unit.colors[i][1] * 257;
    p.blue = unit.colors[i][2] * 257;
    points.push_back(p);
  }
  std::ofstream(path, std::ios::binary) << testing::LasFile(layout, points);
}

TEST_F(LocalCliTest, GeoreferencedLasScansAreReconstructedRelativeToAnOrigin) {
  const double* centre = kSphereScanCentre;
  const std::string las = *dir_ + "/scan.las";
  WriteGeoreferencedSphereLas(las);

  const std::string mesh = *dir_ + "/scan.ply";
  const RunResult run = RunNeuralmesh({"reconstruct", las, "-o", mesh, "--vertices", "1000"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out,
                                "with colours; coordinates taken relative to (500000, 4100000, 0), "
                                "and put back in the files written)"))
      << run.out;
  std::ifstream written(mesh, std::ios::binary);
  std::string header;
  std::getline(written, header, '\0');
  EXPECT_TRUE(absl::StrContains(header, "property double x\n")) << "absolute coordinates";
  const auto expect_on_sphere = [&](const TriangleMesh& learned) {
    EXPECT_EQ(learned.origin, (std::array<double, 3>{500000, 4100000, 0}));
    for (const Vec3f& v : learned.positions) {
      double squared = 0;
      for (int c = 0; c < 3; ++c) squared += std::pow(learned.origin[c] + v[c] - centre[c], 2);
      ASSERT_NEAR(std::sqrt(squared), 10.0, 0.25) << "a vertex off the sphere";
    }
  };
  const absl::StatusOr<TriangleMesh> learned = ReadMesh(mesh);
  ASSERT_TRUE(learned.ok()) << learned.status();
  EXPECT_FALSE(learned->colors.empty());
  expect_on_sphere(*learned);
  // Against the scan's points, in the scan's frame: the mesh lies within its edges' sag.
  const RunResult fit = RunNeuralmesh({"eval", mesh, "--reference", las, "--json"});
  ASSERT_EQ(fit.exit_code, 0) << fit.Describe();
  double completeness = 0, diagonal = 0;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(fit.out, "completeness"), &completeness)) << fit.out;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(fit.out, "diagonal"), &diagonal)) << fit.out;
  EXPECT_NEAR(diagonal, 20 * std::sqrt(3.0), 0.1) << fit.out;
  EXPECT_LT(completeness * diagonal, 0.15) << fit.out;
  // The mesh in Draco, whose metadata keep another origin 400 m away.
  TriangleMesh moved = *learned;
  ASSERT_TRUE(MoveOrigin({500100, 4100400, 0}, &moved).ok());
  const std::string drc = *dir_ + "/scan_moved.drc";
  ASSERT_TRUE(WriteMesh(moved, drc).ok());
  // Learning goes on from it, moved into the scan's frame: after a few steps (which a start
  // mesh 400 m off could not make up) it still lies on the sphere.
  const std::string refined = *dir_ + "/scan_refined.obj";
  const RunResult again = RunNeuralmesh({"reconstruct", las, "-o", refined, "--vertices", "1500",
                                         "--start_mesh", drc, "--max_steps", "100"});
  ASSERT_EQ(again.exit_code, 0) << again.Describe();
  const absl::StatusOr<TriangleMesh> refined_mesh = ReadMesh(refined);
  ASSERT_TRUE(refined_mesh.ok()) << refined_mesh.status();
  expect_on_sphere(*refined_mesh);
  const RunResult convert = RunNeuralmesh({"convert", las, "-o", *dir_ + "/scan.xyz"});
  ASSERT_EQ(convert.exit_code, 0) << convert.Describe();
  EXPECT_EQ(convert.out, *dir_ + "/scan.xyz: 20000 points, with colours; coordinates taken "
                                 "relative to (500000, 4100000, 0), and put back in the files "
                                 "written\n");
  const absl::StatusOr<PointCloud> converted = ReadPointCloud(*dir_ + "/scan.xyz");
  ASSERT_TRUE(converted.ok()) << converted.status();
  EXPECT_EQ(converted->origin, (std::array<double, 3>{500000, 4100000, 0}));
  // LAS to LAS copies the file, in its own coordinates: no origin to speak of.
  const std::string copy = *dir_ + "/scan_copy.las";
  const RunResult copied = RunNeuralmesh({"convert", las, "-o", copy});
  ASSERT_EQ(copied.exit_code, 0) << copied.Describe();
  const std::string size = std::to_string(ReadFileContents(las).value_or("").size());
  EXPECT_EQ(copied.out, copy + ": 20000 records of " + las +
                            ", every one and the header as they were (" + size + " bytes to " +
                            size + ")\n");

  // eval compares files read relative to different origins in one frame: the mesh against
  // itself in Draco.
  const RunResult self = RunNeuralmesh({"eval", mesh, "--reference", drc, "--json"});
  ASSERT_EQ(self.exit_code, 0) << self.Describe();
  const std::smatch hausdorff = [&] {
    std::smatch m;
    std::regex_search(self.out, m, std::regex("\"hausdorff\": ([0-9.e+-]+)"));
    return m;
  }();
  ASSERT_FALSE(hausdorff.empty()) << self.out;
  EXPECT_LT(std::stod(hausdorff[1]), 1e-3) << "Draco's quantization only: " << self.out;
  const std::string stl = *dir_ + "/scan.stl";
  const RunResult as_stl = RunNeuralmesh({"convert", mesh, "-o", stl});
  ASSERT_EQ(as_stl.exit_code, 0) << as_stl.Describe();
  EXPECT_TRUE(absl::StrContains(as_stl.out, stl + ": STL holds only floats; its coordinates "
                                                  "stay relative to (500000, 4100000, 0)\n"))
      << as_stl.out;
}

// A scan whose noise is classified (and one point withheld): reconstruct and convert leave
// those points out and say how many.
// The mesh at `path` has `vertices` vertices, all within `tolerance` of the sphere of `radius`
// about `centre` (in the coordinates its origin puts back).
void ExpectVerticesOnSphere(const std::string& path, size_t vertices, const double centre[3],
                            double radius, double tolerance) {
  const absl::StatusOr<TriangleMesh> learned = ReadMesh(path);
  ASSERT_TRUE(learned.ok()) << learned.status();
  EXPECT_EQ(learned->positions.size(), vertices);
  for (const Vec3f& v : learned->positions) {
    double squared = 0;
    for (int c = 0; c < 3; ++c) squared += std::pow(learned->origin[c] + v[c] - centre[c], 2);
    ASSERT_NEAR(std::sqrt(squared), radius, tolerance) << "a vertex off the sphere";
  }
}

// Two PTX scans of one sphere of radius 10 at a UTM position, each in its scanner's frame: the
// second scanner stands 30 m east, turned 90 degrees, so its points only meet the first's
// once its transformation is applied.
TEST_F(LocalCliTest, PtxScansAreReconstructedInTheirRegisteredFrame) {
  const PointCloud unit = ColoredUnitSpherePoints(12000, 6);
  const double centre[3] = {500123.5, 4100456.25, 80};
  const double second[3] = {500153.5, 4100456.25, 80};  // The second scanner's position.
  std::string ptx = absl::StrCat(
      unit.size() / 2, "\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n",
      absl::StrFormat("%.2f %.2f %.2f 1\n", centre[0], centre[1], centre[2]));
  for (size_t i = 0; i < unit.size() / 2; ++i) {
    absl::StrAppend(&ptx, absl::StrFormat("%.4f %.4f %.4f 0.5\n", 10 * unit.positions[i][0],
                                          10 * unit.positions[i][1], 10 * unit.positions[i][2]));
  }
  // The second scanner's x axis points north (its columns: x to (0,1,0), y to (-1,0,0)).
  absl::StrAppend(&ptx, unit.size() - unit.size() / 2,
                  "\n1\n0 0 0\n0 1 0\n-1 0 0\n0 0 1\n0 1 0 0\n-1 0 0 0\n0 0 1 0\n",
                  absl::StrFormat("%.2f %.2f %.2f 1\n", second[0], second[1], second[2]));
  for (size_t i = unit.size() / 2; i < unit.size(); ++i) {
    // Registered p = R local + t, so local = R^T (p - t): x_local = p_y - t_y, y_local = t_x - p_x.
    const double p[3] = {centre[0] + 10 * unit.positions[i][0],
                         centre[1] + 10 * unit.positions[i][1],
                         centre[2] + 10 * unit.positions[i][2]};
    absl::StrAppend(&ptx, absl::StrFormat("%.4f %.4f %.4f 0.5\n", p[1] - second[1],
                                          second[0] - p[0], p[2] - second[2]));
  }
  const std::string path = *dir_ + "/scans.ptx";
  ASSERT_TRUE(WriteFileContents(path, ptx).ok());
  const std::string mesh = *dir_ + "/scans.ply";
  const RunResult run = RunNeuralmesh({"reconstruct", path, "-o", mesh, "--vertices", "800"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "coordinates taken relative to (500000, 4100000, 0)"))
      << run.out;
  ExpectVerticesOnSphere(mesh, 800, centre, 10.0, 0.3);
}

// Two scanner stations of an E57 file, each holding its points as a scanner measures them:
// range (in 20 bits, steps of 0.1 mm), azimuth and elevation from the station, placed
// by its pose; a few returns that never came back are marked invalid.
TEST_F(LocalCliTest, E57ScansInSphericalCoordinatesAreReconstructedWhereTheirPosesPutThem) {
  const PointCloud unit = ColoredUnitSpherePoints(12000, 8);
  const double centre[3] = {500123.5, 4100456.25, 80};
  // Station 0 stands 25 m west of the centre; station 1 30 m east, turned 90 degrees about z.
  const double stations[2][3] = {{500098.5, 4100456.25, 80}, {500153.5, 4100456.25, 80}};
  const double turn[2] = {0, M_PI / 2};
  std::vector<testing::E57Scan> scans(2);
  for (int s = 0; s < 2; ++s) {
    std::vector<uint64_t> ranges, states;
    std::vector<double> azimuths, elevations;
    const size_t first = s == 0 ? 0 : unit.size() / 2;
    const size_t last = s == 0 ? unit.size() / 2 : unit.size();
    for (size_t i = first; i < last; ++i) {
      double d[3];
      for (int c = 0; c < 3; ++c) d[c] = centre[c] + 10 * unit.positions[i][c] - stations[s][c];
      // The station's frame: the registered offset turned back by its rotation.
      const double x = std::cos(turn[s]) * d[0] + std::sin(turn[s]) * d[1];
      const double y = -std::sin(turn[s]) * d[0] + std::cos(turn[s]) * d[1];
      const double range = std::sqrt(x * x + y * y + d[2] * d[2]);
      ranges.push_back(static_cast<uint64_t>(std::llround(range / 0.0001)));
      azimuths.push_back(std::atan2(y, x));
      elevations.push_back(std::asin(d[2] / range));
      states.push_back(0);
    }
    for (int k = 0; k < 25; ++k) {  // No return: no range, a direction only.
      ranges.push_back(0);
      azimuths.push_back(0.01 * k);
      elevations.push_back(0);
      states.push_back(1);
    }
    testing::E57Scan& scan = scans[s];
    scan.records = ranges.size();
    scan.fields = {
        {"<sphericalRange type=\"ScaledInteger\" minimum=\"0\" maximum=\"1000000\" "
         "scale=\"0.0001\"/>",
         testing::E57PackBits(ranges, 20)},
        {"<sphericalAzimuth type=\"Float\"/>", testing::E57Floats(azimuths)},
        {"<sphericalElevation type=\"Float\"/>", testing::E57Floats(elevations)},
        {"<sphericalInvalidState type=\"Integer\" minimum=\"0\" maximum=\"2\"/>",
         testing::E57PackBits(states, 2)}};
    scan.bytes_per_packet = 16000;
    scan.elements = absl::StrFormat(
        "<pose type=\"Structure\"><rotation type=\"Structure\"><w type=\"Float\">%.17g</w>"
        "<z type=\"Float\">%.17g</z></rotation><translation type=\"Structure\">"
        "<x type=\"Float\">%.17g</x><y type=\"Float\">%.17g</y><z type=\"Float\">%.17g</z>"
        "</translation></pose>",
        std::cos(turn[s] / 2), std::sin(turn[s] / 2), stations[s][0], stations[s][1],
        stations[s][2]);
  }
  const std::string path = *dir_ + "/stations.e57";
  ASSERT_TRUE(WriteFileContents(path, testing::E57File(scans)).ok());
  const std::string mesh = *dir_ + "/stations.ply";
  const RunResult run = RunNeuralmesh({"reconstruct", path, "-o", mesh, "--vertices", "800"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "left out 50 points without a position")) << run.out;
  EXPECT_TRUE(absl::StrContains(run.out, "coordinates taken relative to (500000, 4100000, 0)"))
      << run.out;
  ExpectVerticesOnSphere(mesh, 800, centre, 10.0, 0.3);
}

// A site in two files, a coloured LAS tile of its western half and an XYZ file of its eastern
// half, each in its own frame (offsets, scales): learned as one surface, and written as one
// cloud, the colours dropped because the XYZ file has none.
TEST_F(LocalCliTest, SeveralPointCloudFilesAreLearnedAndWrittenAsOne) {
  const PointCloud unit = ColoredUnitSpherePoints(12000, 10);
  const double centre[3] = {500123.5, 4100456.25, 80};
  testing::LasLayout layout;
  layout.format = 2;
  const double offset[3] = {500100, 4100400, 60};
  for (int c = 0; c < 3; ++c) {
    layout.scale[c] = 0.001;
    layout.offset[c] = offset[c];
  }
  std::vector<testing::LasPoint> west;
  std::string east_xyz;
  size_t east = 0;
  for (size_t i = 0; i < unit.size(); ++i) {
    double p[3];
    for (int c = 0; c < 3; ++c) p[c] = centre[c] + 10 * unit.positions[i][c];
    if (unit.positions[i][0] < 0) {
      testing::LasPoint point{static_cast<int32_t>(std::lround((p[0] - offset[0]) / 0.001)),
                              static_cast<int32_t>(std::lround((p[1] - offset[1]) / 0.001)),
                              static_cast<int32_t>(std::lround((p[2] - offset[2]) / 0.001))};
      point.red = unit.colors[i][0] * 257;
      point.green = unit.colors[i][1] * 257;
      point.blue = unit.colors[i][2] * 257;
      west.push_back(point);
    } else {
      absl::StrAppend(&east_xyz, absl::StrFormat("%.4f %.4f %.4f\n", p[0], p[1], p[2]));
      ++east;
    }
  }
  const std::string las = *dir_ + "/west.las";
  const std::string xyz = *dir_ + "/east.xyz";
  std::ofstream(las, std::ios::binary) << testing::LasFile(layout, west);
  ASSERT_TRUE(WriteFileContents(xyz, east_xyz).ok());

  const std::string mesh = *dir_ + "/site.ply";
  const RunResult run =
      RunNeuralmesh({"reconstruct", las, xyz, "-o", mesh, "--vertices", "800"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, absl::StrCat(unit.size(), " points of ", las, ", ", xyz,
                                                      " (uniform sampling; colours dropped (",
                                                      xyz, " has none)")))
      << run.out;
  ExpectVerticesOnSphere(mesh, 800, centre, 10.0, 0.3);

  const std::string e57 = *dir_ + "/site.e57";
  const RunResult converted = RunNeuralmesh({"convert", las, xyz, "-o", e57});
  ASSERT_EQ(converted.exit_code, 0) << converted.Describe();
  EXPECT_EQ(converted.out,
            absl::StrCat(e57, ": ", unit.size(), " points; colours dropped (", xyz,
                         " has none); coordinates taken relative to (500000, 4100000, 0), and "
                         "put back in the files written\n"));
  const absl::StatusOr<PointCloud> read = ReadPointCloud(e57);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), unit.size());
  EXPECT_EQ(read->size() - east, west.size());
  for (size_t i = 0; i < read->size(); ++i) {
    double squared = 0;
    for (int c = 0; c < 3; ++c) {
      squared += std::pow(read->origin[c] + read->positions[i][c] - centre[c], 2);
    }
    ASSERT_NEAR(std::sqrt(squared), 10.0, 2e-3) << "point " << i;
  }

  // Several inputs are points: not a mesh output, not a builtin among them.
  const RunResult to_obj = RunNeuralmesh({"convert", las, xyz, "-o", *dir_ + "/site.obj"});
  EXPECT_EQ(to_obj.exit_code, 1);
  EXPECT_TRUE(absl::StrContains(to_obj.err, "several INPUTs are written as one point cloud"))
      << to_obj.err;
  const RunResult with_builtin = RunNeuralmesh(
      {"reconstruct", las, "builtin:sphere", "-o", *dir_ + "/x.ply", "--vertices", "100"});
  EXPECT_EQ(with_builtin.exit_code, 1);
  EXPECT_TRUE(absl::StrContains(with_builtin.err,
                                "builtin:sphere is a surface: several INPUTs must all be point "
                                "cloud files"))
      << with_builtin.err;
}

// LAS records of `count` points of the unit sphere, at the layout's scale (the same on every
// axis, no offset).
std::vector<testing::LasPoint> UnitSphereLasPoints(int count, uint64_t seed,
                                                   const testing::LasLayout& layout) {
  std::vector<testing::LasPoint> points;
  for (const Vec3f& p : ColoredUnitSpherePoints(count, seed).positions) {
    points.push_back({static_cast<int32_t>(std::lround(p[0] / layout.scale[0])),
                      static_cast<int32_t>(std::lround(p[1] / layout.scale[1])),
                      static_cast<int32_t>(std::lround(p[2] / layout.scale[2]))});
  }
  return points;
}

// --off_core: the scan sampled where it lies instead of read. The mesh lies on the sphere in
// the scan's coordinates, a seed gives the same file again, and what cannot be sampled so is
// refused, saying why.
TEST_F(LocalCliTest, OffCoreLearnsALasPlyOrPcdScanWhereItLies) {
  const std::string las = *dir_ + "/scan.las";
  WriteGeoreferencedSphereLas(las);
  const std::string mesh = *dir_ + "/off_core.ply";
  const std::vector<std::string> learn = {"reconstruct", las,    "-o",        mesh,
                                          "--vertices",  "1000", "--off_core"};
  const RunResult run = RunNeuralmesh(learn);
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(
      run.out, absl::StrCat("learning the 20000 records of ", las,
                            ", sampled where they lie (off-core; 100.0% of them points to read; "
                            "colours are not painted off-core; coordinates taken relative to "
                            "(500000, 4100000, 0), and put back in the files written)")))
      << run.out;
  const absl::StatusOr<TriangleMesh> learned = ReadMesh(mesh);
  ASSERT_TRUE(learned.ok()) << learned.status();
  EXPECT_EQ(learned->origin, (std::array<double, 3>{500000, 4100000, 0}));
  EXPECT_TRUE(learned->colors.empty());
  EXPECT_EQ(learned->positions.size(), 1000u);
  for (const Vec3f& v : learned->positions) {
    double squared = 0;
    for (int c = 0; c < 3; ++c) {
      squared += std::pow(learned->origin[c] + v[c] - kSphereScanCentre[c], 2);
    }
    ASSERT_NEAR(std::sqrt(squared), 10.0, 0.25) << "a vertex off the sphere";
  }
  const RunResult stats = RunNeuralmesh({"stats", mesh, "--json"});
  EXPECT_EQ(JsonValue(stats.out, "genus"), "0") << stats.out;
  EXPECT_EQ(JsonValue(stats.out, "boundary_loops"), "0") << stats.out;
  std::vector<std::string> again = learn;
  again[3] = *dir_ + "/off_core_again.ply";
  ASSERT_EQ(RunNeuralmesh(again).exit_code, 0);
  EXPECT_EQ(ReadWholeFile(mesh), ReadWholeFile(again[3])) << "the same seed, the same mesh";

  // The scan as binary PLY (doubles, as georeferenced points are written): the same sphere.
  const std::string ply = *dir_ + "/scan.ply";
  ASSERT_EQ(RunNeuralmesh({"convert", las, "-o", ply}).exit_code, 0);
  std::vector<std::string> from_ply = learn;
  from_ply[1] = ply;
  from_ply[3] = *dir_ + "/off_core_ply.obj";
  const RunResult ply_run = RunNeuralmesh(from_ply);
  ASSERT_EQ(ply_run.exit_code, 0) << ply_run.Describe();
  EXPECT_TRUE(absl::StrContains(ply_run.out, "learning the 20000 records of " + ply))
      << ply_run.out;
  const absl::StatusOr<TriangleMesh> from_ply_mesh = ReadMesh(from_ply[3]);
  ASSERT_TRUE(from_ply_mesh.ok()) << from_ply_mesh.status();
  EXPECT_EQ(from_ply_mesh->origin, learned->origin);
  for (const Vec3f& v : from_ply_mesh->positions) {
    double squared = 0;
    for (int c = 0; c < 3; ++c) {
      squared += std::pow(from_ply_mesh->origin[c] + v[c] - kSphereScanCentre[c], 2);
    }
    ASSERT_NEAR(std::sqrt(squared), 10.0, 0.25) << "a vertex off the sphere";
  }

  // And as binary PCD.
  const std::string pcd = *dir_ + "/scan.pcd";
  ASSERT_EQ(RunNeuralmesh({"convert", las, "-o", pcd}).exit_code, 0);
  const RunResult pcd_run = RunNeuralmesh(
      {"reconstruct", pcd, "-o", *dir_ + "/off_core_pcd.ply", "--vertices", "300", "--off_core"});
  ASSERT_EQ(pcd_run.exit_code, 0) << pcd_run.Describe();
  EXPECT_TRUE(absl::StrContains(pcd_run.out, "learning the 20000 records of " + pcd))
      << pcd_run.out;

  const std::string laz = *dir_ + "/scan.laz";
  const std::string xyz = *dir_ + "/scan.xyz";
  ASSERT_EQ(RunNeuralmesh({"convert", las, "-o", laz}).exit_code, 0);
  ASSERT_EQ(RunNeuralmesh({"convert", las, "-o", xyz}).exit_code, 0);
  const std::string out = *dir_ + "/refused.ply";
  const std::vector<std::pair<std::vector<std::string>, std::string>> refused = {
      {{las, las}, "several INPUTs are read whole"},
      {{xyz}, "INPUT '" + xyz + "' is read whole without it"},
      {{laz}, "cannot be read one at a time"},
      {{las, "--remove_outliers"}, "not with --off_core"},
      {{las, "--sampling", "weighted"}, "samples uniformly, not by --sampling weighted"},
  };
  for (const auto& [args, why] : refused) {
    std::vector<std::string> command = {"reconstruct", "-o",  out,
                                        "--vertices",  "100", "--off_core"};
    command.insert(command.begin() + 1, args.begin(), args.end());
    const RunResult result = RunNeuralmesh(command);
    EXPECT_NE(result.exit_code, 0) << result.Describe();
    EXPECT_TRUE(absl::StrContains(result.err, why)) << result.Describe();
  }
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing may be written";
}

// A scan cut short while it is learned where it lies (another program rewriting it): the run
// stops with an error saying so instead of a crash (SIGBUS), and writes no mesh learned from
// what was read past the file's new end; the levels of detail written before stand.
TEST_F(LocalCliTest, OffCoreLearningStopsSayingSoWhenTheScanShrinks) {
  const std::string las = *dir_ + "/shrinks.las";
  testing::LasLayout layout;
  layout.format = 1;
  for (double& s : layout.scale) s = 0.0001;
  std::ofstream(las, std::ios::binary)
      << testing::LasFile(layout, UnitSphereLasPoints(300000, 3, layout));
  const std::string mesh = *dir_ + "/shrinks.ply";
  BackgroundProcess run("neuralmesh", {"reconstruct", las, "-o", mesh, "--vertices", "400000",
                                       "--lod", "1000", "--off_core"});
  const std::string lod = *dir_ + "/shrinks_lod1000.ply";
  for (int i = 0; i < 500 && !std::filesystem::exists(lod) && run.Running(); ++i) {
    usleep(20 * 1000);
  }
  ASSERT_TRUE(std::filesystem::exists(lod)) << run.Stderr();
  std::filesystem::resize_file(las, 50000);
  for (int i = 0; i < 500 && run.Running(); ++i) usleep(20 * 1000);
  ASSERT_FALSE(run.Running()) << "learning went on from a file cut short";
  EXPECT_EQ(run.exit_code(), 1) << run.Stderr();
  EXPECT_TRUE(absl::StrContains(run.Stderr(),
                                absl::StrCat("'", las,
                                             "' shrank from 8400227 to 50000 bytes while it was "
                                             "read; what lay past its new end is gone; learning "
                                             "stopped at ")))
      << run.Stderr();
  EXPECT_TRUE(absl::StrContains(run.Stderr(), " vertices and " + mesh + " was not written"))
      << run.Stderr();
  EXPECT_FALSE(std::filesystem::exists(mesh));
  const absl::StatusOr<TriangleMesh> first = ReadMesh(lod);
  ASSERT_TRUE(first.ok()) << first.status();
  for (const Vec3f& v : first->positions) ASSERT_NEAR(v.norm(), 1.0, 0.1) << "the LOD stands";
}

TEST_F(LocalCliTest, ClassifiedNoiseInLasScansIsLeftOutAndCounted) {
  testing::LasLayout layout;
  layout.format = 1;
  for (double& s : layout.scale) s = 0.0001;
  std::vector<testing::LasPoint> points = UnitSphereLasPoints(4000, 9, layout);
  for (int i = 0; i < 40; ++i) {  // Strays 3 to 5 radii out, classified as high noise.
    testing::LasPoint stray{30000 + 500 * i, -50000 + 1000 * i, 40000};
    stray.classification = 18;
    points.push_back(stray);
  }
  points[0].withheld = true;
  const std::string las = *dir_ + "/classified.las";
  std::ofstream(las, std::ios::binary) << testing::LasFile(layout, points);

  const std::string xyz = *dir_ + "/classified.xyz";
  const RunResult convert = RunNeuralmesh({"convert", las, "-o", xyz});
  ASSERT_EQ(convert.exit_code, 0) << convert.Describe();
  EXPECT_EQ(convert.out,
            xyz + ": 3999 points; left out 1 withheld point and 40 classified as noise\n");
  const std::string mesh = *dir_ + "/classified.ply";
  const RunResult run = RunNeuralmesh({"reconstruct", las, "-o", mesh, "--vertices", "300"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "3999 points of " + las + " (uniform sampling; left out "
                                         "1 withheld point and 40 classified as noise)"))
      << run.out;
  const absl::StatusOr<TriangleMesh> learned = ReadMesh(mesh);
  ASSERT_TRUE(learned.ok()) << learned.status();
  for (const Vec3f& v : learned->positions) {
    ASSERT_NEAR(v.norm(), 1.0f, 0.05f) << "no vertex pulled toward the noise";
  }
}

// A LAS scan cleaned of its strays and written as LAS keeps what the learner does not read:
// each record whole (class, intensity, returns, GPS time), the header's scale and offset, its
// coordinate system. Records classified as noise are left out as on reading.
TEST_F(LocalCliTest, ALasScanCleanedIntoLasKeepsItsRecordsWhole) {
  testing::LasLayout layout;
  layout.version_minor = 4;
  layout.format = 6;
  for (double& s : layout.scale) s = 0.00025;
  layout.vlrs = std::string(54, '\0') + "COMPD_CS[\"a coordinate system\"]";
  layout.vlrs[2] = 'x';  // The record's user id, so that it is not all zeros.
  layout.vlrs[20] = static_cast<char>(layout.vlrs.size() - 54);
  layout.vlr_count = 1;
  std::vector<testing::LasPoint> points = UnitSphereLasPoints(3000, 4, layout);
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].classification = 2;
    points[i].intensity = static_cast<uint16_t>(i);
    points[i].gps_time = 4.0e5 + i;
  }
  for (int i = 0; i < 3; ++i) {  // Strays 4 radii out, unclassified: outliers.
    testing::LasPoint stray{16000 + 400 * i, -16000, 0};
    stray.intensity = 60000;
    points.insert(points.begin() + 1000 * i + 500, stray);
  }
  points[7].classification = 7;  // Low noise.
  const std::string las = *dir_ + "/scan.las";
  const std::string source = testing::LasFile(layout, points);
  std::ofstream(las, std::ios::binary) << source;

  const std::string clean = *dir_ + "/clean.las";
  const RunResult run = RunNeuralmesh({"convert", las, "-o", clean, "--remove_outliers"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_EQ(run.out, clean + ": 2999 points, each record as in " + las +
                         " with every field, and its header's scale, offset and "
                         "variable-length records (3 outliers of 3002 removed); left out 1 "
                         "point classified as noise\n");
  const std::string bytes = ReadFileContents(clean).value_or("");
  ASSERT_EQ(bytes.size(), source.size() - 4 * 30);
  const size_t first = 375 + layout.vlrs.size();
  EXPECT_EQ(bytes.substr(375, layout.vlrs.size()), layout.vlrs) << "the coordinate system";
  EXPECT_EQ(bytes.substr(131, 48), source.substr(131, 48)) << "scale and offset";
  // The records in order, each as it was: the source's but the strays and the noise.
  size_t at = first;
  for (size_t i = 0; i < points.size(); ++i) {
    if (points[i].intensity == 60000 || points[i].classification == 7) continue;
    ASSERT_LT(at, bytes.size());
    ASSERT_EQ(bytes.substr(at, 30), source.substr(first + 30 * i, 30)) << "source record " << i;
    at += 30;
  }
  const absl::StatusOr<PointCloud> read = ReadPointCloud(clean);
  ASSERT_TRUE(read.ok()) << read.status();
  for (const Vec3f& p : read->positions) ASSERT_NEAR(p.norm(), 1.0f, 1e-3f);

  // Classified as noise instead: every record stays, the strays' with class 7, which the
  // readers leave out.
  const std::string marked = *dir_ + "/marked.las";
  const RunResult mark =
      RunNeuralmesh({"convert", las, "-o", marked, "--remove_outliers", "--outliers_as_noise"});
  ASSERT_EQ(mark.exit_code, 0) << mark.Describe();
  EXPECT_EQ(mark.out, marked + ": 3002 points, each record as in " + las +
                          " with every field, and its header's scale, offset and "
                          "variable-length records (3 outliers of 3002 classified as noise)\n");
  const std::string marked_bytes = ReadFileContents(marked).value_or("");
  ASSERT_EQ(marked_bytes.size(), source.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const bool noise = points[i].intensity == 60000 || points[i].classification == 7;
    EXPECT_EQ(marked_bytes[first + 30 * i + 16], noise ? 7 : 2) << "record " << i;
  }
  PointsLeftOut left_out;
  const absl::StatusOr<PointCloud> unmarked = ReadPointCloud(marked, &left_out);
  ASSERT_TRUE(unmarked.ok()) << unmarked.status();
  EXPECT_EQ(unmarked->size(), 2999u);
  EXPECT_EQ(left_out.noise, 4u);

  // Two tiles joined: one file of both tiles' records, each whole, after the first's header.
  const std::string both = *dir_ + "/both.las";
  const RunResult joined = RunNeuralmesh({"convert", las, clean, "-o", both});
  ASSERT_EQ(joined.exit_code, 0) << joined.Describe();
  EXPECT_EQ(joined.out, both + ": 6001 points, each record as in its INPUT with every field, "
                               "and the header's offset and variable-length records of " +
                            las + "; left out 1 point classified as noise\n");
  const std::string both_bytes = ReadFileContents(both).value_or("");
  ASSERT_EQ(both_bytes.size(), first + 6001 * 30);
  EXPECT_EQ(both_bytes.substr(375, layout.vlrs.size()), layout.vlrs) << "the coordinate system";
  EXPECT_EQ(both_bytes.substr(first + 3002 * 30), bytes.substr(first)) << "the second tile";
  EXPECT_EQ(both_bytes.substr(first + 7 * 30, 30), source.substr(first + 8 * 30, 30))
      << "the first tile, its noise left out";

  // A tile of another point format joins them in the one that holds both's fields.
  testing::LasLayout other = layout;
  other.format = 1;
  const std::string tile = *dir_ + "/tile.las";
  std::ofstream(tile, std::ios::binary) << testing::LasFile(other, {{0, 0, 100}, {0, 100, 0}});
  const std::string mixed_path = *dir_ + "/mixed.las";
  const RunResult mixed = RunNeuralmesh({"convert", las, tile, "-o", mixed_path});
  ASSERT_EQ(mixed.exit_code, 0) << mixed.Describe();
  EXPECT_EQ(mixed.out, mixed_path +
                           ": 3004 points, each record as in its INPUT with every "
                           "field, in point format 6 of LAS 1.4, and the header's offset "
                           "and variable-length records of " +
                           las + "; left out 1 point classified as noise\n");
  const std::string mixed_bytes = ReadFileContents(mixed_path).value_or("");
  ASSERT_EQ(mixed_bytes.size(), first + 3004 * 30);
  EXPECT_EQ(mixed_bytes[104], 6);

  // Tiles in other coordinate systems go through the point cloud (LAS 1.2 of positions),
  // saying why; --outliers_as_noise, which needs their records, is refused.
  other.vlrs =
      testing::LasVariableLengthRecord("LASF_Projection", 2112, "PROJCS[\"another zone\"]", false);
  std::ofstream(tile, std::ios::binary) << testing::LasFile(other, {{0, 0, 100}, {0, 100, 0}});
  const RunResult apart = RunNeuralmesh({"convert", las, tile, "-o", mixed_path});
  ASSERT_EQ(apart.exit_code, 0) << apart.Describe();
  EXPECT_THAT(apart.out, ::testing::HasSubstr("3004 points"));
  EXPECT_THAT(apart.out, ::testing::HasSubstr("; the records could not be kept whole: the "
                                              "coordinate systems or extra bytes of '" +
                                              tile + "' and '" + las + "' differ\n"));
  const RunResult refused = RunNeuralmesh(
      {"convert", las, tile, "-o", mixed_path, "--remove_outliers", "--outliers_as_noise"});
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_THAT(refused.err,
              ::testing::HasSubstr("--outliers_as_noise: the records of INPUT '" + las + "', '" +
                                   tile + "' cannot be put in one file: the coordinate systems"));
}

// A classified scan: a building (class 6, a unit sphere) above the ground (class 2, a square
// 3 m below). --las_classes 6 learns the building alone; --las_classes 2 converts the ground
// alone, LAS to LAS with its records whole.
// LAZ (LASzip-compressed LAS) is read and written as LAS is: a scan converted to .laz keeps
// every record (noise too) in a smaller file and converts back to the same bytes, is cleaned
// into LAZ with its records whole, and is learned from; LAS 1.4's formats, which are not
// written as LAZ here, go through the point cloud, saying why.
TEST_F(LocalCliTest, ALazScanIsConvertedAndLearnedAsItsLas) {
  testing::LasLayout layout;
  layout.format = 1;
  for (double& s : layout.scale) s = 0.0001;
  std::vector<testing::LasPoint> points = UnitSphereLasPoints(3000, 5, layout);
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].intensity = static_cast<uint16_t>(100 + i % 50);
    points[i].gps_time = 2.0e5 + 0.001 * i;
  }
  points[7].classification = 7;  // Low noise: kept by a copy, left out by the readers.
  const std::string las = *dir_ + "/scan.las", laz = *dir_ + "/scan.laz";
  const std::string source = testing::LasFile(layout, points);
  std::ofstream(las, std::ios::binary) << source;
  const RunResult compress = RunNeuralmesh({"convert", las, "-o", laz});
  ASSERT_EQ(compress.exit_code, 0) << compress.Describe();
  const std::string laz_bytes = ReadFileContents(laz).value_or("");
  EXPECT_EQ(compress.out, absl::StrCat(laz, ": 3000 records of ", las,
                                       ", every one and the header as they were (",
                                       source.size(), " bytes to ", laz_bytes.size(), ")\n"));
  EXPECT_EQ(static_cast<uint8_t>(laz_bytes.at(104)), 0x81) << "format 1, compressed";
  EXPECT_LT(laz_bytes.size(), source.size() / 2);
  const std::string back = *dir_ + "/back.las";
  const RunResult decompress = RunNeuralmesh({"convert", laz, "-o", back});
  ASSERT_EQ(decompress.exit_code, 0) << decompress.Describe();
  EXPECT_TRUE(ReadFileContents(back).value_or("") == source);

  const std::string clean = *dir_ + "/clean.laz";
  const RunResult cleaned = RunNeuralmesh({"convert", laz, "-o", clean, "--remove_outliers"});
  ASSERT_EQ(cleaned.exit_code, 0) << cleaned.Describe();
  EXPECT_THAT(cleaned.out, ::testing::HasSubstr(" points, each record as in " + laz +
                                                " with every field"));
  EXPECT_THAT(cleaned.out, ::testing::HasSubstr(
                               " of 2999 removed); left out 1 point classified as noise\n"));
  const size_t kept = std::stoul(cleaned.out.substr(clean.size() + 2));
  EXPECT_GT(kept, 2900u);
  const absl::StatusOr<PointCloud> clean_points = ReadPointCloud(clean);
  ASSERT_TRUE(clean_points.ok()) << clean_points.status();
  EXPECT_EQ(clean_points->size(), kept);

  const std::string mesh = *dir_ + "/from_laz.ply";
  const RunResult run = RunNeuralmesh({"reconstruct", laz, "-o", mesh, "--vertices", "300"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_THAT(run.out, ::testing::HasSubstr("2999 points of " + laz));
  const absl::StatusOr<TriangleMesh> learned = ReadMesh(mesh);
  ASSERT_TRUE(learned.ok()) << learned.status();
  EXPECT_EQ(learned->positions.size(), 300u);
  for (const Vec3f& v : learned->positions) ASSERT_NEAR(v.norm(), 1.0f, 0.05f);

  // LAS 1.4's format 6 is copied whole; waveform records (format 9) are not written as LAZ,
  // so their points are.
  testing::LasLayout extended;
  extended.version_minor = 4;
  extended.format = 6;
  const std::string format6 = *dir_ + "/format6.las", format6_laz = *dir_ + "/format6.laz";
  std::ofstream(format6, std::ios::binary)
      << testing::LasFile(extended, {{0, 0, 100}, {0, 100, 0}, {100, 0, 0}});
  const RunResult copied = RunNeuralmesh({"convert", format6, "-o", format6_laz});
  ASSERT_EQ(copied.exit_code, 0) << copied.Describe();
  EXPECT_THAT(copied.out, ::testing::HasSubstr("3 records of " + format6 +
                                               ", every one and the header as they were"));
  extended.format = 9;
  const std::string format9 = *dir_ + "/format9.las", format9_laz = *dir_ + "/format9.laz";
  std::ofstream(format9, std::ios::binary)
      << testing::LasFile(extended, {{0, 0, 100}, {0, 100, 0}, {100, 0, 0}});
  const RunResult points_only = RunNeuralmesh({"convert", format9, "-o", format9_laz});
  ASSERT_EQ(points_only.exit_code, 0) << points_only.Describe();
  EXPECT_THAT(points_only.out,
              ::testing::HasSubstr("3 points; the records could not be kept whole: LAZ: writing "
                                   "point format 9 (waveform packets) is not supported"));
  for (const std::string& path : {format6_laz, format9_laz}) {
    const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->size(), 3u);
  }
}

TEST_F(LocalCliTest, LasClassesChooseWhichPointsAreLearnedAndConverted) {
  testing::LasLayout layout;
  layout.format = 1;
  for (double& s : layout.scale) s = 0.0001;
  std::vector<testing::LasPoint> points = UnitSphereLasPoints(3000, 6, layout);
  for (testing::LasPoint& p : points) p.classification = 6;
  Random rng(3);
  for (int i = 0; i < 3000; ++i) {
    testing::LasPoint ground{static_cast<int32_t>(std::lround((6 * rng.NextDouble() - 3) / 0.0001)),
                             static_cast<int32_t>(std::lround((6 * rng.NextDouble() - 3) / 0.0001)),
                             -30000};
    ground.classification = 2;
    points.push_back(ground);
  }
  const std::string las = *dir_ + "/classified_site.las";
  std::ofstream(las, std::ios::binary) << testing::LasFile(layout, points);

  const std::string mesh = *dir_ + "/building.ply";
  const RunResult run = RunNeuralmesh(
      {"reconstruct", las, "-o", mesh, "--vertices", "300", "--las_classes", "6"});
  ASSERT_EQ(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.out, "3000 points of " + las +
                                             " (uniform sampling; left out 3000 points of "
                                             "other classes)"))
      << run.out;
  const double centre[3] = {0, 0, 0};
  ExpectVerticesOnSphere(mesh, 300, centre, 1.0, 0.05);
  // Against the building's points, the mesh fits; against all of them, the ground is far off.
  const RunResult fits = RunNeuralmesh(
      {"eval", mesh, "--reference", las, "--las_classes", "6", "--json", "--samples", "20000"});
  ASSERT_EQ(fits.exit_code, 0) << fits.Describe();
  EXPECT_EQ(JsonValue(fits.out, "reference_points"), "3000") << fits.out;
  double completeness = 0, hausdorff = 0, diagonal = 0;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(fits.out, "completeness"), &completeness)) << fits.out;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(fits.out, "hausdorff"), &hausdorff)) << fits.out;
  ASSERT_TRUE(absl::SimpleAtod(JsonValue(fits.out, "diagonal"), &diagonal)) << fits.out;
  EXPECT_NEAR(diagonal, 2 * std::sqrt(3.0), 0.05);
  EXPECT_LT(completeness * diagonal, 0.03) << "the building's points lie on its mesh";
  EXPECT_LT(hausdorff * diagonal, 0.15);
  const RunResult off = RunNeuralmesh({"eval", mesh, "--reference", las, "--samples", "20000"});
  ASSERT_EQ(off.exit_code, 0) << off.Describe();
  EXPECT_TRUE(absl::StrContains(off.out, "against the 6000 points of " + las)) << off.out;
  EXPECT_FALSE(absl::StrContains(off.out, "normal_consistency")) << "points without normals";
  // The ground's half of the points lies 2 to 4 from the sphere.
  const std::smatch row = [&] {
    std::smatch m;
    std::regex_search(off.out, m,
                      std::regex("completeness +[0-9.e+-]+ +([0-9.e+-]+) +\\(points -> "
                                 "reconstruction\\)"));
    return m;
  }();
  ASSERT_FALSE(row.empty()) << off.out;
  EXPECT_GT(std::stod(row[1]), 1.0) << off.out;

  const std::string ground = *dir_ + "/ground.las";
  const RunResult convert =
      RunNeuralmesh({"convert", las, "-o", ground, "--las_classes", "2"});
  ASSERT_EQ(convert.exit_code, 0) << convert.Describe();
  EXPECT_TRUE(absl::StartsWith(convert.out, ground + ": 3000 points, each record as in "))
      << convert.out;
  const absl::StatusOr<PointCloud> read = ReadPointCloud(ground);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), 3000u);
  for (const Vec3f& p : read->positions) ASSERT_FLOAT_EQ(p[2], -3.0f);

  const RunResult not_las = RunNeuralmesh(
      {"convert", ground, "-o", *dir_ + "/ground.xyz", "--las_classes", "2"});
  ASSERT_EQ(not_las.exit_code, 0) << "a LAS input: " << not_las.Describe();
  const RunResult refused = RunNeuralmesh(
      {"reconstruct", *dir_ + "/ground.xyz", "-o", mesh, "--vertices", "100", "--las_classes",
       "2"});
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_TRUE(absl::StrContains(refused.err,
                                "--las_classes selects the points of LAS files by class; no "
                                "INPUT is a .las or .laz file"))
      << refused.Describe();
  const RunResult bad = RunNeuralmesh({"convert", las, "-o", ground, "--las_classes", "2,ground"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(absl::StrContains(
      bad.err, "--las_classes: LAS classes '2,ground': 'ground' is not a class from 0 to 255"))
      << bad.Describe();
}

TEST_F(LocalCliTest, AnInterruptWritesTheMeshLearnedSoFar) {
  const std::string path = *dir_ + "/interrupted.ply";
  BackgroundProcess run("neuralmesh",
                        {"reconstruct", "builtin:sphere", "-o", path, "--vertices", "1000000"});
  // Interrupt once learning has begun (the first line is printed before it starts).
  for (int i = 0; i < 200 && !absl::StrContains(run.Stdout(), "learning"); ++i) {
    usleep(20 * 1000);
  }
  usleep(300 * 1000);
  const int exit_code = run.SignalAndWait(SIGINT);
  EXPECT_EQ(exit_code, 1) << run.Stderr();
  EXPECT_TRUE(absl::StrContains(run.Stderr(), "interrupted")) << run.Stderr();
  EXPECT_TRUE(absl::StrContains(run.Stdout(), "interrupted: ")) << run.Stdout();
  EXPECT_TRUE(std::filesystem::exists(path)) << "the mesh learned so far was not written";
}

TEST(LocalCliHelpTest, HelpDocumentsEveryReconstructFlag) {
  const RunResult help = RunNeuralmesh({"reconstruct", "--help"});
  ASSERT_EQ(help.exit_code, 0) << help.Describe();
  for (const char* flag : {"--output",
                           "--vertices",
                           "--seed",
                           "--lod",
                           "--alpha_w",
                           "--alpha_l",
                           "--c_l",
                           "--c_vs",
                           "--c_ec",
                           "--early_phase_vertices",
                           "--early_c_vs",
                           "--early_c_ec",
                           "--alpha_sc",
                           "--alpha_r",
                           "--alpha_m",
                           "--remove_triangles",
                           "--merge_boundaries",
                           "--splits_per_step",
                           "--sampling",
                           "--initial_mesh",
                           "--start_mesh",
                           "--off_core",
                           "--remove_outliers",
                           "--outlier_neighbours",
                           "--outlier_std_ratio",
                           "--time_budget",
                           "--max_steps",
                           "--quantization_bits",
                           "--encode_speed",
                           "--progress",
                           "--server",
                           "--out-dir",
                           "--batch-size",
                           "--ply"}) {
    EXPECT_TRUE(absl::StrContains(help.out, std::string(flag) + "\n") ||
                absl::StrContains(help.out, std::string(flag) + ","))
        << flag << " is not documented:\n"
        << help.out;
  }
}

TEST(LocalCliHelpTest, NoArgumentsListsTheCommandsAndFails) {
  const RunResult run = RunNeuralmesh({});
  EXPECT_NE(run.exit_code, 0);
  for (const char* command : {"reconstruct", "stats", "eval", "watch", "sessions"}) {
    EXPECT_TRUE(absl::StrContains(run.err, command)) << command << " not listed:\n" << run.err;
  }
}

// "NAME 0.1.0 (Draco 1.5.5, OpenMesh 9.0.0, gRPC 1.51.1)", a line of its own.
bool IsVersionLine(const std::string& name, const std::string& text) {
  return std::regex_match(text, std::regex(name + " [0-9]+\\.[0-9]+\\.[0-9]+ \\(Draco [0-9.]+, "
                                                  "OpenMesh [0-9]+\\.[0-9]+\\.[0-9]+, gRPC "
                                                  "[0-9]+\\.[0-9]+\\.[0-9]+\\)\n"));
}

TEST(VersionTest, BothProgramsNameTheirVersionAndTheirLibraries) {
  for (const char* flag : {"--version", "version"}) {
    const RunResult cli = RunNeuralmesh({flag});
    EXPECT_EQ(cli.exit_code, 0) << cli.Describe();
    EXPECT_TRUE(IsVersionLine("neuralmesh", cli.out)) << cli.Describe();
  }
  const RunResult server = RunBinary("neuralmesh-server", {"--version"});
  EXPECT_EQ(server.exit_code, 0) << server.Describe();
  EXPECT_TRUE(IsVersionLine("neuralmesh-server", server.out)) << server.Describe();
}

}  // namespace
}  // namespace neuralmesh::testing
