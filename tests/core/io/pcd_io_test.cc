// PCL's PCD point clouds (core/io/internal/pcd.h) through ReadPointCloud and WritePointCloud:
// what neuralmesh writes read back, files as PCL and Open3D write them (ascii with packed
// colours, binary with doubles, descriptors and padding, LZF-compressed columns), organized
// clouds with empty pixels, and malformed files refused with what is wrong.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/io/point_cloud_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"

namespace neuralmesh {
namespace {

using io_test::Put;
using io_test::ReadBytes;
using io_test::ReadCloudFrom;
using io_test::TempPath;
using ::testing::HasSubstr;

// LZF as liblzf decodes it, from literal runs and back references to the byte before (runs of
// one repeated byte), so that both kinds of instruction and long references are exercised.
std::string Lzf(const std::string& data) {
  std::string out, literal;
  const auto flush = [&] {
    for (size_t at = 0; at < literal.size(); at += 32) {
      const size_t n = std::min<size_t>(32, literal.size() - at);
      out.push_back(static_cast<char>(n - 1));
      out += literal.substr(at, n);
    }
    literal.clear();
  };
  size_t i = 0;
  while (i < data.size()) {
    size_t run = 0;  // Bytes after data[i - 1] equal to it.
    while (i > 0 && i + run < data.size() && data[i + run] == data[i - 1] && run < 264) ++run;
    if (run >= 3) {
      flush();
      const size_t length = run - 2;  // Distance 1: the low byte is distance - 1 = 0.
      if (length < 7) {
        out.push_back(static_cast<char>(length << 5));
      } else {
        out.push_back(static_cast<char>(7 << 5));
        out.push_back(static_cast<char>(length - 7));
      }
      out.push_back('\0');
      i += run;
    } else {
      literal.push_back(data[i++]);
    }
  }
  flush();
  return out;
}

uint32_t Packed(const Rgb& c) { return uint32_t{c[0]} << 16 | uint32_t{c[1]} << 8 | c[2]; }

TEST(PcdIoTest, WrittenCloudsComeBackWithNormalsColoursAndWeights) {
  PointCloud cloud = io_test::RandomCloud(200, 3, /*normals=*/true, /*weights=*/true);
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud.colors.push_back({static_cast<uint8_t>(i), 255, static_cast<uint8_t>(3 * i)});
  }
  const std::string path = TempPath("cloud.pcd");
  ASSERT_TRUE(WritePointCloud(cloud, path).ok());
  const std::string bytes = ReadBytes(path);
  const std::string header =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
      "FIELDS x y z normal_x normal_y normal_z rgb confidence\nSIZE 4 4 4 4 4 4 4 4\n"
      "TYPE F F F F F F F F\nCOUNT 1 1 1 1 1 1 1 1\nWIDTH 200\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 200\nDATA binary\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 200 * 32);
  uint32_t first_rgb;
  std::memcpy(&first_rgb, bytes.data() + header.size() + 24, 4);
  EXPECT_EQ(first_rgb, 0x00FF00u) << "PCL's packed 0x00RRGGBB";

  const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->positions, cloud.positions);
  EXPECT_EQ(read->normals, cloud.normals);
  EXPECT_EQ(read->weights, cloud.weights);
  EXPECT_EQ(read->colors, cloud.colors);

  // Georeferenced points: doubles, as PCD has no offset; read relative to the same origin.
  PointCloud utm;
  utm.origin = {500000, 4100000, 0};
  utm.positions = {Vec3f(956.034f, 234.567f, 101.25f), Vec3f(1, 2, 3)};
  ASSERT_TRUE(WritePointCloud(utm, path).ok());
  EXPECT_THAT(ReadBytes(path), HasSubstr("FIELDS x y z\nSIZE 8 8 8\nTYPE F F F\n"));
  const absl::StatusOr<PointCloud> placed = ReadPointCloud(path);
  ASSERT_TRUE(placed.ok()) << placed.status();
  EXPECT_EQ(placed->origin, utm.origin);
  EXPECT_EQ(placed->positions, utm.positions);
}

