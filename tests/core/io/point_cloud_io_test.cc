#include "core/io/point_cloud_io.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "core/io/mesh_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using io_test::ExpectSameCloud;
using io_test::Put;
using io_test::ReadBytes;
using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;


absl::StatusOr<PointCloud> ReadContent(const std::string& name, const std::string& content) {
  const std::string path = TempPath(name);
  WriteBytes(path, content);
  return ReadPointCloud(path);
}

void ExpectRejected(const std::string& name, const std::string& content,
                    const std::string& substring, const std::string& what) {
  const absl::StatusOr<PointCloud> cloud = ReadContent(name, content);
  ASSERT_FALSE(cloud.ok()) << what << ": the malformed file was accepted";
  EXPECT_EQ(cloud.status().code(), absl::StatusCode::kInvalidArgument)
      << what << ": wrong status code: " << cloud.status();
  EXPECT_THAT(std::string(cloud.status().message()), HasSubstr(substring))
      << what << ": the message does not explain the problem";
  EXPECT_THAT(std::string(cloud.status().message()), HasSubstr(name))
      << what << ": the message does not name the file";
}

void ExpectCloud(const PointCloud& expected, const absl::StatusOr<PointCloud>& actual,
                 const std::string& what) {
  ASSERT_TRUE(actual.ok()) << what << ": " << actual.status();
  EXPECT_EQ(actual->positions, expected.positions) << what << ": positions differ";
  EXPECT_EQ(actual->normals, expected.normals) << what << ": normals differ";
  EXPECT_EQ(actual->weights, expected.weights) << what << ": weights differ";
}

PointCloud MakeCloud(std::vector<Vec3f> positions, std::vector<Vec3f> normals = {},
                     std::vector<float> weights = {}) {
  PointCloud cloud;
  cloud.positions = std::move(positions);
  cloud.normals = std::move(normals);
  cloud.weights = std::move(weights);
  return cloud;
}

const PointCloud kThree = MakeCloud({Vec3f(0, 0, 0), Vec3f(1, 2, 3), Vec3f(-1.5f, 0.25f, 8)});
const std::vector<Vec3f> kThreeNormals = {Vec3f(0, 0, 1), Vec3f(0, 1, 0), Vec3f(1, 0, 0)};

// ---------------------------------------------------------------------------------------------
// Round trips: every writable format, with and without normals and weights.

class CloudRoundTripTest : public ::testing::TestWithParam<std::tuple<const char*, bool, bool>> {};

TEST_P(CloudRoundTripTest, WriteThenReadGivesTheSameCloud) {
  const auto [extension, normals, weights] = GetParam();
  const PointCloud cloud = io_test::RandomCloud(500, 42, normals, weights);
  const std::string path = TempPath(std::string("cloud") + extension);
  const absl::Status written = WritePointCloud(cloud, path);
  ASSERT_TRUE(written.ok()) << "writing " << extension << ": " << written;
  const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
  ASSERT_TRUE(read.ok()) << "reading back " << extension << ": " << read.status();
  const bool e57 = std::string(extension) == ".e57";
  if (std::string(extension) == ".las" || e57) {
    // Integers in steps of 1e-8 (internal/las.h, internal/e57.h); no weights, and in LAS no
    // normals.
    ASSERT_EQ(read->size(), cloud.size());
    for (size_t i = 0; i < cloud.size(); ++i) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(read->positions[i][c], cloud.positions[i][c], 1e-8);
    }
    EXPECT_EQ(read->normals, e57 ? cloud.normals : std::vector<Vec3f>{});
    EXPECT_TRUE(read->weights.empty());
  } else if (std::string(extension) == ".ptx") {  // Exact text; no normals or weights.
    EXPECT_EQ(read->positions, cloud.positions);
    EXPECT_TRUE(read->normals.empty());
    EXPECT_TRUE(read->weights.empty());
  } else if (std::string(extension) == ".drc") {
    ExpectSameCloud(cloud, *read,
                    io_test::QuantizationTolerance(io_test::BoundingCubeRange(cloud.positions), 11),
                    0.01f, 1.5f / 65535 + 1e-5f, "Draco round trip");
  } else {
    ExpectCloud(cloud, read, std::string("round trip through ") + extension);
  }
}

