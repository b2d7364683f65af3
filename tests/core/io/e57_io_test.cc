// ASTM E57 files (core/io/internal/e57.h) through ReadPointCloud and WritePointCloud: files
// laid out by tests/testing/e57_file.h (scans in cartesian and spherical coordinates, poses,
// fields packed in 2 to 64 bits across packets split at any byte, colour limits, normals,
// invalid points), neuralmesh's own files read back, and damaged or malformed files refused
// with what is wrong.
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/point_cloud_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/e57_file.h"

namespace neuralmesh {
namespace {

using io_test::ReadCloudFrom;
using io_test::TempPath;
using testing::E57Field;
using testing::E57File;
using testing::E57Floats;
using testing::E57PackBits;
using testing::E57Scan;
using ::testing::HasSubstr;

// A ScaledInteger or Integer field whose stored values are `values`, packed as the difference
// to `minimum` in the bits the range needs.
E57Field IntegerField(const std::string& name, int64_t minimum, int64_t maximum, int bits,
                      const std::vector<int64_t>& values, const std::string& scaling = "") {
  std::vector<uint64_t> packed;
  for (int64_t v : values)
    packed.push_back(static_cast<uint64_t>(v) - static_cast<uint64_t>(minimum));
  return {absl::StrCat("<", name, " type=\"", scaling.empty() ? "Integer" : "ScaledInteger",
                       "\" minimum=\"", minimum, "\" maximum=\"", maximum, "\" ", scaling, "/>"),
          E57PackBits(packed, bits)};
}

E57Field DoubleField(const std::string& name, const std::vector<double>& values) {
  return {absl::StrCat("<", name, " type=\"Float\"/>"), E57Floats(values)};
}

// A pose turning 90 degrees about z (x goes to y, y to -x), then moving by `translation`.
std::string QuarterTurnPose(const std::string& translation) {
  return absl::StrCat(
      "<pose type=\"Structure\"><rotation type=\"Structure\">"
      "<w type=\"Float\">0.70710678118654757</w><x type=\"Float\">0</x>"
      "<y type=\"Float\">0</y><z type=\"Float\">0.70710678118654757</z></rotation>"
      "<translation type=\"Structure\">",
      translation, "</translation></pose>");
}

void ExpectNear(const PointCloud& cloud, const std::vector<std::array<double, 3>>& expected,
                double tolerance) {
  ASSERT_EQ(cloud.positions.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(cloud.origin[c] + cloud.positions[i][c], expected[i][c], tolerance)
          << "point " << i << " axis " << c;
    }
  }
}

TEST(E57IoTest, ScansAreMovedByTheirPosesFromCartesianOrSphericalCoordinates) {
  // Scan 0: georeferenced ScaledIntegers of 13 bits (millimetres from -1 m to 5 m above their
  // offsets), the third record marked invalid, in packets of 3 bytes a stream with empty and
  // index packets between them.
  E57Scan cartesian;
  cartesian.records = 4;
  const std::string mm = "scale=\"0.001\" offset=\"";
  cartesian.fields = {
      IntegerField("cartesianX", -1000, 5000, 13, {1000, 2500, 0, 4999}, mm + "500000\""),
      IntegerField("cartesianY", -1000, 5000, 13, {3000, 0, 0, 5000}, mm + "4100000\""),
      IntegerField("cartesianZ", -1000, 5000, 13, {100, 200, 0, 4000}, mm + "0\""),
      IntegerField("cartesianInvalidState", 0, 2, 2, {0, 0, 2, 0})};
  cartesian.bytes_per_packet = 3;
  cartesian.other_packets = true;
  // Scan 1: ranges and angles in doubles, turned a quarter about z and moved.
  E57Scan spherical;
  spherical.records = 3;
  spherical.fields = {DoubleField("sphericalRange", {2, 1, 3}),
                      DoubleField("sphericalAzimuth", {0, M_PI / 2, 0}),
                      DoubleField("sphericalElevation", {0, 0, M_PI / 2})};
  spherical.elements = QuarterTurnPose(
      "<x type=\"Float\">500010</x><y type=\"Float\">4100020</y><z type=\"Float\">5</z>");
  PointsLeftOut left_out;
  const absl::StatusOr<PointCloud> cloud =
      ReadCloudFrom("two_scans.e57", E57File({cartesian, spherical}), &left_out);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(cloud->origin, (Origin{500000, 4100000, 0}));
  ExpectNear(*cloud,
             {{500001, 4100003, 0.1},
              {500002.5, 4100000, 0.2},
              {500004.999, 4100005, 4},
              {500010, 4100022, 5},
              {500009, 4100020, 5},
              {500010, 4100020, 8}},
             2e-4);
  EXPECT_EQ(left_out.invalid, 1u);
  EXPECT_TRUE(cloud->colors.empty());
  EXPECT_TRUE(cloud->normals.empty());
  EXPECT_TRUE(cloud->weights.empty()) << "intensity is not a confidence";
}

TEST(E57IoTest, FieldsOfUpToSixtyFourBitsAreUnpackedAcrossWordBoundaries) {
  // An Integer without limits takes 64 bits; 33 bits straddle every byte and word boundary.
  const int64_t kMin = std::numeric_limits<int64_t>::min();
  E57Scan scan;
  scan.records = 5;
  const std::vector<int64_t> x = {7, -3, 1000000, 0, -123456};
  const std::vector<int64_t> y = {0, 8589934591, 4294967296, 12345, 1};
  std::vector<uint64_t> packed_x;
  for (int64_t v : x) packed_x.push_back(static_cast<uint64_t>(v) - static_cast<uint64_t>(kMin));
  scan.fields = {{"<cartesianX type=\"Integer\"/>", E57PackBits(packed_x, 64)},
                 IntegerField("cartesianY", 0, 8589934591, 33, y),
                 {"<cartesianZ type=\"Float\" precision=\"single\"/>",
                  E57Floats(std::vector<float>{0.5f, -1, 2, 3.25f, 4})}};
  scan.bytes_per_packet = 5;
  const absl::StatusOr<PointCloud> cloud = ReadCloudFrom("wide.e57", E57File({scan}));
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  std::vector<std::array<double, 3>> expected;
  const float z[] = {0.5f, -1, 2, 3.25f, 4};
  for (int i = 0; i < 5; ++i) {
    expected.push_back({static_cast<double>(x[i]), static_cast<double>(y[i]), z[i]});
  }
  // 8.6e9 in a float relative to an origin: within a float's step there.
  ExpectNear(*cloud, expected, 1024);
  EXPECT_EQ(cloud->origin[2], 0);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(cloud->positions[i][2], z[i]);
}

TEST(E57IoTest, ColoursAreScaledFromTheirLimitsAndNormalsTurnedByThePose) {
  E57Scan scan;
  scan.records = 2;
  scan.fields = {
      DoubleField("cartesianX", {1, 0}),
      DoubleField("cartesianY", {0, 1}),
      DoubleField("cartesianZ", {0, 0}),
      IntegerField("colorRed", 0, 1023, 10, {1023, 0}),
      IntegerField("colorGreen", 0, 1023, 10, {512, 0}),
      IntegerField("colorBlue", 0, 1023, 10, {0, 100}),
      {"<nor:normalX type=\"Float\" precision=\"single\"/>", E57Floats(std::vector<float>{1, 0})},
      {"<nor:normalY type=\"Float\" precision=\"single\"/>", E57Floats(std::vector<float>{0, 0})},
      {"<nor:normalZ type=\"Float\" precision=\"single\"/>", E57Floats(std::vector<float>{0, 1})}};
  // The limits say the channels span 0 to 512, not the fields' 0 to 1023.
  scan.elements = absl::StrCat(
      QuarterTurnPose(""),
      "<colorLimits type=\"Structure\"><colorRedMaximum type=\"Integer\">512</colorRedMaximum>"
      "<colorGreenMaximum type=\"Integer\">512</colorGreenMaximum>"
      "<colorBlueMaximum type=\"Integer\">512</colorBlueMaximum></colorLimits>");
  const absl::StatusOr<PointCloud> cloud = ReadCloudFrom("colored.e57", E57File({scan}));
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  ExpectNear(*cloud, {{0, 1, 0}, {-1, 0, 0}}, 1e-6);
  EXPECT_EQ(cloud->colors, (std::vector<Rgb>{{255, 255, 0}, {0, 0, 50}}));
  ASSERT_EQ(cloud->normals.size(), 2u);
  EXPECT_NEAR(cloud->normals[0][0], 0, 1e-6);
  EXPECT_NEAR(cloud->normals[0][1], 1, 1e-6);
  EXPECT_NEAR(cloud->normals[1][2], 1, 1e-6);

  // A point whose colour is marked invalid keeps its position; the file's colours are dropped,
  // as they are when one scan has none.
  scan.fields.push_back(IntegerField("isColorInvalid", 0, 1, 1, {0, 1}));
  const absl::StatusOr<PointCloud> partly = ReadCloudFrom("partly_colored.e57", E57File({scan}));
  ASSERT_TRUE(partly.ok()) << partly.status();
  EXPECT_EQ(partly->size(), 2u);
  EXPECT_TRUE(partly->colors.empty());
  E57Scan plain;
  plain.records = 1;
  plain.fields = {DoubleField("cartesianX", {5}), DoubleField("cartesianY", {5}),
                  DoubleField("cartesianZ", {5})};
  scan.fields.pop_back();
  const absl::StatusOr<PointCloud> mixed = ReadCloudFrom("mixed.e57", E57File({scan, plain}));
  ASSERT_TRUE(mixed.ok()) << mixed.status();
  EXPECT_EQ(mixed->size(), 3u);
  EXPECT_TRUE(mixed->colors.empty());
  EXPECT_TRUE(mixed->normals.empty());
}

TEST(E57IoTest, WrittenFilesKeepPositionsColoursAndNormalsAndAreReproducible) {
  PointCloud cloud = io_test::RandomCloud(5000, 7, /*normals=*/true, /*weights=*/true);
  cloud.origin = {500000, 4100000, 250};
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud.positions[i] *= 400.0f;  // A tile of 800 m: the scale is 1e-5 m.
    cloud.colors.push_back({static_cast<uint8_t>(i), static_cast<uint8_t>(i * 7),
                            static_cast<uint8_t>(255 - i % 256)});
  }
  const std::string path = TempPath("written.e57");
  ASSERT_TRUE(WritePointCloud(cloud, path).ok());
  const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      // Half the scale, and half a float's step where the reader puts the point.
      const double local =
          std::max(std::fabs(cloud.positions[i][c]), std::fabs(read->positions[i][c]));
      EXPECT_NEAR(read->origin[c] + read->positions[i][c], cloud.origin[c] + cloud.positions[i][c],
                  0.5e-5 + local * std::ldexp(1.0, -24))
          << "point " << i;
    }
  }
  EXPECT_EQ(read->colors, cloud.colors);
  EXPECT_EQ(read->normals, cloud.normals);
  EXPECT_TRUE(read->weights.empty()) << "E57 has no place for weights";
  // Several data packets of at most 64 KiB; the same points give the same bytes.
  const std::string bytes = io_test::ReadBytes(path);
  EXPECT_GT(bytes.size(), 65536u);
  EXPECT_EQ(bytes.size() % 1024, 0u);
  const std::string again = TempPath("again.e57");
  ASSERT_TRUE(WritePointCloud(cloud, again).ok());
  EXPECT_EQ(io_test::ReadBytes(again), bytes);
}

