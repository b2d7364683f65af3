// LAS point clouds (core/io/internal/las.h) through ReadPointCloud: every point format, with
// and without colours, LAS 1.2 and 1.4 headers, georeferenced coordinates moved to an origin,
// and malformed files refused with what is wrong (LAZ: laz_test.cc).
#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/point_cloud_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/las_file.h"

namespace neuralmesh {
namespace {

using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;
using testing::kLasRgbOffset;
using testing::LasFile;
using testing::LasLayout;
using testing::LasPoint;

absl::StatusOr<PointCloud> ReadLas(const std::string& name, const std::string& bytes) {
  const std::string path = TempPath(name);
  WriteBytes(path, bytes);
  return ReadPointCloud(path);
}

const std::vector<LasPoint> kPoints = {
    {0, 0, 0, 65535, 0, 32896}, {100, -250, 7, 257, 514, 771}, {-12345, 678, -9, 0, 65535, 0}};

TEST(LasIoTest, ReadsThePositionsAndColoursOfEveryPointFormat) {
  const std::vector<Rgb> colors = {{255, 0, 128}, {1, 2, 3}, {0, 255, 0}};
  for (int format = 0; format <= 10; ++format) {
    SCOPED_TRACE(::testing::Message() << "format " << format);
    LasLayout layout;
    layout.version_minor = format <= 5 ? 2 : 4;
    layout.format = format;
    layout.offset[0] = 10;
    layout.offset[2] = -3;
    const absl::StatusOr<PointCloud> cloud = ReadLas("format.las", LasFile(layout, kPoints));
    ASSERT_TRUE(cloud.ok()) << cloud.status();
    ASSERT_EQ(cloud->size(), 3u);
    for (size_t i = 0; i < kPoints.size(); ++i) {
      EXPECT_FLOAT_EQ(cloud->positions[i][0], kPoints[i].x * 0.01 + 10);
      EXPECT_FLOAT_EQ(cloud->positions[i][1], kPoints[i].y * 0.01);
      EXPECT_FLOAT_EQ(cloud->positions[i][2], kPoints[i].z * 0.01 - 3);
    }
    EXPECT_EQ(cloud->colors, kLasRgbOffset[format] != 0 ? colors : std::vector<Rgb>{});
    EXPECT_EQ(cloud->origin, (std::array<double, 3>{0, 0, 0}));
  }
  // Records longer than their format (extra bytes) are read by the header's length; 8-bit
  // colours stored in 16-bit channels (no channel above 255) are taken as they are.
  LasLayout padded;
  padded.format = 2;
  padded.record_length = 31;
  const std::vector<LasPoint> dim = {{1, 2, 3, 255, 0, 128}, {4, 5, 6, 1, 2, 3}};
  const absl::StatusOr<PointCloud> cloud = ReadLas("padded.las", LasFile(padded, dim));
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_FLOAT_EQ(cloud->positions[1][2], 0.06f);
  EXPECT_EQ(cloud->colors, (std::vector<Rgb>{{255, 0, 128}, {1, 2, 3}}));
}

// Classes asked for (PointSelection): only their points are read, noise classes among them
// when asked for; the others are counted apart from noise; withheld points stay out.
TEST(LasIoTest, OnlyThePointsOfTheClassesAskedForAreRead) {
  for (const int format : {1, 6}) {
    SCOPED_TRACE(::testing::Message() << "format " << format);
    LasLayout layout;
    layout.version_minor = format >= 6 ? 4 : 2;
    layout.format = format;
    std::vector<LasPoint> points;
    for (int c : {2, 6, 7, 2, 18, 6, 5, 2}) {
      LasPoint p{100 * c, static_cast<int32_t>(points.size()), 0};
      p.classification = static_cast<uint8_t>(c);
      points.push_back(p);
    }
    points[3].withheld = true;
    const std::string path = TempPath(absl::StrCat("classes", format, ".las"));
    WriteBytes(path, LasFile(layout, points));

    PointSelection ground_and_low_noise;
    ground_and_low_noise.las_classes = LasClasses().set(2).set(7);
    PointsLeftOut left_out;
    absl::StatusOr<PointCloud> cloud = ReadPointCloud(path, &left_out, ground_and_low_noise);
    ASSERT_TRUE(cloud.ok()) << cloud.status();
    ASSERT_EQ(cloud->size(), 3u);  // Points 0, 2 and 7.
    EXPECT_FLOAT_EQ(cloud->positions[0][1], 0.0f);
    EXPECT_FLOAT_EQ(cloud->positions[1][0], 7.0f) << "low noise, asked for";
    EXPECT_FLOAT_EQ(cloud->positions[2][1], 0.07f);
    EXPECT_EQ(left_out.withheld, 1u);
    EXPECT_EQ(left_out.other_class, 4u);
    EXPECT_EQ(left_out.noise, 0u) << "with classes asked for, noise is a class like another";

    PointSelection all;
    all.las_classes = LasClasses().set();
    cloud = ReadPointCloud(path, &left_out, all);
    ASSERT_TRUE(cloud.ok()) << cloud.status();
    EXPECT_EQ(cloud->size(), 7u) << "every point but the withheld one";

    PointSelection water;
    water.las_classes = LasClasses().set(9);
    cloud = ReadPointCloud(path, &left_out, water);
    EXPECT_EQ(cloud.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(cloud.status().message()),
                HasSubstr("all 8 points are withheld (1) or of classes not asked for (7)"));
  }
}

// Withheld points (to be treated as deleted) and those classified as noise (class 7, low
// point; 18, high noise) are left out and counted, in both record families; they do not move
// the origin. A file of nothing else says so.
TEST(LasIoTest, WithheldAndNoisePointsAreLeftOutAndCounted) {
  for (const int format : {1, 6}) {
    SCOPED_TRACE(::testing::Message() << "format " << format);
    LasLayout layout;
    layout.version_minor = format >= 6 ? 4 : 2;
    layout.format = format;
    for (double& s : layout.scale) s = 0.001;
    layout.offset[0] = 500000;
    std::vector<LasPoint> points = {{1000, 2000, 3000}, {1500, 2500, 3500}, {1, 2, 3},
                                    {-400000000, 0, 0}, {7, 8, 9},          {4, 5, 6}};
    points[0].classification = 2;  // Ground: kept.
    points[1].classification = 6;  // Building: kept.
    points[2].classification = 7;
    points[3].classification = 18;  // 100 km away: it would have moved the origin.
    points[4].withheld = true;
    points[4].classification = 2;
    points[5].classification = 31;  // Unassigned user classes are kept.
    PointsLeftOut left_out;
    const std::string path = TempPath(absl::StrCat("classes", format, ".las"));
    WriteBytes(path, LasFile(layout, points));
    const absl::StatusOr<PointCloud> cloud = ReadPointCloud(path, &left_out);
    ASSERT_TRUE(cloud.ok()) << cloud.status();
    EXPECT_EQ(left_out.noise, 2u);
    EXPECT_EQ(left_out.withheld, 1u);
    ASSERT_EQ(cloud->size(), 3u);
    EXPECT_EQ(cloud->origin, (std::array<double, 3>{500000, 0, 0}));
    EXPECT_FLOAT_EQ(cloud->positions[0][0], 1.0f);
    EXPECT_FLOAT_EQ(cloud->positions[1][1], 2.5f);
    EXPECT_FLOAT_EQ(cloud->positions[2][2], 0.006f);

    for (LasPoint& p : points) p.classification = 7;
    const absl::StatusOr<PointCloud> none = ReadLas("noise.las", LasFile(layout, points));
    EXPECT_EQ(none.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(none.status().message()),
                HasSubstr("all 6 points are withheld (1) or classified as noise (5)"));
  }
}

// UTM coordinates at millimetre resolution: a float holds 500,000 m to about 3 cm (and
// 4,100,000 m to 25 cm), so x and y are taken relative to the origin (the minimum rounded down
// to 1,000 m) and keep their millimetres; z, near 0, stays as it is.
TEST(LasIoTest, GeoreferencedCoordinatesKeepTheirResolutionRelativeToAnOrigin) {
  LasLayout layout;
  layout.version_minor = 4;
  layout.format = 6;
  for (double& s : layout.scale) s = 0.001;
  layout.offset[0] = 500000;
  layout.offset[1] = 4100000;
  const std::vector<LasPoint> points = {
      {-1234567, 2345678, 12345}, {1, -1, 1}, {2, -1, 1}, {1000001, 999, -5000}};
  const absl::StatusOr<PointCloud> cloud = ReadLas("utm.las", LasFile(layout, points));
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(cloud->origin, (std::array<double, 3>{498000, 4099000, 0}));
  for (size_t i = 0; i < points.size(); ++i) {
    const double x = points[i].x * 0.001 + 500000, y = points[i].y * 0.001 + 4100000;
    EXPECT_NEAR(cloud->positions[i][0] + 498000.0, x, 2e-4) << i;
    EXPECT_NEAR(cloud->positions[i][1] + 4099000.0, y, 2e-4) << i;
    EXPECT_FLOAT_EQ(cloud->positions[i][2], points[i].z * 0.001);
  }
  // A millimetre apart stays a millimetre apart, to a float's spacing 2 km from the origin.
  EXPECT_NEAR(cloud->positions[2][0] - cloud->positions[1][0], 0.001, 2.5e-4);

  // A scan near 0 at a resolution finer than a float keeps at 50 m: an origin 1,000 m off would
  // only take it farther, so there is none.
  LasLayout fine;
  for (double& s : fine.scale) s = 1e-5;
  const absl::StatusOr<PointCloud> near_zero =
      ReadLas("fine.las", LasFile(fine, {{-5000000, 0, 0}, {5000000, 1, 2}}));
  ASSERT_TRUE(near_zero.ok()) << near_zero.status();
  EXPECT_EQ(near_zero->origin, (std::array<double, 3>{0, 0, 0}));
  EXPECT_FLOAT_EQ(near_zero->positions[0][0], -50.0f);
}

// A LAS file is read where it lies (mapped); one that cannot be mapped, a named pipe fed by
// another program, is read as it comes, to the same points.
TEST(LasIoTest, ANamedPipeIsReadLikeAFile) {
  const std::string bytes = LasFile(LasLayout{}, kPoints);
  absl::StatusOr<PointCloud> from_file = ReadLas("mapped.las", bytes);
  ASSERT_TRUE(from_file.ok()) << from_file.status();
  const std::string fifo = TempPath("piped.las");
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] {
    std::ofstream(fifo, std::ios::binary) << bytes;  // Opening waits for the reader.
  });
  absl::StatusOr<PointCloud> from_pipe = ReadPointCloud(fifo);
  writer.join();
  ASSERT_TRUE(from_pipe.ok()) << from_pipe.status();
  EXPECT_EQ(from_pipe->positions, from_file->positions);
  EXPECT_EQ(from_pipe->origin, from_file->origin);
}