INSTANTIATE_TEST_SUITE_P(AllWritableFormats, CloudRoundTripTest,
                         ::testing::Combine(::testing::Values(".ply", ".xyz", ".txt", ".pts",
                                                              ".ptx", ".las", ".pcd", ".e57",
                                                              ".drc", ".glb", ".gltf"),
                                            ::testing::Bool(), ::testing::Bool()),
                         [](const auto& info) {
                           return std::string(std::get<0>(info.param) + 1) +
                                  (std::get<1>(info.param) ? "_normals" : "") +
                                  (std::get<2>(info.param) ? "_weights" : "");
                         });

TEST(PointCloudIoTest, ExtensionHelpers) {
  for (const char* name :
       {"a.ply", "b.XYZ", "c.txt", "d.Pts", "e.obj", "f.off", "g.drc", "h.ptx", "i.pcd",
        "j.E57"}) {
    EXPECT_TRUE(IsReadablePointCloudExtension(name)) << name << " should be readable";
  }
  for (const char* name : {"a.stl", "b.xyzw", "noextension"}) {
    EXPECT_FALSE(IsReadablePointCloudExtension(name)) << name << " should not be readable";
  }
  for (const char* name :
       {"a.ply", "b.xyz", "c.txt", "d.pts", "g.DRC", "h.las", "i.glb", "j.PCD", "k.e57",
        "l.Ptx"}) {
    EXPECT_TRUE(IsWritablePointCloudExtension(name)) << name << " should be writable";
  }
  for (const char* name : {"e.obj", "f.off", "a.stl"}) {
    EXPECT_FALSE(IsWritablePointCloudExtension(name)) << name << " should not be writable";
  }
  const WrittenPointAttributes ply = PointAttributesWrittenTo("a.ply");
  EXPECT_TRUE(ply.normals && ply.weights && ply.colors);
  const WrittenPointAttributes las = PointAttributesWrittenTo("b.LAS");
  EXPECT_TRUE(!las.normals && !las.weights && las.colors);
  const WrittenPointAttributes e57 = PointAttributesWrittenTo("c.e57");
  EXPECT_TRUE(e57.normals && !e57.weights && e57.colors);
  const WrittenPointAttributes ptx = PointAttributesWrittenTo("d.ptx");
  EXPECT_TRUE(!ptx.normals && !ptx.weights && ptx.colors);
}

// ---------------------------------------------------------------------------------------------
// PLY

TEST(PlyCloudTest, AsciiWithNormalsAndConfidence) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
      "property uchar red\nproperty float confidence\nend_header\n"
      "0 0 0 0 0 1 255 0.5\n1 2 3 0 1 0 0 1\n-1.5 0.25 8 1 0 0 7 2\n";
  ExpectCloud(MakeCloud(kThree.positions, kThreeNormals, {0.5f, 1, 2}),
              ReadContent("confidence.ply", ply), "ASCII PLY with normals and confidence");
}

TEST(PlyCloudTest, EveryWeightPropertyNameIsRecognised) {
  for (const char* name : {"confidence", "weight", "quality", "Intensity", "scalar"}) {
    const std::string ply = std::string(
                                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                "property float y\nproperty float z\nproperty float ") +
                            name + "\nend_header\n0 0 0 1\n1 2 3 2\n-1.5 0.25 8 3\n";
    ExpectCloud(MakeCloud(kThree.positions, {}, {1, 2, 3}), ReadContent("named.ply", ply),
                std::string("weights named ") + name);
  }
}

TEST(PlyCloudTest, ConfidenceWinsOverIntensityAndPartialNormalsAreIgnored) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty float intensity\nproperty float nx\nproperty float ny\n"
      "property float confidence\nend_header\n"
      "0 0 0 9 1 1 1\n1 2 3 9 1 1 2\n-1.5 0.25 8 9 1 1 3\n";
  ExpectCloud(MakeCloud(kThree.positions, {}, {1, 2, 3}), ReadContent("priority.ply", ply),
              "confidence preferred, nx/ny without nz ignored");
}

TEST(PlyCloudTest, BinaryBigEndianMeshWithBrokenFacesReadsItsVertices) {
  // Faces are skipped, not validated: the index 77 is out of range but harmless here.
  std::string ply =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n"
      "property double y\nproperty double z\nproperty uchar intensity\nelement face 2\n"
      "property list uchar int vertex_indices\nend_header\n";
  const uint8_t intensities[3] = {10, 20, 30};
  for (int i = 0; i < 3; ++i) {
    for (int c = 0; c < 3; ++c) Put<double>(kThree.positions[i][c], true, &ply);
    Put(intensities[i], true, &ply);
  }
  Put<uint8_t>(3, true, &ply);
  for (int32_t v : {0, 1, 77}) Put(v, true, &ply);
  Put<uint8_t>(4, true, &ply);
  for (int32_t v : {0, 1, 2, 0}) Put(v, true, &ply);
  ExpectCloud(MakeCloud(kThree.positions, {}, {10, 20, 30}), ReadContent("mesh.ply", ply),
              "vertices of a binary big-endian mesh");
}