// The points of a valid one-scan file, for the malformed ones below to break.
E57Scan SmallScan() {
  E57Scan scan;
  scan.records = 2;
  scan.fields = {DoubleField("cartesianX", {1, 2}), DoubleField("cartesianY", {3, 4}),
                 IntegerField("cartesianZ", 0, 5, 3, {1, 5})};
  return scan;
}

TEST(E57IoTest, DamagedAndMalformedFilesAreRefusedWithWhatIsWrong) {
  const std::string good = E57File({SmallScan()});
  ASSERT_TRUE(ReadCloudFrom("good.e57", good).ok());

  std::string flipped = good;
  flipped[500] ^= 0x10;
  std::string version = good;
  version[8] = 2;
  E57Scan beyond = SmallScan();
  beyond.fields[2] = IntegerField("cartesianZ", 0, 5, 3, {1, 7});
  E57Scan short_scan = SmallScan();
  short_scan.records = 3;
  E57Scan missing_field = SmallScan();
  missing_field.fields.erase(missing_field.fields.begin());
  E57Scan no_coordinates = SmallScan();
  for (E57Field& field : no_coordinates.fields) field.xml.replace(1, 9, "something");
  E57Scan all_invalid = SmallScan();
  all_invalid.fields.push_back(IntegerField("cartesianInvalidState", 0, 2, 2, {2, 1}));
  E57Scan huge = SmallScan();
  huge.records = 1000000000;
  // The prototype declares a fourth field, of no bits, that the packets do not carry.
  E57Scan undeclared_stream = SmallScan();
  undeclared_stream.fields[1].xml += "<intensity type=\"Integer\" minimum=\"0\" maximum=\"0\"/>";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"not E57", "not an E57 file at all, but long enough to hold a header of 48 bytes"},
      {"truncated", good.substr(0, good.size() - 10)},
      {"damaged", flipped},
      {"version 2", version},
      {"bad XML", E57File({}, "", "<e57Root><data3D></e57Root>")},
      {"no data3D", E57File({}, "", "<e57Root type=\"Structure\"/>")},
      {"no scans", E57File({})},
      {"beyond", E57File({beyond})},
      {"short", E57File({short_scan})},
      {"partial", E57File({missing_field})},
      {"no coordinates", E57File({no_coordinates})},
      {"all invalid", E57File({all_invalid})},
      {"huge", E57File({huge})},
      {"streams", E57File({undeclared_stream})},
  };
  const std::vector<std::string> messages = {
      "does not begin with the signature",
      "the header says the file has 1024 bytes, but it has 1014 (truncated?)",
      "checksum of page 0 (bytes 0 to 1023) does not match its data: the file is damaged",
      "version 2 is not supported",
      "its XML is malformed: line 1: end tag </e57Root> where <data3D> ends",
      "the XML has no data3D element",
      "the file holds no 3D scans",
      "record 1 of field cartesianZ is beyond the field's maximum 5",
      "scan 0's section ends before all its records",
      "scan 0 has a cartesianY field but no cartesianX",
      "scan 0 has neither cartesian nor spherical coordinates",
      "all 2 points are marked invalid",
      "scan 0 claims 1000000000 records, more than the file holds",
      "scan 0's data packet holds 3 bytestreams where its prototype declares 4 fields",
  };
  for (size_t k = 0; k < cases.size(); ++k) {
    const absl::StatusOr<PointCloud> read = ReadCloudFrom(cases[k].first + ".e57", cases[k].second);
    ASSERT_FALSE(read.ok()) << cases[k].first;
    EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument) << cases[k].first;
    EXPECT_THAT(std::string(read.status().message()), HasSubstr(messages[k])) << cases[k].first;
    EXPECT_THAT(std::string(read.status().message()), HasSubstr(".e57': E57")) << cases[k].first;
  }
}

}  // namespace
}  // namespace neuralmesh