TEST(LasIoTest, MalformedFilesAreRefusedWithWhatIsWrong) {
  LasLayout layout;
  layout.format = 3;
  const std::string good = LasFile(layout, kPoints);
  struct Case {
    const char* what;
    std::string bytes;
    const char* message;
  };
  std::string laz = good;
  laz[104] = static_cast<char>(3 | 0x80);
  std::string format11 = good;
  format11[104] = 11;
  std::string short_records = good;
  short_records[105] = 20;
  short_records[106] = 0;
  std::string too_many = good;
  too_many[107] = 4;
  std::string zero_scale = good;
  std::fill(zero_scale.begin() + 131, zero_scale.begin() + 139, '\0');
  std::string version = good;
  version[24] = 2;
  const Case cases[] = {
      {"not LAS", "ply\nformat ascii 1.0\n", "LAS: no LASF signature"},
      {"truncated header", good.substr(0, 100), "the file ends within its header (100 bytes)"},
      {"truncated points", good.substr(0, good.size() - 1),
       "3 points of 34 bytes from byte 227 do not fit in the file's 328 bytes"},
      {"LAZ bits without LASzip's record", laz, "LAZ: no LASzip record"},
      {"format 11", format11, "point data format 11 is not 0 to 10"},
      {"short records", short_records, "records of 20 bytes are shorter than format 3's 34"},
      {"too many points", too_many, "4 points of 34 bytes"},
      {"zero scale", zero_scale, "the scale and offset of axis x"},
      {"version 2", version, "version 2.2 is not 1.0 to 1.4"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const absl::StatusOr<PointCloud> cloud = ReadLas("bad.las", c.bytes);
    ASSERT_FALSE(cloud.ok());
    EXPECT_EQ(cloud.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(cloud.status().message()), HasSubstr(c.message));
    EXPECT_THAT(std::string(cloud.status().message()), HasSubstr("bad.las"));
  }
  EXPECT_TRUE(IsReadablePointCloudExtension("scan.LAS"));
}

using io_test::Field;

TEST(LasIoTest, WrittenFilesKeepColoursAndGeoreferencedCoordinates) {
  PointCloud cloud;
  cloud.origin = {500000, 4100000, 0};
  cloud.positions = {Vec3f(956.034f, 234.567f, 101.234f), Vec3f(0.001f, 999.999f, 0),
                     Vec3f(1500.25f, 12.5f, -3.75f)};
  cloud.colors = {{255, 0, 128}, {1, 2, 3}, {0, 0, 0}};
  cloud.normals = {Vec3f(0, 0, 1), Vec3f(0, 0, 1), Vec3f(0, 0, 1)};
  cloud.weights = {1, 2, 3};
  const std::string path = TempPath("written.las");
  ASSERT_TRUE(WritePointCloud(cloud, path).ok());
  const std::string bytes = io_test::ReadBytes(path);

  // The header, field by field (LAS 1.2, Table 4).
  ASSERT_EQ(bytes.size(), 227u + 3 * 26);
  EXPECT_EQ(bytes.substr(0, 4), "LASF");
  EXPECT_EQ(bytes[24], 1);
  EXPECT_EQ(bytes[25], 2);
  EXPECT_EQ(Field<uint16_t>(bytes, 94), 227) << "header size";
  EXPECT_EQ(Field<uint32_t>(bytes, 96), 227u) << "offset to the points";
  EXPECT_EQ(Field<uint32_t>(bytes, 100), 0u) << "variable-length records";
  EXPECT_EQ(bytes[104], 2) << "point format 2: with colours";
  EXPECT_EQ(Field<uint16_t>(bytes, 105), 26);
  EXPECT_EQ(Field<uint32_t>(bytes, 107), 3u);
  EXPECT_EQ(Field<uint32_t>(bytes, 111), 3u) << "every point a first return";
  // Scales: the power of ten at most 1/2^24 of each axis's farthest coordinate.
  EXPECT_EQ(Field<double>(bytes, 131), 1e-5);
  EXPECT_EQ(Field<double>(bytes, 139), 1e-5);
  EXPECT_EQ(Field<double>(bytes, 147), 1e-6);
  EXPECT_EQ(Field<double>(bytes, 155), 500000.0) << "the offset is the origin";
  EXPECT_EQ(Field<double>(bytes, 163), 4100000.0);
  EXPECT_EQ(Field<double>(bytes, 171), 0.0);
  EXPECT_NEAR(Field<double>(bytes, 179), 501500.25, 1e-5) << "max x";
  EXPECT_NEAR(Field<double>(bytes, 187), 500000.001, 1e-5) << "min x";
  EXPECT_NEAR(Field<double>(bytes, 211), 101.234, 1e-5) << "max z";
  EXPECT_NEAR(Field<double>(bytes, 219), -3.75, 1e-5) << "min z";
  // The first record: coordinates, return 1 of 1, class 0, colour levels times 257.
  EXPECT_NEAR(Field<int32_t>(bytes, 227) * 1e-5, cloud.positions[0][0], 1e-5);
  EXPECT_NEAR(Field<int32_t>(bytes, 235) * 1e-6, cloud.positions[0][2], 1e-6);
  EXPECT_EQ(bytes[227 + 14], 9);
  EXPECT_EQ(bytes[227 + 15], 0);
  EXPECT_EQ(Field<uint16_t>(bytes, 227 + 20), 65535);
  EXPECT_EQ(Field<uint16_t>(bytes, 227 + 22), 0);
  EXPECT_EQ(Field<uint16_t>(bytes, 227 + 24), 128 * 257);

  const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->origin, cloud.origin);
  ASSERT_EQ(read->size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(read->positions[i][c], cloud.positions[i][c], c < 2 ? 5e-6 : 5e-7) << i;
    }
  }
  EXPECT_EQ(read->positions[0], cloud.positions[0]) << "floats that the scale resolves";
  EXPECT_EQ(read->colors, cloud.colors);
  EXPECT_TRUE(read->normals.empty());
  EXPECT_TRUE(read->weights.empty());

  // Without colours: format 0; near zero, no offset; the same points give the same bytes.
  PointCloud plain;
  plain.positions = {Vec3f(-1, 0.5f, 0), Vec3f(0.25f, -0.125f, 0)};
  ASSERT_TRUE(WritePointCloud(plain, path).ok());
  const std::string plain_bytes = io_test::ReadBytes(path);
  EXPECT_EQ(plain_bytes[104], 0);
  EXPECT_EQ(Field<uint16_t>(plain_bytes, 105), 20);
  EXPECT_EQ(Field<double>(plain_bytes, 131), 1e-8);
  EXPECT_EQ(Field<double>(plain_bytes, 147), 0.001) << "an axis that is zero everywhere";
  EXPECT_EQ(Field<double>(plain_bytes, 155), 0.0);
  const absl::StatusOr<PointCloud> plain_read = ReadPointCloud(path);
  ASSERT_TRUE(plain_read.ok()) << plain_read.status();
  EXPECT_EQ(plain_read->positions, plain.positions);
  EXPECT_TRUE(plain_read->colors.empty());
  ASSERT_TRUE(WritePointCloud(plain, path).ok());
  EXPECT_EQ(io_test::ReadBytes(path), plain_bytes);
}

}  // namespace
}  // namespace neuralmesh