// binary_compressed and ascii data give the same points back, georeferenced ones too; the
// compressed file of a smooth cloud is smaller than the binary one; ascii colours are PCL's
// packed integers.
TEST(PcdIoTest, CompressedAndAsciiDataComeBackAsBinaryDoes) {
  PointCloud cloud = io_test::RandomCloud(3000, 4, /*normals=*/true, /*weights=*/true);
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud.colors.push_back({static_cast<uint8_t>(i), 200, 7});
    cloud.weights[i] = 1.0f;  // Constant columns, as a scan's often are: they compress.
  }
  PointCloud utm = cloud;
  utm.origin = {500000, 4100000, 0};
  for (Vec3f& p : utm.positions) p += Vec3f(500, 500, 0);  // The reader's origin stays.
  const std::string binary = TempPath("binary.pcd");
  ASSERT_TRUE(WritePointCloud(cloud, binary).ok());
  for (const PcdData kind : {PcdData::kBinaryCompressed, PcdData::kAscii}) {
    const bool ascii = kind == PcdData::kAscii;
    SCOPED_TRACE(ascii ? "ascii" : "binary_compressed");
    for (const PointCloud* written : {&cloud, &utm}) {
      const std::string path = TempPath(ascii ? "cloud_ascii.pcd" : "cloud_compressed.pcd");
      PointCloudWriteOptions options;
      options.pcd = kind;
      ASSERT_TRUE(WritePointCloud(*written, path, options).ok());
      const std::string bytes = ReadBytes(path);
      EXPECT_THAT(bytes, HasSubstr(ascii ? "\nDATA ascii\n" : "\nDATA binary_compressed\n"));
      const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
      ASSERT_TRUE(read.ok()) << read.status();
      EXPECT_EQ(read->origin, written->origin);
      EXPECT_EQ(read->positions, written->positions);
      EXPECT_EQ(read->normals, written->normals);
      EXPECT_EQ(read->weights, written->weights);
      EXPECT_EQ(read->colors, written->colors);
      if (written == &cloud && !ascii) {
        EXPECT_LT(bytes.size(), ReadBytes(binary).size() * 9 / 10);
      }
      if (written == &cloud && ascii) {
        EXPECT_THAT(bytes, HasSubstr("TYPE F F F F F F U F\n"));
        EXPECT_THAT(bytes, HasSubstr(absl::StrCat(" ", Packed({1, 200, 7}), " 1\n")));
      }
    }
  }
}

TEST(PcdIoTest, ReadsAsciiAsPclWritesItWithEmptyPixelsLeftOut) {
  // An organized 3 x 2 cloud: rgb as the packed integer (PCL since 1.9) or as the float whose
  // bits it is (older files); one pixel without a position; intensity skipped.
  const Rgb pink = {255, 0, 128};
  const uint32_t pink_bits = Packed(pink);
  float pink_float;
  std::memcpy(&pink_float, &pink_bits, 4);
  const std::string pcd = absl::StrCat(
      "# .PCD v0.7 - Point Cloud Data file format\r\nVERSION 0.7\r\n"
      "FIELDS x y z rgb intensity\nSIZE 4 4 4 4 4\nTYPE F F F F F\nCOUNT 1 1 1 1 1\n"
      "WIDTH 3\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 6\nDATA ascii\n",
      "0 0 0 4210752 7\n", "1 2 3 ", absl::StrFormat("%.9g", pink_float), " 8\n",
      "nan nan nan 0 0\n\n", "-1.5 0.25 8 65280 1\n", "4 5 6 255 2\n", "7 8 9 16711680 3\n");
  PointsLeftOut left_out;
  const absl::StatusOr<PointCloud> read = ReadCloudFrom("organized.pcd", pcd, &left_out);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->positions,
            (std::vector<Vec3f>{Vec3f(0, 0, 0), Vec3f(1, 2, 3), Vec3f(-1.5f, 0.25f, 8),
                                Vec3f(4, 5, 6), Vec3f(7, 8, 9)}));
  EXPECT_EQ(read->colors,
            (std::vector<Rgb>{{64, 64, 64}, pink, {0, 255, 0}, {0, 0, 255}, {255, 0, 0}}));
  EXPECT_TRUE(read->weights.empty()) << "intensity is not a confidence";
  EXPECT_TRUE(read->normals.empty());
  EXPECT_EQ(left_out.invalid, 1u);
  EXPECT_EQ(left_out.total(), 1u);

  // Every point without a position: refused.
  const std::string empty =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nDATA ascii\n"
      "nan 0 0\n0 inf 0\n";
  const absl::StatusOr<PointCloud> none = ReadCloudFrom("empty.pcd", empty);
  EXPECT_EQ(none.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(none.status().message()),
              HasSubstr("all 2 points lack a position (NaN or infinite x, y or z)"));
}

