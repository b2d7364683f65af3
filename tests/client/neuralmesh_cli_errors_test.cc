// The command line's answers to bad input: build/bin/neuralmesh must exit non-zero with a
// message on stderr that names the problem.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "gtest/gtest.h"
#include "tests/client/subprocess.h"

namespace neuralmesh::testing {
namespace {

class CliErrorsTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = MakeTempDir("cli_errors"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string WriteFile(const std::string& name, const std::string& contents) {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path, std::ios::binary) << contents;
    return path;
  }

  // Runs the command, expects failure, and returns stderr.
  std::string ExpectFailure(const std::vector<std::string>& args) {
    const RunResult run = RunNeuralmesh(args);
    EXPECT_NE(run.exit_code, 0) << "expected a failure:\n" << run.Describe();
    EXPECT_NE(run.exit_code, 127) << run.Describe();
    EXPECT_LT(run.exit_code, 128) << "killed by a signal:\n" << run.Describe();
    return run.err;
  }

  std::string Output() const { return dir_ + "/out.ply"; }

  std::string dir_;
};

TEST_F(CliErrorsTest, MissingInputFile) {
  const std::string missing = dir_ + "/nothing_here.ply";
  const std::string err =
      ExpectFailure({"reconstruct", missing, "-o", Output(), "--vertices", "100"});
  EXPECT_TRUE(absl::StrContains(err, missing) && absl::StrContains(err, "does not exist")) << err;
}

TEST_F(CliErrorsTest, EmptyInputFile) {
  const std::string empty = WriteFile("empty.xyz", "");
  const std::string err =
      ExpectFailure({"reconstruct", empty, "-o", Output(), "--vertices", "100"});
  EXPECT_TRUE(absl::StrContains(err, empty) && absl::StrContains(err, "empty")) << err;
}

TEST_F(CliErrorsTest, MalformedPlyNamesTheLine) {
  const std::string bad = WriteFile("bad.ply", "this is not a ply file\n");
  const std::string err = ExpectFailure({"reconstruct", bad, "-o", Output(), "--vertices", "100"});
  EXPECT_TRUE(absl::StrContains(err, bad)) << err;
  EXPECT_TRUE(absl::StrContains(err, "line 1")) << err;
}

TEST_F(CliErrorsTest, MalformedXyzNamesTheLine) {
  const std::string bad = WriteFile("bad.xyz", "0 0 0\n1 1 1\n1 banana 2\n");
  const std::string err = ExpectFailure({"reconstruct", bad, "-o", Output(), "--vertices", "100"});
  EXPECT_TRUE(absl::StrContains(err, bad)) << err;
  EXPECT_TRUE(absl::StrContains(err, "line 3")) << err;
}

TEST_F(CliErrorsTest, UnknownInputExtension) {
  const std::string odd = WriteFile("points.foo", "0 0 0\n");
  const std::string err = ExpectFailure({"reconstruct", odd, "-o", Output(), "--vertices", "100"});
  EXPECT_TRUE(absl::StrContains(err, ".foo")) << err;
}

TEST_F(CliErrorsTest, UnknownOutputExtension) {
  const std::string err = ExpectFailure(
      {"reconstruct", "builtin:sphere", "-o", dir_ + "/out.xyz", "--vertices", "100"});
  EXPECT_TRUE(absl::StrContains(err, "out.xyz") && absl::StrContains(err, ".ply")) << err;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/out.xyz"));
}

TEST_F(CliErrorsTest, LearnerParameterOutOfRange) {
  const std::string err = ExpectFailure(
      {"reconstruct", "builtin:sphere", "-o", Output(), "--vertices", "100", "--alpha_w", "2"});
  EXPECT_TRUE(absl::StrContains(err, "alpha_w")) << err;
  EXPECT_FALSE(std::filesystem::exists(Output())) << "nothing may be written";
  const std::string early =
      ExpectFailure({"reconstruct", "builtin:sphere", "-o", Output(), "--vertices", "100",
                     "--early_phase_vertices", "1000", "--early_c_ec", "0"});
  EXPECT_TRUE(absl::StrContains(early, "early_c_ec")) << early;
}

TEST_F(CliErrorsTest, NonNumericFlagValue) {
  const std::string err =
      ExpectFailure({"reconstruct", "builtin:sphere", "-o", Output(), "--vertices", "many"});
  EXPECT_TRUE(absl::StrContains(err, "--vertices") && absl::StrContains(err, "many")) << err;
}

TEST_F(CliErrorsTest, UnknownFlag) {
  const std::string err = ExpectFailure(
      {"reconstruct", "builtin:sphere", "-o", Output(), "--vertices", "100", "--alpha_z", "1"});
  EXPECT_TRUE(absl::StrContains(err, "unknown flag --alpha_z")) << err;
}

TEST_F(CliErrorsTest, FlagOfAnotherCommand) {
  const std::string err = ExpectFailure({"stats", Output(), "--vertices", "10"});
  EXPECT_TRUE(absl::StrContains(err, "--vertices") && absl::StrContains(err, "stats")) << err;
}

TEST_F(CliErrorsTest, MissingVertices) {
  const std::string err = ExpectFailure({"reconstruct", "builtin:sphere", "-o", Output()});
  EXPECT_TRUE(absl::StrContains(err, "--vertices")) << err;
}

TEST_F(CliErrorsTest, LodNotBelowVertices) {
  const std::string err = ExpectFailure(
      {"reconstruct", "builtin:sphere", "-o", Output(), "--vertices", "100", "--lod", "50,150"});
  EXPECT_TRUE(absl::StrContains(err, "--lod") && absl::StrContains(err, "150")) << err;
}

TEST_F(CliErrorsTest, UnknownBuiltin) {
  const std::string err =
      ExpectFailure({"reconstruct", "builtin:cube", "-o", Output(), "--vertices", "100"});
  EXPECT_TRUE(absl::StrContains(err, "builtin:cube") && absl::StrContains(err, "builtin:torus"))
      << err;
}

TEST_F(CliErrorsTest, UnknownSamplingMode) {
  const std::string err = ExpectFailure({"reconstruct", "builtin:sphere", "-o", Output(),
                                         "--vertices", "100", "--sampling", "gaussian"});
  EXPECT_TRUE(absl::StrContains(err, "gaussian")) << err;
}

TEST_F(CliErrorsTest, UnknownInitialMesh) {
  const std::string err = ExpectFailure({"reconstruct", "builtin:sphere", "-o", Output(),
                                         "--vertices", "100", "--initial_mesh", "cube"});
  EXPECT_TRUE(absl::StrContains(err, "'cube'") && absl::StrContains(err, "tetrahedron or disc"))
      << err;
}

TEST_F(CliErrorsTest, RemoveOutliersOfABuiltinSurfaceOrWithBadSettings) {
  std::string err = ExpectFailure(
      {"reconstruct", "builtin:sphere", "-o", Output(), "--vertices", "100", "--remove_outliers"});
  EXPECT_TRUE(absl::StrContains(err, "point cloud inputs")) << err;
  const std::string cloud = WriteFile("cloud.xyz", "0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
  err = ExpectFailure({"reconstruct", cloud, "-o", Output(), "--vertices", "100",
                       "--remove_outliers", "--outlier_neighbours", "0"});
  EXPECT_TRUE(absl::StrContains(err, "--outlier_neighbours is 0")) << err;
  err = ExpectFailure({"reconstruct", cloud, "-o", Output(), "--vertices", "100",
                       "--remove_outliers", "--outlier_std_ratio", "-1"});
  EXPECT_TRUE(absl::StrContains(err, "--outlier_std_ratio is -1")) << err;
  err = ExpectFailure({"reconstruct", cloud, "-o", Output(), "--vertices", "100",
                       "--remove_outliers", "--outliers_on_server"});
  EXPECT_TRUE(absl::StrContains(err, "--outliers_on_server needs --server")) << err;
  err = ExpectFailure({"reconstruct", cloud, "--server", "127.0.0.1:1", "--out-dir", Output(),
                       "--outliers_on_server"});
  EXPECT_TRUE(absl::StrContains(err, "--outliers_on_server needs --remove_outliers")) << err;
}

TEST_F(CliErrorsTest, MeshSamplingOfAPointCloud) {
  const std::string cloud = WriteFile("cloud.off", "OFF\n4 0 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
  const std::string err = ExpectFailure(
      {"reconstruct", cloud, "-o", Output(), "--vertices", "100", "--sampling", "area"});
  EXPECT_TRUE(absl::StrContains(err, "no faces")) << err;
}

TEST_F(CliErrorsTest, StatsOfAMissingFile) {
  const std::string err = ExpectFailure({"stats", dir_ + "/absent.off"});
  EXPECT_TRUE(absl::StrContains(err, "absent.off")) << err;
}

TEST_F(CliErrorsTest, EvalWithoutReference) {
  const std::string err = ExpectFailure({"eval", Output()});
  EXPECT_TRUE(absl::StrContains(err, "--reference")) << err;
}

TEST_F(CliErrorsTest, EvalAgainstAnEmptyReference) {
  const std::string mesh = WriteFile("tri.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const std::string empty = WriteFile("empty.obj", "");
  const std::string err = ExpectFailure({"eval", mesh, "--reference", empty});
  EXPECT_TRUE(absl::StrContains(err, empty) && absl::StrContains(err, "empty")) << err;
}

TEST_F(CliErrorsTest, EvalOfAFlatMeshNamesBothFiles) {
  const std::string mesh = WriteFile("tri.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const std::string line = WriteFile("line.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n");
  const std::string err = ExpectFailure({"eval", mesh, "--reference", line});
  EXPECT_TRUE(absl::StrContains(
      err, "MESH '" + mesh + "' against --reference '" + line + "': the reference has zero area"))
      << err;
}

TEST_F(CliErrorsTest, OutputThatIsADirectoryIsRefusedBeforeLearning) {
  const std::string dir = dir_ + "/taken.ply";
  std::filesystem::create_directory(dir);
  const RunResult run = RunNeuralmesh(
      {"reconstruct", "builtin:sphere", "-o", dir, "--vertices", "100000", "--time_budget", "60s"});
  EXPECT_NE(run.exit_code, 0) << run.Describe();
  EXPECT_TRUE(absl::StrContains(run.err, "OUTPUT '" + dir + "' is a directory")) << run.Describe();
  EXPECT_FALSE(absl::StrContains(run.out, "learning ")) << "refused before learning:\n"
                                                        << run.Describe();
}

TEST_F(CliErrorsTest, DracoFlagsOutOfRangeAreNamedByTheirFlags) {
  const std::string drc = dir_ + "/out.drc";
  std::string err = ExpectFailure({"reconstruct", "builtin:sphere", "-o", drc, "--vertices", "100",
                                   "--quantization_bits", "25"});
  EXPECT_TRUE(absl::StrContains(err, "--quantization_bits is 25; it must be in [1, 24]")) << err;
  err = ExpectFailure(
      {"reconstruct", "builtin:sphere", "-o", drc, "--vertices", "100", "--encode_speed", "11"});
  EXPECT_TRUE(absl::StrContains(err, "--encode_speed is 11; it must be in [0, 10]")) << err;
}

TEST_F(CliErrorsTest, NonPositiveTimeBudget) {
  for (const char* budget : {"0s", "-5s"}) {
    const std::string err = ExpectFailure({"reconstruct", "builtin:sphere", "-o", Output(),
                                           "--vertices", "100", "--time_budget", budget});
    EXPECT_TRUE(absl::StrContains(err, "--time_budget must be positive")) << err;
    EXPECT_FALSE(std::filesystem::exists(Output())) << "nothing learned, nothing written";
  }
}

TEST_F(CliErrorsTest, ReconnectWindowThatIsNegativeOrInfinite) {
  // Refused before any connection is tried (nothing listens on port 1).
  for (const char* window : {"-5s", "inf"}) {
    std::string err =
        ExpectFailure({"reconstruct", "builtin:sphere", "--server", "127.0.0.1:1", "--out-dir",
                       dir_, "--vertices", "100", "--reconnect_for", window});
    EXPECT_TRUE(absl::StrContains(err, "--reconnect_for must be a finite duration >= 0")) << err;
    err = ExpectFailure(
        {"watch", "s-0", "--server", "127.0.0.1:1", "--out-dir", dir_, "--reconnect_for", window});
    EXPECT_TRUE(absl::StrContains(err, "--reconnect_for must be a finite duration >= 0")) << err;
  }
  const std::string err = ExpectFailure({"reconstruct", "builtin:sphere", "-o", Output(),
                                         "--vertices", "100", "--reconnect_for", "10s"});
  EXPECT_TRUE(absl::StrContains(err, "--reconnect_for needs --server")) << err;
}

TEST_F(CliErrorsTest, EvalWithTooManySamples) {
  const std::string err = ExpectFailure(
      {"eval", "builtin:sphere", "--reference", "builtin:sphere", "--samples", "100000000000"});
  EXPECT_TRUE(absl::StrContains(err, "samples must be at most 20000000")) << err;
}

TEST_F(CliErrorsTest, UploadOfTooManyBuiltinPoints) {
  // Refused before any connection is tried (nothing listens on port 1).
  const std::string err =
      ExpectFailure({"reconstruct", "builtin:sphere", "--server", "127.0.0.1:1", "--out-dir", dir_,
                     "--vertices", "100", "--points", "100000000000"});
  EXPECT_TRUE(absl::StrContains(err, "--points must be at most 67108864")) << err;
}

TEST_F(CliErrorsTest, LearningThatStallsEndsWithTheMeshSoFar) {
  std::string same;
  for (int i = 0; i < 1000; ++i) same += "1 2 3\n";
  const std::string input = WriteFile("same.xyz", same);
  const std::string err =
      ExpectFailure({"reconstruct", input, "-o", Output(), "--vertices", "200"});
  EXPECT_TRUE(absl::StrContains(err, "learning stalled") &&
              absl::StrContains(err, "the mesh learned so far is in " + Output()))
      << err;
  EXPECT_TRUE(std::filesystem::exists(Output()));
}

TEST_F(CliErrorsTest, UnknownCommand) {
  const std::string err = ExpectFailure({"reconstrukt"});
  EXPECT_TRUE(absl::StrContains(err, "unknown command 'reconstrukt'")) << err;
}

TEST_F(CliErrorsTest, RemoteFlagWithoutServer) {
  const std::string err =
      ExpectFailure({"reconstruct", "builtin:sphere", "--out-dir", dir_, "--vertices", "100"});
  EXPECT_TRUE(absl::StrContains(err, "--server")) << err;
}

}  // namespace
}  // namespace neuralmesh::testing
