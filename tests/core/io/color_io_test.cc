// Per-point and per-vertex colours through every reader and writer that carries them: PLY,
// OBJ, OFF (COFF), XYZ and Draco, as neuralmesh writes them and as other tools do.
#include <string>
#include <vector>

#include "core/io/draco_codec.h"
#include "core/io/mesh_io.h"
#include "core/io/point_cloud_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using io_test::MatchPoints;
using io_test::QuantizationTolerance;
using io_test::TempPath;
using io_test::WriteBytes;
using testing::ColorOfPosition;
using ::testing::HasSubstr;

// Colours of `actual` against those of `expected`, matched by position within `tolerance`
// (Draco may reorder).
void ExpectSameColorsByPosition(const std::vector<Vec3f>& expected_positions,
                                const std::vector<Rgb>& expected_colors,
                                const std::vector<Vec3f>& actual_positions,
                                const std::vector<Rgb>& actual_colors, float tolerance) {
  ASSERT_EQ(actual_colors.size(), actual_positions.size()) << "colours lost or invented";
  const std::vector<int> match = MatchPoints(expected_positions, actual_positions, tolerance);
  int wrong = 0;
  for (size_t i = 0; i < match.size(); ++i) {
    ASSERT_GE(match[i], 0) << "point " << i << " has no counterpart";
    if (actual_colors[i] != expected_colors[match[i]] && ++wrong <= 3) {
      ADD_FAILURE() << "point " << i << " has colour " << int{actual_colors[i][0]} << " "
                    << int{actual_colors[i][1]} << " " << int{actual_colors[i][2]};
    }
  }
  EXPECT_EQ(wrong, 0);
}

TEST(ColorIoTest, MeshColorsSurviveEveryFormatButStl) {
  const TriangleMesh mesh = testing::ColoredIcosphere(2);
  for (const char* name : {"colored.ply", "colored.obj", "colored.off"}) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    ASSERT_TRUE(WriteMesh(mesh, path).ok());
    const absl::StatusOr<TriangleMesh> read = ReadMesh(path);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->colors, mesh.colors);
    EXPECT_EQ(read->positions, mesh.positions);
  }
  const std::string drc = TempPath("colored.drc");
  DracoOptions draco;
  ASSERT_TRUE(WriteMesh(mesh, drc, {draco}).ok());
  const absl::StatusOr<TriangleMesh> decoded = ReadMesh(drc);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  ExpectSameColorsByPosition(mesh.positions, mesh.colors, decoded->positions, decoded->colors,
                             QuantizationTolerance(2.0f, draco.position_quantization_bits));

  const std::string stl = TempPath("colored.stl");
  ASSERT_TRUE(WriteMesh(mesh, stl).ok());
  const absl::StatusOr<TriangleMesh> from_stl = ReadMesh(stl);
  ASSERT_TRUE(from_stl.ok()) << from_stl.status();
  EXPECT_TRUE(from_stl->colors.empty()) << "STL stores no colours";
}

TEST(ColorIoTest, PointColorsSurvivePlyXyzAndDraco) {
  const PointCloud cloud = testing::ColoredUnitSpherePoints(500, 3);
  for (const bool normals : {false, true}) {
    for (const bool weights : {false, true}) {
      // The header written names the columns, so every combination reads back.
      SCOPED_TRACE(::testing::Message() << "normals " << normals << ", weights " << weights);
      PointCloud written = cloud;
      if (normals) written.normals = written.positions;  // A unit sphere's.
      if (weights) written.weights.assign(written.size(), 0.5f);
      for (const char* name : {"colored_points.ply", "colored_points.xyz"}) {
        SCOPED_TRACE(name);
        ASSERT_TRUE(WritePointCloud(written, TempPath(name)).ok());
        const absl::StatusOr<PointCloud> read = ReadPointCloud(TempPath(name));
        ASSERT_TRUE(read.ok()) << read.status();
        EXPECT_EQ(read->positions, written.positions);
        EXPECT_EQ(read->colors, written.colors);
        EXPECT_EQ(read->normals, written.normals);
        EXPECT_EQ(read->weights, written.weights);
      }
    }
  }

  for (const int speed : {5, 10}) {  // The kd-tree coder, and the sequential one.
    SCOPED_TRACE(speed);
    DracoOptions draco;
    draco.position_quantization_bits = 16;
    draco.encode_speed = speed;
    const std::string drc = TempPath("colored_points.drc");
    ASSERT_TRUE(WritePointCloud(cloud, drc, {draco}).ok());
    const absl::StatusOr<PointCloud> decoded = ReadPointCloud(drc);
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    ExpectSameColorsByPosition(cloud.positions, cloud.colors, decoded->positions, decoded->colors,
                               QuantizationTolerance(2.0f, 16));
  }
}