// A binary record as other tools lay it out: double x, y, z of a UTM scan, an unsigned 16-bit
// intensity, padding, a descriptor of 3 values, normals, rgba as an unsigned integer and a
// 16-bit quality taken as the weight.
std::string BinaryHeader(const std::string& data_kind, int points) {
  return absl::StrCat(
      "VERSION .7\nFIELDS x y z intensity _ descriptor normal_x normal_y normal_z rgba quality\n"
      "SIZE 8 8 8 2 1 4 4 4 4 4 2\nTYPE F F F U U F F F F U U\nCOUNT 1 1 1 1 2 3 1 1 1 1 1\n"
      "WIDTH ",
      points, "\nHEIGHT 1\nPOINTS ", points, "\nDATA ", data_kind, "\n");
}

struct BinaryPoint {
  double x, y, z;
  Vec3f normal;
  Rgb color;
  uint16_t quality;
};

const std::vector<BinaryPoint> kBinaryPoints = {
    {500000.25, 4100000.5, 100, Vec3f(0, 0, 1), {10, 20, 30}, 1},
    {500001.75, 4100002.125, 101, Vec3f(0, 1, 0), {10, 20, 30}, 2},
    {500003.5, 4100001, 99.5, Vec3f(1, 0, 0), {200, 0, 0}, 3}};

// The values of field `f` of every point, in the file's byte layout.
std::string FieldBytes(int f, const BinaryPoint& p) {
  std::string out;
  switch (f) {
    case 0:
      Put(p.x, false, &out);
      break;
    case 1:
      Put(p.y, false, &out);
      break;
    case 2:
      Put(p.z, false, &out);
      break;
    case 3:
      Put(uint16_t{999}, false, &out);
      break;
    case 4:
      out += std::string(2, '\0');
      break;
    case 5:
      for (float v : {0.5f, 0.25f, 0.125f}) Put(v, false, &out);
      break;
    case 6:
    case 7:
    case 8:
      Put(p.normal[f - 6], false, &out);
      break;
    case 9:
      Put(Packed(p.color) | 0xFF000000u, false, &out);
      break;
    default:
      Put(p.quality, false, &out);
      break;
  }
  return out;
}

void ExpectBinaryPoints(const absl::StatusOr<PointCloud>& read) {
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), kBinaryPoints.size());
  EXPECT_EQ(read->origin, (Origin{500000, 4100000, 0})) << "doubles far from zero";
  for (size_t i = 0; i < kBinaryPoints.size(); ++i) {
    const BinaryPoint& p = kBinaryPoints[i];
    EXPECT_EQ(read->positions[i], Vec3f(p.x - 500000, p.y - 4100000, p.z)) << i;
    EXPECT_EQ(read->normals[i], p.normal) << i;
    EXPECT_EQ(read->colors[i], p.color) << i;
    EXPECT_EQ(read->weights[i], p.quality) << i;
  }
}

TEST(PcdIoTest, ReadsBinaryRecordsOfMixedTypesAndCompressedColumns) {
  std::string records;
  for (const BinaryPoint& p : kBinaryPoints) {
    for (int f = 0; f < 11; ++f) records += FieldBytes(f, p);
  }
  ExpectBinaryPoints(ReadCloudFrom("binary.pcd", BinaryHeader("binary", 3) + records));

  // binary_compressed: the fields' columns one after another, LZF-compressed behind their
  // compressed and uncompressed sizes.
  std::string columns;
  for (int f = 0; f < 11; ++f) {
    for (const BinaryPoint& p : kBinaryPoints) columns += FieldBytes(f, p);
  }
  const std::string compressed = Lzf(columns);
  ASSERT_LT(compressed.size(), columns.size()) << "the runs of zeros became back references";
  std::string body;
  Put(static_cast<uint32_t>(compressed.size()), false, &body);
  Put(static_cast<uint32_t>(columns.size()), false, &body);
  body += compressed;
  ExpectBinaryPoints(ReadCloudFrom("compressed.pcd", BinaryHeader("binary_compressed", 3) + body));

  // A long run (a back reference of more than 8 bytes) of a large cloud of one point repeated.
  std::string many_columns;
  const int many = 1000;
  for (int f = 0; f < 11; ++f) {
    for (int i = 0; i < many; ++i) many_columns += FieldBytes(f, kBinaryPoints[0]);
  }
  const std::string packed = Lzf(many_columns);
  EXPECT_LT(packed.size(), many_columns.size());
  std::string many_body;
  Put(static_cast<uint32_t>(packed.size()), false, &many_body);
  Put(static_cast<uint32_t>(many_columns.size()), false, &many_body);
  const absl::StatusOr<PointCloud> repeated =
      ReadCloudFrom("many.pcd", BinaryHeader("binary_compressed", many) + many_body + packed);
  ASSERT_TRUE(repeated.ok()) << repeated.status();
  ASSERT_EQ(repeated->size(), static_cast<size_t>(many));
  EXPECT_EQ(repeated->colors.back(), kBinaryPoints[0].color);
  EXPECT_EQ(repeated->positions.back(), repeated->positions.front());
  EXPECT_EQ(repeated->normals.back(), kBinaryPoints[0].normal);
}

