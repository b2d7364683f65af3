// Georeferenced coordinates (UTM eastings of 500,000 m, northings of 4,100,000 m) through the
// readers and writers: read relative to an origin that keeps a float's resolution
// (core/io/internal/position_collector.h), written back in the data's own coordinates.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/io/internal/position_collector.h"
#include "core/io/mesh_io.h"
#include "core/io/point_cloud_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"

namespace neuralmesh {
namespace {

using io_internal::OriginKeepingResolution;
using io_internal::Point3d;
using io_test::ReadBytes;
using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr Point3d kNoOrigin = {0, 0, 0};

// A tetrahedron of about 40 m in UTM coordinates, with millimetres.
const std::vector<Point3d> kSurveyed = {{500123.456, 4100234.567, 101.234},
                                        {500163.457, 4100234.568, 102.5},
                                        {500143.001, 4100270.999, 99.75},
                                        {500140.25, 4100250.125, 140.875}};
const std::vector<std::array<uint32_t, 3>> kFaces = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};

// kSurveyed relative to (500000, 4100000, 0), as a tetrahedron.
TriangleMesh SurveyedMesh() {
  TriangleMesh mesh;
  for (const Point3d& p : kSurveyed) {
    mesh.positions.emplace_back(static_cast<float>(p[0] - 500000),
                                static_cast<float>(p[1] - 4100000), static_cast<float>(p[2]));
  }
  mesh.faces = kFaces;
  mesh.origin = {500000, 4100000, 0};
  return mesh;
}

// Where each point lies, with its origin put back.
std::vector<Point3d> Placed(const std::vector<Vec3f>& positions, const Point3d& origin) {
  std::vector<Point3d> placed;
  for (const Vec3f& p : positions) {
    placed.push_back({origin[0] + p[0], origin[1] + p[1], origin[2] + p[2]});
  }
  return placed;
}

void ExpectNear(const std::vector<Point3d>& actual, const std::vector<Point3d>& expected,
                double tolerance) {
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t i = 0; i < actual.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(actual[i][c], expected[i][c], tolerance) << "point " << i << " axis " << c;
    }
  }
}

TEST(GeoreferencedIoTest, AnOriginIsTakenOnlyWhereAFloatWouldLoseTheResolution) {
  // UTM at millimetres: easting and northing move to multiples of 1,000 below the points;
  // heights of about 100 m keep their float.
  EXPECT_EQ(OriginKeepingResolution({500123.4, 4100234.5, 99.7}, {500163.5, 4100271.0, 140.9},
                                    {0.001, 0.001, 0.001}),
            (Point3d{500000, 4100000, 0}));
  // Coarser data keep a float farther out: 2^22 steps of 10 cm reach 419 km.
  EXPECT_EQ(OriginKeepingResolution({400000, 0, 0}, {400100, 1, 1}, {0.1, 0.1, 0.1}),
            kNoOrigin);
  // Below zero the minimum rounds down too; points on both sides of 0 stay where they are.
  EXPECT_EQ(OriginKeepingResolution({-500500, -9000, -1}, {-500400, 9000, 1}, {0.001, 1e-9, 0}),
            (Point3d{-501000, 0, 0}));
  // Points within 1,000 of a multiple of 1,000 but far from zero: the origin brings them near.
  EXPECT_EQ(OriginKeepingResolution({7e6, 7e6, 7e6}, {7e6 + 0.5, 7e6 + 0.5, 7e6 + 0.5},
                                    {1e-4, 1e-4, 1e-4}),
            (Point3d{7e6, 7e6, 7e6}));
  // Beyond 2^40 no coordinate is georeferenced (a 64-bit integer field of a PCD file can hold
  // 1e18): doubles there keep no more than floats would, relative to any origin.
  EXPECT_EQ(OriginKeepingResolution({1e12, 1e12, 2e12}, {1e12 + 1, 1e12 + 1, 2e12 + 1},
                                    {1e-4, 1e-4, 1e-4}),
            (Point3d{1e12, 1e12, 0}));
}