// Other tools' ways of writing colours: 16-bit and float PLY channels, other property names,
// OBJ colours as fractions or as levels, COFF with alpha, as integers or as fractions.
TEST(ColorIoTest, ReadsColoursAsOtherToolsWriteThem) {
  struct Case {
    const char* name;
    std::string content;
  };
  const std::string ply_head =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\n";
  const std::vector<Case> cases = {
      {"ushort.ply", ply_head + "property ushort red\nproperty ushort green\nproperty ushort blue\n"
                                "end_header\n0 0 0 65535 0 32896\n1 0 0 257 514 771\n"},
      {"float.ply", ply_head + "property float r\nproperty float g\nproperty float b\nend_header\n"
                               "0 0 0 1 0 0.50196\n1 0 0 0.00392 0.00784 0.01176\n"},
      {"diffuse.ply", ply_head + "property uchar diffuse_red\nproperty uchar diffuse_green\n"
                                 "property uchar diffuse_blue\nproperty uchar alpha\nend_header\n"
                                 "0 0 0 255 0 128 9\n1 0 0 1 2 3 9\n"},
      {"fractions.obj", "v 0 0 0 1 0 0.50196\nv 1 0 0 0.00392 0.00784 0.01176\n"},
      {"levels.obj", "v 0 0 0 255 0 128\nv 1 0 0 1 2 3\n"},
      {"integers.off", "COFF\n2 0 0\n0 0 0 255 0 128 255\n1 0 0 1 2 3 255\n"},
      {"fractions.off", "COFF\n2 0 0\n0 0 0 1.0 0.0 0.50196 1.0\n1 0 0 0.00392 0.00784 0.01176\n"},
  };
  const std::vector<Rgb> expected = {{255, 0, 128}, {1, 2, 3}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = TempPath(c.name);
    WriteBytes(path, c.content);
    const absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
    ASSERT_TRUE(cloud.ok()) << cloud.status();
    EXPECT_EQ(cloud->colors, expected);
  }
}

// Colours for some vertices only, or fewer than three channels, are no colours: the file's
// positions are read as without them.
TEST(ColorIoTest, ColoursOfSomeVerticesOrChannelsAreLeftOut) {
  const std::vector<std::pair<const char*, std::string>> cases = {
      {"some.obj", "v 0 0 0 1 0 0\nv 1 0 0\n"},
      {"some.off", "COFF\n2 0 0\n0 0 0 255 0 0 255\n1 0 0\n"},
      {"two_channels.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nproperty uchar red\nproperty uchar green\nend_header\n0 0 0 1 2\n"},
  };
  for (const auto& [name, content] : cases) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    WriteBytes(path, content);
    const absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
    ASSERT_TRUE(cloud.ok()) << cloud.status();
    EXPECT_TRUE(cloud->colors.empty());
    EXPECT_FALSE(cloud->positions.empty());
  }
}

TEST(ColorIoTest, MalformedColoursAreRejectedWithTheirLine) {
  const std::vector<std::tuple<const char*, std::string, std::string>> cases = {
      {"bad.obj", "v 0 0 0 1 0 0\nv 1 0 0 red 0 0\n",
       "line 2: expected a finite number for the red"},
      {"bad.off", "COFF\n1 0 0\n0 0 0 255 zero 0 255\n", "line 3: expected a colour channel"},
      {"bad.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
       "end_header\n0 0 0 1 2 300\n",
       "expected an integer in [0, 255] for property 'blue'"},
  };
  for (const auto& [name, content, message] : cases) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    WriteBytes(path, content);
    const absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
    ASSERT_FALSE(cloud.ok());
    EXPECT_EQ(cloud.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(cloud.status().message()), HasSubstr(message));
  }
}

TEST(ColorIoTest, ColoursThatAreNotOnePerPointAreRefused) {
  TriangleMesh mesh = testing::ColoredIcosphere(2);
  mesh.colors.pop_back();
  for (const char* name : {"short.ply", "short.drc"}) {
    const absl::Status written = WriteMesh(mesh, TempPath(name));
    EXPECT_EQ(written.code(), absl::StatusCode::kInvalidArgument) << name;
    EXPECT_THAT(std::string(written.message()), HasSubstr("colours for 162 vertices")) << name;
  }
  PointCloud cloud = testing::ColoredUnitSpherePoints(10, 1);
  cloud.colors.resize(3);
  const absl::Status valid = ValidatePointCloud(cloud);
  EXPECT_EQ(valid.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(valid.message()), HasSubstr("3 colours for 10 points"));
}

}  // namespace
}  // namespace neuralmesh