TEST(PcdIoTest, MalformedFilesAreRefusedWithWhatIsWrong) {
  const std::string fields = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\n";
  std::string binary = fields + "DATA binary\n";
  for (float v : {0.f, 1.f, 2.f, 3.f, 4.f}) Put(v, false, &binary);  // 5 of 6 floats.
  std::string corrupt = absl::StrCat(fields, "DATA binary_compressed\n");
  Put(uint32_t{3}, false, &corrupt);
  Put(uint32_t{24}, false, &corrupt);
  corrupt += std::string("\x20\x05\x00", 3);  // A back reference before any byte.
  std::string short_columns = absl::StrCat(fields, "DATA binary_compressed\n");
  Put(uint32_t{2}, false, &short_columns);
  Put(uint32_t{24}, false, &short_columns);
  short_columns += std::string("\x00\x07", 2);  // One literal byte of the 24 stated.
  std::string huge = absl::StrCat(
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 100000000\nDATA binary_compressed\n");
  Put(uint32_t{4}, false, &huge);
  Put(uint32_t{1200000000}, false, &huge);
  huge += std::string(4, '\0');
  const struct {
    const char* what;
    std::string bytes;
    const char* message;
  } cases[] = {
      {"not PCD", "ply\nformat ascii 1.0\n", "no FIELDS line: not a PCD file"},
      {"no DATA", fields, "the header has no DATA line"},
      {"SIZE short", "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n0 0 0\n",
       "FIELDS names 3 fields but SIZE gives 2, TYPE 3 and COUNT 3"},
      {"SIZE 3", "FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 1\nDATA ascii\n0 0 0\n",
       "field z has SIZE 3; sizes are 1, 2, 4 or 8"},
      {"half float", "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 1\nDATA ascii\n0 0 0\n",
       "field z is a float of 2 bytes"},
      {"TYPE", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F D\nWIDTH 1\nDATA ascii\n0 0 0\n",
       "line 3: TYPE 'D' is not F, I or U"},
      {"no z", "FIELDS x y w\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n0 0 0\n",
       "no field z (FIELDS x y w)"},
      {"POINTS", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA ascii\n",
       "POINTS 3 is not WIDTH 2 x HEIGHT 2"},
      {"DATA kind", fields + "DATA zipped\n", "DATA 'zipped' is not ascii, binary or"},
      {"ascii values", fields + "DATA ascii\n0 0 0\n1 1\n", "line 7: point 1 has 2 values"},
      {"ascii number", fields + "DATA ascii\n0 0 0\n1 one 1\n",
       "line 7: y of point 1 is 'one', not a number"},
      {"ascii short", fields + "DATA ascii\n0 0 0\n", "the data end after 1 of 2 points"},
      {"binary short", binary, "2 points of 12 bytes do not fit in the 20 bytes"},
      {"LZF reference", corrupt, "a back reference points before the start"},
      {"LZF short", short_columns, "the compressed points give 1 bytes; the header states 24"},
      {"LZF bomb", huge, "4 compressed bytes cannot hold 1200000000"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const absl::StatusOr<PointCloud> read = ReadCloudFrom("bad.pcd", c.bytes);
    ASSERT_FALSE(read.ok());
    EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(read.status().message()), HasSubstr(c.message));
    EXPECT_THAT(std::string(read.status().message()), HasSubstr("bad.pcd"));
  }
}

}  // namespace
}  // namespace neuralmesh