TEST(PlyCloudTest, MalformedFilesAreRejectedWithAReason) {
  std::string bogus_count =
      "ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  bogus_count.append(16, '\0');
  std::string truncated =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n";
  for (int i = 0; i < 3; ++i) {
    for (int c = 0; c < 3; ++c) Put<float>(kThree.positions[i][c], false, &truncated);
  }
  Put<uint8_t>(3, false, &truncated);
  Put<int32_t>(0, false, &truncated);  // Two indices missing.
  const struct {
    const char* what;
    std::string content;
    const char* message;
  } cases[] = {
      {"vertex count beyond the data", bogus_count, "declares 999999999999 'vertex' elements"},
      {"truncated inside a skipped face", truncated, "the file is truncated"},
      {"letters for a weight",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nproperty float quality\nend_header\n0 0 0 high\n",
       "line 9: expected a number for property 'quality' of vertex 0, found 'high'"},
      {"NaN normal",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
       "end_header\n0 0 0 nan 0 1\n",
       "vertex 0 has a non-finite normal"},
      {"negative weight",
       "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
       "property float z\nproperty float weight\nend_header\n0 0 0 1\n1 1 1 -2\n",
       "weight 1 is -2"},
      {"all weights zero",
       "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
       "property float z\nproperty float weight\nend_header\n0 0 0 0\n1 1 1 0\n",
       "all weights are zero"},
      {"no points",
       "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n",
       "contains no points"},
  };
  for (const auto& c : cases) ExpectRejected("malformed.ply", c.content, c.message, c.what);
}

// ---------------------------------------------------------------------------------------------
// XYZ / TXT / PTS

TEST(XyzCloudTest, ColumnLayoutsCommentsAndCountLine) {
  ExpectCloud(kThree, ReadContent("plain.xyz", "0 0 0\n1 2 3\n-1.5 0.25 8"),
              "three columns, no final newline");
  ExpectCloud(kThree,
              ReadContent("commented.txt",
                          "# exported by a scanner\n\n0 0 0   # origin\r\n\t1\t2\t3\n\n"
                          "-1.5 0.25 8\n# end\n"),
              "comments, blank lines, tabs and CRLF");
  ExpectCloud(kThree, ReadContent("counted.pts", "3\n0 0 0\n1 2 3\n-1.5 0.25 8\n"),
              "a leading point count");
  ExpectCloud(MakeCloud(kThree.positions, {}, {1, 0.5f, 2}),
              ReadContent("weights.xyz", "0 0 0 1\n1 2 3 0.5\n-1.5 0.25 8 2\n"),
              "four columns: weights");
  ExpectCloud(MakeCloud(kThree.positions, kThreeNormals),
              ReadContent("normals.xyz", "0 0 0 0 0 1\n1 2 3 0 1 0\n-1.5 0.25 8 1 0 0\n"),
              "six columns: normals");
  ExpectCloud(MakeCloud(kThree.positions, kThreeNormals, {3, 2, 1}),
              ReadContent("both.xyz", "0 0 0 0 0 1 3\n1 2 3 0 1 0 2\n-1.5 0.25 8 1 0 0 1\n"),
              "seven columns: normals and weights");
}