TEST(GeoreferencedIoTest, TextPointCloudsAreReadRelativeToAnOriginWithTheirMillimetres) {
  const std::string xyz =
      "500123.456 4100234.567 101.234\n500163.457 4100234.568 102.5\n"
      "500143.001 4100270.999 99.75\n500140.25 4100250.125 140.875\n";
  const std::string path = TempPath("survey.xyz");
  WriteBytes(path, xyz);
  const absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(cloud->origin, (Point3d{500000, 4100000, 0}));
  EXPECT_FLOAT_EQ(cloud->positions[0][0], 123.456f);
  EXPECT_FLOAT_EQ(cloud->positions[0][1], 234.567f);
  ExpectNear(Placed(cloud->positions, cloud->origin), kSurveyed, 1e-4);

  // One surveyed point (or many that a float cannot tell apart) keeps its millimetres too.
  WriteBytes(path, "500123.456 4100234.567 101.234\n");
  const absl::StatusOr<PointCloud> one = ReadPointCloud(path);
  ASSERT_TRUE(one.ok()) << one.status();
  EXPECT_EQ(one->origin, (Point3d{500000, 4100000, 0}));
  EXPECT_EQ(one->positions[0], Vec3f(123.456f, 234.567f, 101.234f));
}

TEST(GeoreferencedIoTest, MeshFilesAreReadRelativeToAnOrigin) {
  const std::string obj =
      "v 500123.456 4100234.567 101.234\nv 500163.457 4100234.568 102.5\n"
      "v 500143.001 4100270.999 99.75\nv 500140.25 4100250.125 140.875\n"
      "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
  const std::string off =
      "OFF\n4 4 0\n500123.456 4100234.567 101.234\n500163.457 4100234.568 102.5\n"
      "500143.001 4100270.999 99.75\n500140.25 4100250.125 140.875\n"
      "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
      "property double z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
      "500123.456 4100234.567 101.234\n500163.457 4100234.568 102.5\n"
      "500143.001 4100270.999 99.75\n500140.25 4100250.125 140.875\n"
      "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"survey.obj", obj},
                                   {"survey.off", off},
                                   {"survey.ply", ply}}) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    WriteBytes(path, text);
    const absl::StatusOr<TriangleMesh> mesh = ReadMesh(path);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    EXPECT_EQ(mesh->origin, (Point3d{500000, 4100000, 0}));
    ExpectNear(Placed(mesh->positions, mesh->origin), kSurveyed, 1e-4);
    EXPECT_EQ(mesh->faces, kFaces);
  }
}

TEST(GeoreferencedIoTest, MeshesAreWrittenInTheirDataCoordinatesAndReadBackExactly) {
  TriangleMesh mesh = SurveyedMesh();
  mesh.colors = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {9, 9, 9}};
  for (const std::string name : {"out.ply", "out.obj", "out.off", "out.glb", "out.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    ASSERT_TRUE(WriteMesh(mesh, path).ok());
    const absl::StatusOr<TriangleMesh> read = ReadMesh(path);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->origin, mesh.origin);
    EXPECT_EQ(read->positions, mesh.positions);
    EXPECT_EQ(read->faces, mesh.faces);
    EXPECT_EQ(read->colors, mesh.colors);
  }
  // The text formats hold the coordinates themselves, in as few digits as the floats need.
  EXPECT_THAT(ReadBytes(TempPath("out.obj")), HasSubstr("v 500123.456 4100234.567 101.234 "));
  EXPECT_THAT(ReadBytes(TempPath("out.ply")), HasSubstr("property double x\n"));
  // glTF places the mesh with its node's translation.
  EXPECT_THAT(ReadBytes(TempPath("out.gltf")), HasSubstr("\"translation\":[5e+05,4100000,0]"));
  // Draco keeps the origin as metadata beside its quantized positions.
  const std::string drc = TempPath("out.drc");
  ASSERT_TRUE(WriteMesh(mesh, drc).ok());
  const absl::StatusOr<TriangleMesh> decoded = ReadMesh(drc);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_EQ(decoded->origin, mesh.origin);
  EXPECT_THAT(io_test::MatchPoints(mesh.positions, decoded->positions, 0.01f),
              Not(::testing::Contains(-1)));
  // STL holds only floats: its coordinates stay relative to the origin.
  const std::string stl = TempPath("out.stl");
  ASSERT_TRUE(WriteMesh(mesh, stl).ok());
  const absl::StatusOr<TriangleMesh> triangles = ReadMesh(stl);
  ASSERT_TRUE(triangles.ok()) << triangles.status();
  EXPECT_EQ(triangles->origin, kNoOrigin);
  EXPECT_FLOAT_EQ(triangles->positions[0][0], mesh.positions[0][0]);
}