// Colours as scanners and tools write them: "x y z r g b" (levels or fractions), Leica PTS and
// Semantic3D's "x y z intensity r g b", normals and colours in either order, and columns a
// header names (CloudCompare's "//X,Y,Z,..." with commas too).
TEST(XyzCloudTest, ColoursAsScannersAndToolsWriteThem) {
  const std::vector<Rgb> colors = {{255, 0, 128}, {1, 2, 3}, {10, 20, 30}};
  const std::vector<Rgb> from_fractions = {{255, 0, 128}, {1, 2, 3}, {0, 128, 255}};
  struct Case {
    const char* name;
    std::string content;
    std::vector<Vec3f> normals;
    std::vector<float> weights;
    std::vector<Rgb> colors;
  };
  const Case cases[] = {
      {"levels.xyz", "0 0 0 255 0 128\n1 2 3 1 2 3\n-1.5 0.25 8 10 20 30\n", {}, {}, colors},
      {"fractions.txt",
       "0 0 0 1 0 0.50196\n1 2 3 0.00392 0.00784 0.01176\n-1.5 0.25 8 0 0.50196 1\n",
       {},
       {},
       from_fractions},
      {"leica.pts",
       "3\n0 0 0 -1024 255 0 128\n1 2 3 2047 1 2 3\n-1.5 0.25 8 0 10 20 30\n",
       {},
       {},
       colors},
      {"normals_then_colors.xyz",
       "0 0 0 0 0 1 255 0 128\n1 2 3 0 1 0 1 2 3\n-1.5 0.25 8 1 0 0 10 20 30\n",
       kThreeNormals,
       {},
       colors},
      {"colors_then_normals.xyz",
       "0 0 0 255 0 128 0 0 1\n1 2 3 1 2 3 0 1 0\n-1.5 0.25 8 10 20 30 1 0 0\n",
       kThreeNormals,
       {},
       colors},
      {"cloudcompare.txt",
       "//X,Y,Z,R,G,B\n0,0,0,255,0,128\n1,2,3,1,2,3\n-1.5,0.25,8,10,20,30\n",
       {},
       {},
       colors},
      {"named.xyz",
       "# scanner export\n# x y z intensity Nx Ny Nz red green blue scalar confidence\n"
       "0 0 0 7 0 0 1 255 0 128 -4 3\n1 2 3 7 0 1 0 1 2 3 -4 2\n"
       "-1.5 0.25 8 7 1 0 0 10 20 30 -4 1\n",
       kThreeNormals,
       {3, 2, 1},
       colors},
      {"two_channels_named.xyz", "# x y z r g w\n0 0 0 1 1 3\n1 2 3 1 1 2\n-1.5 0.25 8 1 1 1\n",
       {},
       {3, 2, 1},
       {}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const absl::StatusOr<PointCloud> cloud = ReadContent(c.name, c.content);
    ExpectCloud(MakeCloud(kThree.positions, c.normals, c.weights), cloud, c.name);
    if (cloud.ok()) {
      EXPECT_EQ(cloud->colors, c.colors);
    }
  }
  // Three columns that are unit vectors in every row are normals, even when they could be
  // colours.
  const absl::StatusOr<PointCloud> unit =
      ReadContent("unit.xyz", "0 0 0 0 0 1\n1 2 3 0 1 0\n-1.5 0.25 8 1 0 0\n");
  ExpectCloud(MakeCloud(kThree.positions, kThreeNormals), unit, "unit vectors");
}

// Normals that are not unit vectors and lie in [0, 1], like colours as fractions: the header
// written with them says what they are.
TEST(XyzCloudTest, WrittenNormalsThatCouldBeColoursReadBackAsNormals) {
  const PointCloud cloud = MakeCloud(kThree.positions, {Vec3f(0.25f, 0.5f, 0), Vec3f(0, 0, 0.5f),
                                                        Vec3f(0.125f, 0.125f, 0.125f)});
  const std::string path = TempPath("short_normals.xyz");
  ASSERT_TRUE(WritePointCloud(cloud, path).ok());
  ExpectCloud(cloud, ReadPointCloud(path), "written with a header");
  const absl::StatusOr<PointCloud> headless =
      ReadContent("headless.xyz", "0 0 0 0.25 0.5 0\n1 2 3 0 0 0.5\n-1.5 0.25 8 0.125 0.125 0.125");
  ASSERT_TRUE(headless.ok()) << headless.status();
  EXPECT_TRUE(headless->normals.empty()) << "without a header they read as colours";
  EXPECT_EQ(headless->colors.size(), 3u);
}

// The largest float prints as "3.4028235e+38", which as a double lies beyond it: read back, it
// is the largest float again, not infinity (and the point is not dropped). Subnormals and -0
// come back too. Found by pcd_format_fuzzer writing ASCII PCD.
TEST(XyzCloudTest, TextGivesBackTheExtremeFloats) {
  constexpr float kMax = std::numeric_limits<float>::max();
  constexpr float kTiny = std::numeric_limits<float>::denorm_min();
  PointCloud cloud;
  cloud.positions = {Vec3f(kMax, 1, 2), Vec3f(-kMax, 0, -0.0f), Vec3f(kTiny, -kTiny, 5)};
  for (const char* name : {"extremes.xyz", "extremes.pcd"}) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    PointCloudWriteOptions options;
    options.pcd = PcdData::kAscii;
    ASSERT_TRUE(WritePointCloud(cloud, path, options).ok());
    EXPECT_THAT(ReadBytes(path), HasSubstr("3.4028235e+38"));
    const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
    ASSERT_TRUE(read.ok()) << read.status();
    ASSERT_EQ(read->size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(std::signbit(read->positions[i][c]), std::signbit(cloud.positions[i][c]));
        EXPECT_EQ(read->positions[i][c], cloud.positions[i][c]) << i << " " << c;
      }
    }
  }
}

TEST(XyzCloudTest, MalformedFilesAreRejectedWithAReason) {
  std::string seventy_columns = "0 0 0";
  for (int k = 3; k < 70; ++k) seventy_columns += " 1";
  const struct {
    const char* what;
    std::string content;
    const char* message;
  } cases[] = {
      {"letters", "0 0 0\n1 two 3\n", "line 2: expected a number in column 2, found 'two'"},
      {"five columns", "0 0 0 1 1\n", "line 1: expected 3, 4, 6, 7 or 9 numbers"},
      {"eight columns after another file's header", "# x y z r g b\n0 0 0 1 1 1 1 1\n",
       "line 2: expected 3, 4, 6, 7 or 9 numbers"},
      {"two columns", "# header\n0 0\n", "line 2: expected x y z and at most 61 more"},
      {"nine columns of neither normals nor colours",
       "0 0 0 0 0 1 0 0 300\n0 0 0 0 0 1 0 0 1\n",
       "line 1: 9 columns are x y z, a normal and a colour"},
      {"seventy columns", seventy_columns, "line 1: expected x y z and at most 61 more numbers, "
                                            "found 70 values"},
      {"ragged columns", "0 0 0\n1 2 3\n1 2 3 0 0 1\n", "line 3: expected 3 numbers like line 1"},
      {"NaN", "0 0 0\nnan 1 1\n", "line 2: column 1 is not finite"},
      {"infinity", "0 0 0\n1 -inf 1\n", "line 2: column 2 is not finite"},
      {"overflowing float", "0 0 0\n1 1 1e40\n", "line 2: column 3 is not finite"},
      {"only comments", "# nothing\n", "contains no points"},
      {"count line only", "12\n", "contains no points"},
  };
  for (const auto& c : cases) ExpectRejected("malformed.xyz", c.content, c.message, c.what);
}

// ---------------------------------------------------------------------------------------------
// OBJ, OFF and Draco as point clouds

TEST(ObjCloudTest, ReadsVertexLinesOnly) {
  const std::string obj =
      "# normals belong to face corners in OBJ, so they are not point normals\n"
      "v 0 0 0\nvn 0 0 1\nv 1 2 3\nvt 0.5 0.5\nv -1.5 0.25 8 1.0\n"
      "f 1/1/1 2/1/1 3/1/1\nf 1 2 99 and garbage\n";
  ExpectCloud(kThree, ReadContent("points.obj", obj), "OBJ vertices (faces skipped)");
  ExpectRejected("bad.obj", "v 0 0 0\nv 1 2\n", "line 2: expected 'v x y z'", "short v line");
}

TEST(OffCloudTest, ReadsVerticesAndNoffNormals) {
  ExpectCloud(kThree,
              ReadContent("points.off",
                          "OFF\n3 1 0\n0 0 0\n1 2 3\n-1.5 0.25 8\n"
                          "3 0 1 99\n"),
              "OFF vertices (faces skipped)");
  ExpectCloud(
      MakeCloud(kThree.positions, kThreeNormals),
      ReadContent("normals.off", "NOFF\n3 0 0\n0 0 0 0 0 1\n1 2 3 0 1 0\n-1.5 0.25 8 1 0 0\n"),
      "NOFF normals");
  ExpectCloud(kThree,
              ReadContent("colors.off",
                          "COFF 3 0 0\n0 0 0 1 0 0 1\n1 2 3 0 1 0 1\n"
                          "-1.5 0.25 8 0 0 1 1\n"),
              "COFF colors ignored");
  ExpectRejected("short.off", "OFF\n3 0 0\n0 0 0\n1 1 1\n",
                 "the file ends after 2 of the 3 vertices", "too few vertices");
}

TEST(DracoCloudTest, ReadsDracoMeshesAsPoints) {
  const TriangleMesh mesh = testing::Icosphere(1);
  const std::string path = TempPath("mesh_as_cloud.drc");
  ASSERT_TRUE(WriteMesh(mesh, path).ok());
  const absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  ExpectSameCloud(MakeCloud(mesh.positions), *cloud, io_test::QuantizationTolerance(2.0f, 11), 0, 0,
                  "mesh vertices from .drc");
  ExpectRejected("corrupt.drc", "DRACO garbage", "Draco", "corrupt Draco file");
}