TEST(GeoreferencedIoTest, PointCloudsAreWrittenInTheirDataCoordinatesAndReadBackExactly) {
  PointCloud cloud;
  cloud.positions = SurveyedMesh().positions;
  cloud.normals.assign(cloud.size(), Vec3f(0.0f, 0.0f, 1.0f));
  cloud.origin = {500000, 4100000, 0};
  for (const std::string name : {"out.ply", "out.xyz", "out.glb"}) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    ASSERT_TRUE(WritePointCloud(cloud, path).ok());
    const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->origin, cloud.origin);
    EXPECT_EQ(read->positions, cloud.positions);
  }
  const std::string drc = TempPath("out.drc");
  ASSERT_TRUE(WritePointCloud(cloud, drc).ok());
  const absl::StatusOr<PointCloud> decoded = ReadPointCloud(drc);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_EQ(decoded->origin, cloud.origin);
  EXPECT_THAT(io_test::MatchPoints(cloud.positions, decoded->positions, 0.01f),
              Not(::testing::Contains(-1)));
}

// Text near 0 is kept as floats while it is read (PositionPrecision::kFloatsNearZero), which
// are the positions when the origin comes out 0; a site whose box lies far from 0 for its size
// is read again with doubles, so its decimals keep what the doubles relative to the origin give.
TEST(GeoreferencedIoTest, ASiteNearZeroButFarForItsSizeKeepsItsDecimals) {
  const std::vector<Point3d> site = {
      {3000.123, 1000.456, 10.789}, {3000.987, 1000.001, 10.5}, {3000.5, 1000.75, 11.125}};
  const Point3d origin = {3000, 1000, 0};
  std::vector<Vec3f> expected;
  for (const Point3d& p : site) {
    expected.emplace_back(static_cast<float>(p[0] - origin[0]),
                          static_cast<float>(p[1] - origin[1]), static_cast<float>(p[2]));
  }
  // What floats of the text would have given: other positions.
  ASSERT_NE(static_cast<float>(static_cast<double>(static_cast<float>(site[0][0])) - origin[0]),
            expected[0][0]);
  const std::string xyz =
      "3000.123 1000.456 10.789\n3000.987 1000.001 10.5\n3000.5 1000.75 11.125\n";
  const std::string path = TempPath("site.xyz");
  WriteBytes(path, xyz);
  const absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(cloud->origin, origin);
  EXPECT_EQ(cloud->positions, expected);
  const std::string obj = TempPath("site.obj");
  WriteBytes(obj,
             "v 3000.123 1000.456 10.789\nv 3000.987 1000.001 10.5\nv 3000.5 1000.75 11.125\n"
             "f 1 2 3\n");
  const absl::StatusOr<TriangleMesh> mesh = ReadMesh(obj);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->origin, origin);
  EXPECT_EQ(mesh->positions, expected);

  // Near 0 for their size, the same decimals are the floats of their text.
  WriteBytes(path, "3.123 1.456 10.789\n3.987 1.001 10.5\n3.5 1.75 11.125\n");
  const absl::StatusOr<PointCloud> near = ReadPointCloud(path);
  ASSERT_TRUE(near.ok()) << near.status();
  EXPECT_EQ(near->origin, kNoOrigin);
  EXPECT_EQ(near->positions[0], Vec3f(3.123f, 1.456f, 10.789f));
}

TEST(GeoreferencedIoTest, DataNearZeroKeepTheirFloatsAndFormats) {
  // Coordinates within 64 bounding-box sides of zero have no origin, and the writers write
  // what they always did: float PLY properties, a glTF node without translation.
  TriangleMesh mesh;
  mesh.positions = {{1000, 2000, 0}, {1100, 2000, 0}, {1000, 2100, 0}, {1000, 2000, 100}};
  mesh.faces = kFaces;
  const std::string ply = TempPath("near.ply");
  ASSERT_TRUE(WriteMesh(mesh, ply).ok());
  EXPECT_THAT(ReadBytes(ply), HasSubstr("property float x\n"));
  const std::string glb = TempPath("near.glb");
  ASSERT_TRUE(WriteMesh(mesh, glb).ok());
  EXPECT_THAT(ReadBytes(glb), Not(HasSubstr("translation")));
  for (const std::string& path : {ply, glb}) {
    const absl::StatusOr<TriangleMesh> read = ReadMesh(path);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->origin, kNoOrigin);
    EXPECT_EQ(read->positions, mesh.positions);
  }
  // A metre-sized object 5 km out is farther than 64 sides: it moves.
  const std::string far = TempPath("far.xyz");
  WriteBytes(far, "5000 0 0\n5001 1 0\n5000 1 1\n");
  const absl::StatusOr<PointCloud> cloud = ReadPointCloud(far);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(cloud->origin, (Point3d{5000, 0, 0}));
}

}  // namespace
}  // namespace neuralmesh