// ---------------------------------------------------------------------------------------------
// Errors

TEST(PointCloudIoTest, MissingFileUnsupportedExtensionAndEmptyFile) {
  const absl::StatusOr<PointCloud> missing = ReadPointCloud(TempPath("missing/cloud.ply"));
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound) << missing.status();
  EXPECT_THAT(std::string(missing.status().message()), HasSubstr("cannot open"))
      << "the message should say the file cannot be opened";

  const absl::StatusOr<PointCloud> stl = ReadPointCloud(TempPath("part.stl"));
  EXPECT_EQ(stl.status().code(), absl::StatusCode::kInvalidArgument) << stl.status();
  EXPECT_THAT(std::string(stl.status().message()),
              HasSubstr(".ply, .xyz, .txt, .pts, .ptx, .las, .laz, .pcd, .e57, .obj, .off, .drc, .glb, "
                        ".gltf"))
      << "the message should list the readable extensions";

  const absl::Status obj = WritePointCloud(kThree, TempPath("cloud.obj"));
  EXPECT_EQ(obj.code(), absl::StatusCode::kInvalidArgument) << obj;
  EXPECT_THAT(std::string(obj.message()),
              HasSubstr(".ply, .xyz, .txt, .pts, .ptx, .las, .laz, .pcd, .e57, .drc, .glb, .gltf"))
      << "the message should list the writable extensions";

  for (const char* name : {"empty.ply", "empty.xyz", "empty.obj", "empty.off", "empty.drc"}) {
    ExpectRejected(name, "", "is empty", name);
  }
}

TEST(PointCloudIoTest, WriteRejectsInvalidCloudsAndReportsIoFailures) {
  PointCloud mismatched = kThree;
  mismatched.normals = {Vec3f(0, 0, 1)};
  PointCloud nan_point = kThree;
  nan_point.positions[1][0] = NAN;
  PointCloud negative = kThree;
  negative.weights = {1, -1, 1};
  const PointCloud empty;
  const struct {
    const char* what;
    const PointCloud& cloud;
    const char* name;
    const char* message;
  } cases[] = {
      {"empty cloud", empty, "empty.ply", "the point cloud is empty"},
      {"normals count", mismatched, "mismatched.xyz", "1 normals for 3 points"},
      {"NaN point", nan_point, "nan.drc", "point 1 has a non-finite coordinate"},
      {"negative weight", negative, "negative.ply", "weight 1 is -1"},
  };
  for (const auto& c : cases) {
    const absl::Status status = WritePointCloud(c.cloud, TempPath(c.name));
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << c.what << ": " << status;
    EXPECT_THAT(std::string(status.message()), HasSubstr(c.message)) << c.what;
  }
  const absl::Status missing_dir = WritePointCloud(kThree, TempPath("nowhere/cloud.ply"));
  EXPECT_EQ(missing_dir.code(), absl::StatusCode::kNotFound) << missing_dir;
  EXPECT_THAT(std::string(missing_dir.message()), HasSubstr("cannot write")) << missing_dir;
  DracoOptions bad;
  bad.position_quantization_bits = 0;
  const absl::Status bad_options = WritePointCloud(kThree, TempPath("bad.drc"), {bad});
  EXPECT_EQ(bad_options.code(), absl::StatusCode::kInvalidArgument) << bad_options;
  EXPECT_THAT(std::string(bad_options.message()), HasSubstr("position_quantization_bits"))
      << "the message should name the bad option";
}

TEST(PointCloudIoTest, TruncatedFilesFailCleanly) {
  const PointCloud cloud = io_test::RandomCloud(40, 5, true, true);
  for (const char* extension : {".ply", ".xyz", ".drc"}) {
    const std::string path = TempPath(std::string("whole_cloud") + extension);
    ASSERT_TRUE(WritePointCloud(cloud, path).ok());
    const std::string bytes = io_test::ReadBytes(path);
    for (size_t length = 0; length < bytes.size(); length += 3) {
      const absl::StatusOr<PointCloud> read =
          ReadContent(std::string("cloud_prefix") + extension, bytes.substr(0, length));
      if (!read.ok()) {
        ASSERT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument)
            << extension << " cut to " << length << " bytes: " << read.status();
      }
    }
  }
}

}  // namespace
}  // namespace neuralmesh
