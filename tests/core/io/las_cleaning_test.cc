// Cleaning a LAS file without losing what a PointCloud does not hold (WriteCleanedLas,
// core/io/las_cleaning.h): the kept records byte for byte, the header's version, format, scale
// and offset, the variable-length records and what follows the points as they were. Outliers
// left out: the header's point counts, counts by return and bounds those of the kept points,
// and the starts of the waveform data and extended records moved up with them. Outliers
// classified as noise: every record kept, theirs with class 7 and their flags. Tiles joined
// into one file, on the finest scale, or refused saying why.
#include "core/io/las_cleaning.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/laz.h"
#include "core/io/point_cloud_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/las_file.h"
#include "tests/testing/las_scan.h"

namespace neuralmesh {
namespace {

using io_test::Field;
using io_test::ReadBytes;
using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;
using testing::LasFile;
using testing::LasLayout;
using testing::LasPoint;
using testing::LasVariableLengthRecord;

// Points with every field set to something of its own: intensity, returns, class (2 or 5), GPS
// time, extra bytes, colour.
std::vector<LasPoint> VariedPoints(int count) {
  std::vector<LasPoint> points;
  for (int i = 0; i < count; ++i) {
    LasPoint p{1000 * i - 3000,
               70 * i * i,
               -25 * i,
               static_cast<uint16_t>(257 * i),
               7,
               static_cast<uint16_t>(65535 - i)};
    p.classification = static_cast<uint8_t>(i % 3 == 0 ? 2 : 5);  // Ground or high vegetation.
    p.intensity = static_cast<uint16_t>(100 + 31 * i);
    p.returns = 3;
    p.return_number = static_cast<uint8_t>(1 + i % 3);
    p.gps_time = 1.0e8 + 0.25 * i;
    p.extra = 0xA5000000u + i;
    points.push_back(p);
  }
  return points;
}

// The byte ranges of the public header block that FormatCleanedLas writes anew: the generating
// software, the legacy counts and bounds, the starts of the waveform data and of the extended
// records, the LAS 1.4 counts.
std::string WithoutRewrittenFields(std::string header) {
  for (auto [from, to] : {std::pair{58, 90}, {107, 131}, {179, 227}, {227, 243}, {247, 375}}) {
    if (static_cast<size_t>(from) < header.size()) {
      std::fill(header.begin() + from, header.begin() + std::min<size_t>(to, header.size()), 0);
    }
  }
  return header;
}

struct Expected {
  std::vector<size_t> records;  // Of the source file, in order.
  size_t record_length;
  size_t offset_to_points;
  size_t source_count;
};

// Checks `out` against `in`, from which it kept expected.records.
void ExpectRecordsKept(const std::string& in, const std::string& out, const Expected& expected,
                       size_t header_size) {
  const size_t kept = expected.records.size();
  ASSERT_EQ(out.size(), in.size() - (expected.source_count - kept) * expected.record_length);
  EXPECT_EQ(WithoutRewrittenFields(out.substr(0, header_size)),
            WithoutRewrittenFields(in.substr(0, header_size)));
  EXPECT_EQ(out.substr(header_size, expected.offset_to_points - header_size),
            in.substr(header_size, expected.offset_to_points - header_size))
      << "the variable-length records";
  EXPECT_THAT(out.substr(58, 32), HasSubstr("neuralmesh ")) << "generating software";
  for (size_t k = 0; k < kept; ++k) {
    EXPECT_EQ(
        out.substr(expected.offset_to_points + k * expected.record_length, expected.record_length),
        in.substr(expected.offset_to_points + expected.records[k] * expected.record_length,
                  expected.record_length))
        << "record " << k << " (source record " << expected.records[k] << ")";
  }
  const size_t out_end = expected.offset_to_points + kept * expected.record_length;
  const size_t in_end = expected.offset_to_points + expected.source_count * expected.record_length;
  EXPECT_EQ(out.substr(out_end), in.substr(in_end)) << "what follows the points";
  // Bounds: the kept records' coordinates, scaled.
  for (int c = 0; c < 3; ++c) {
    double low = INFINITY, high = -INFINITY;
    for (size_t r : expected.records) {
      const double v =
          Field<int32_t>(in, expected.offset_to_points + r * expected.record_length + 4 * c) *
              Field<double>(in, 131 + 8 * c) +
          Field<double>(in, 155 + 8 * c);
      low = std::min(low, v);
      high = std::max(high, v);
    }
    EXPECT_EQ(Field<double>(out, 179 + 16 * c), high) << "max of axis " << c;
    EXPECT_EQ(Field<double>(out, 187 + 16 * c), low) << "min of axis " << c;
  }
}

// Writes `in` to a file and cleans it of the points flagged in `outliers` into a new one;
// returns its bytes.
std::string Cleaned(const std::string& name, const std::string& in,
                    const std::vector<bool>& outliers,
                    LasOutlierRecords records = LasOutlierRecords::kLeftOut) {
  const std::string source = TempPath(name + ".las");
  const std::string written = TempPath(name + "_cleaned.las");
  WriteBytes(source, in);
  const absl::Status status = WriteCleanedLas({source}, outliers, records, written);
  EXPECT_TRUE(status.ok()) << status;
  return ReadBytes(written);
}

TEST(LasCleaningTest, Las14KeepsEveryFieldTheCoordinateSystemAndTheExtendedRecords) {
  LasLayout layout;
  layout.version_minor = 4;
  layout.format = 7;  // Colours and GPS time.
  layout.record_length = 36 + 4;
  layout.scale[2] = 0.001;
  layout.offset[0] = 500000;
  layout.offset[1] = 4100000;
  const std::string wkt = "PROJCS[\"WGS 84 / UTM zone 33N\",AUTHORITY[\"EPSG\",\"32633\"]]";
  layout.vlrs = LasVariableLengthRecord("LASF_Projection", 2112, wkt, false);
  layout.vlr_count = 1;
  layout.after_points = LasVariableLengthRecord("LASF_Spec", 65535, "waveform packets", true);
  layout.evlr_count = 1;
  std::vector<LasPoint> points = VariedPoints(8);
  points[2].classification = 7;  // Noise: ReadPointCloud leaves it out, and so does the copy.
  points[5].withheld = true;
  const std::string in = LasFile(layout, points);

  PointsLeftOut left_out;
  const absl::StatusOr<PointCloud> read = io_test::ReadCloudFrom("source.las", in, &left_out);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), 6u);  // Records 0, 1, 3, 4, 6, 7.
  const std::string out = Cleaned("las14", in, {false, true, false, false, true, false});
  ASSERT_FALSE(out.empty());
  const size_t offset_to_points = 375 + layout.vlrs.size();
  ExpectRecordsKept(in, out, {{0, 3, 4, 7}, 40, offset_to_points, 8}, 375);

  EXPECT_EQ(Field<uint64_t>(out, 247), 4u) << "point count";
  EXPECT_EQ(Field<uint32_t>(out, 107), 0u) << "the legacy count stays zero for format 7";
  // Returns of the kept points 0, 3, 4, 7: 1, 1, 2, 2.
  EXPECT_EQ(Field<uint64_t>(out, 255), 2u);
  EXPECT_EQ(Field<uint64_t>(out, 263), 2u);
  EXPECT_EQ(Field<uint64_t>(out, 271), 0u);
  const uint64_t evlr_start = Field<uint64_t>(out, 235);
  EXPECT_EQ(evlr_start, offset_to_points + 4 * 40);
  EXPECT_EQ(out.substr(evlr_start), layout.after_points);
  EXPECT_EQ(Field<uint32_t>(out, 243), 1u);

  // Read back: the kept points, where they were, with their colours.
  const absl::StatusOr<PointCloud> reread = io_test::ReadCloudFrom("kept.las", out);
  ASSERT_TRUE(reread.ok()) << reread.status();
  EXPECT_EQ(reread->origin, read->origin);
  ASSERT_EQ(reread->size(), 4u);
  const std::vector<size_t> kept_points = {0, 2, 3, 5};
  for (size_t k = 0; k < kept_points.size(); ++k) {
    EXPECT_EQ(reread->positions[k], read->positions[kept_points[k]]) << k;
    EXPECT_EQ(reread->colors[k], read->colors[kept_points[k]]) << k;
  }
}

TEST(LasCleaningTest, Las12AndLas13CountAgainAndMoveTheWaveformData) {
  for (const int minor : {2, 3}) {
    SCOPED_TRACE(::testing::Message() << "LAS 1." << minor);
    LasLayout layout;
    layout.version_minor = minor;
    layout.format = 1;  // GPS time, no colour.
    if (minor == 3) layout.after_points = "waveform packets, 29 bytes.";
    const std::vector<LasPoint> points = VariedPoints(5);
    const std::string in = LasFile(layout, points);
    const size_t header_size = minor == 3 ? 235 : 227;
    const std::string out =
        Cleaned(absl::StrCat("las1", minor), in, {true, false, false, false, true});
    ASSERT_FALSE(out.empty());
    ExpectRecordsKept(in, out, {{1, 2, 3}, 28, header_size, 5}, header_size);
    EXPECT_EQ(Field<uint32_t>(out, 107), 3u) << "point count";
    // Returns of points 1, 2, 3: 2, 3, 1.
    for (int r = 1; r <= 5; ++r) {
      EXPECT_EQ(Field<uint32_t>(out, 111 + 4 * (r - 1)), r <= 3 ? 1u : 0u) << "return " << r;
    }
    if (minor == 3) {
      const uint64_t waveform_start = Field<uint64_t>(out, 227);
      EXPECT_EQ(waveform_start, header_size + 3 * 28);
      EXPECT_EQ(out.substr(waveform_start), layout.after_points);
    }
  }
}

TEST(LasCleaningTest, OutliersClassifiedAsNoiseKeepEveryRecordAndTheirFlags) {
  for (const int format : {3, 8}) {  // The two record families: class in byte 15, or 16.
    SCOPED_TRACE(::testing::Message() << "format " << format);
    LasLayout layout;
    layout.version_minor = format >= 6 ? 4 : 2;
    layout.format = format;
    std::vector<LasPoint> points = VariedPoints(6);
    points[1].withheld = true;  // Withheld: kept as it is, not one of the points to flag.
    points[3].classification = 18;
    const std::string in = LasFile(layout, points);
    // The points read: 0, 2, 4, 5; outliers 2 and 5.
    const std::string out = Cleaned(absl::StrCat("noise", format), in, {false, true, false, true},
                                    LasOutlierRecords::kClassifiedAsNoise);
    ASSERT_EQ(out.size(), in.size());
    const size_t header_size = format >= 6 ? 375 : 227;
    const size_t length = testing::kLasRecordLength[format];
    EXPECT_EQ(WithoutRewrittenFields(out.substr(0, header_size)),
              WithoutRewrittenFields(in.substr(0, header_size)));
    EXPECT_EQ(out.substr(107, 24), in.substr(107, 24)) << "the counts stay";
    EXPECT_EQ(out.substr(179, 48), in.substr(179, 48)) << "the bounds stay";
    for (size_t i = 0; i < points.size(); ++i) {
      std::string expected = in.substr(header_size + i * length, length);
      if (i == 2 || i == 5) {
        if (format >= 6) {
          expected[16] = 7;
        } else {
          expected[15] = static_cast<char>(7);
        }
      }
      EXPECT_EQ(out.substr(header_size + i * length, length), expected) << "record " << i;
    }
    // Read again, the outliers are left out as noise.
    PointsLeftOut left_out;
    const absl::StatusOr<PointCloud> reread = io_test::ReadCloudFrom("noise.las", out, &left_out);
    ASSERT_TRUE(reread.ok()) << reread.status();
    EXPECT_EQ(reread->size(), 2u);
    EXPECT_EQ(left_out.noise, 3u);
    EXPECT_EQ(left_out.withheld, 1u);
  }
  // Format 1's flags (synthetic, key point, withheld) share the class's byte and stay.
  LasLayout layout;
  layout.format = 1;
  std::vector<LasPoint> points = VariedPoints(3);
  std::string in = LasFile(layout, points);
  in[227 + 28 + 15] = static_cast<char>(0x60 | 5);  // Point 1: synthetic and key point, class 5.
  const std::string out =
      Cleaned("flags", in, {false, true, false}, LasOutlierRecords::kClassifiedAsNoise);
  EXPECT_EQ(static_cast<uint8_t>(out[227 + 28 + 15]), 0x60 | 7);
}

// With classes asked for, the flags are for the points of those classes; left out, the
// records of other classes go too; classified as noise, they stay as they were.
TEST(LasCleaningTest, TheClassesAskedForChooseThePointsAndTheRecordsKept) {
  LasLayout layout;
  layout.format = 1;
  std::vector<LasPoint> points = VariedPoints(6);  // Classes 2, 5, 5, 2, 5, 5.
  const std::string in = LasFile(layout, points);
  const std::string source = TempPath("classes.las");
  WriteBytes(source, in);
  PointSelection vegetation;
  vegetation.las_classes = LasClasses().set(5);
  const std::string written = TempPath("vegetation.las");
  // Points 1, 2, 4, 5 are read; 4 is an outlier.
  ASSERT_TRUE(WriteCleanedLas({source}, {false, false, true, false}, LasOutlierRecords::kLeftOut,
                              written, vegetation)
                  .ok());
  std::string out = ReadBytes(written);
  ExpectRecordsKept(in, out, {{1, 2, 5}, 28, 227, 6}, 227);

  ASSERT_TRUE(WriteCleanedLas({source}, {false, false, true, false},
                              LasOutlierRecords::kClassifiedAsNoise, written, vegetation)
                  .ok());
  out = ReadBytes(written);
  ASSERT_EQ(out.size(), in.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(out[227 + 28 * i + 15], i == 4 ? 7 : in[227 + 28 * i + 15]) << "record " << i;
  }

  const absl::Status status = WriteCleanedLas({source}, {false, false, false, false, false, false},
                                              LasOutlierRecords::kLeftOut, written, vegetation);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("6 flags for the 4 points read from '" + source +
                        "' (withheld, noise or other classes"));
}

// A survey's tiles joined: every record whole and in order, after the first tile's header and
// coordinate system; a tile on another scale and offset is put on the finest scale, every
// coordinate kept.
TEST(LasCleaningTest, TilesJoinIntoOneFileOnTheFinestScale) {
  const std::string crs =
      LasVariableLengthRecord("LASF_Projection", 2112, "PROJCS[\"UTM zone 32N\"]", false);
  LasLayout a;
  a.format = 3;
  a.vlrs = crs;
  a.vlr_count = 1;
  a.offset[0] = 500000;
  a.offset[1] = 4000000;
  LasLayout b = a;
  for (double& s : b.scale) s = 0.001;
  b.offset[0] = 500100;
  const std::vector<LasPoint> points_a = VariedPoints(5);
  std::vector<LasPoint> points_b = VariedPoints(4);
  points_b[2].withheld = true;
  const std::string in_a = LasFile(a, points_a), in_b = LasFile(b, points_b);
  const std::string tile_a = TempPath("tile_a.las"), tile_b = TempPath("tile_b.las");
  WriteBytes(tile_a, in_a);
  WriteBytes(tile_b, in_b);
  const size_t length = testing::kLasRecordLength[3];
  const size_t first = 227 + crs.size();

  for (const auto records : {LasOutlierRecords::kLeftOut, LasOutlierRecords::kClassifiedAsNoise}) {
    const bool as_noise = records == LasOutlierRecords::kClassifiedAsNoise;
    SCOPED_TRACE(as_noise ? "classified as noise" : "left out");
    // The points read: a's 5, then b's 0, 1 and 3; the outliers a's 1 and b's 3.
    const std::string written = TempPath("joined.las");
    const absl::Status status = WriteCleanedLas(
        {tile_a, tile_b}, {false, true, false, false, false, false, false, true}, records, written);
    ASSERT_TRUE(status.ok()) << status;
    const std::string out = ReadBytes(written);
    // (tile, record) of each record written.
    std::vector<std::pair<int, size_t>> expected;
    for (size_t i = 0; i < 5; ++i) {
      if (as_noise || i != 1) expected.push_back({0, i});
    }
    for (size_t i = 0; i < 4; ++i) {
      if (as_noise || (i != 2 && i != 3)) expected.push_back({1, i});
    }
    ASSERT_EQ(out.size(), first + expected.size() * length);
    EXPECT_EQ(out.substr(227, crs.size()), crs) << "the coordinate system";
    EXPECT_EQ(Field<uint32_t>(out, 107), expected.size());
    uint32_t first_returns = 0;
    std::array<double, 3> low = {INFINITY, INFINITY, INFINITY};
    std::array<double, 3> high = {-INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(Field<double>(out, 131 + 8 * c), 0.001) << "the finest scale, axis " << c;
      EXPECT_EQ(Field<double>(out, 155 + 8 * c), a.offset[c]) << "a's offset, axis " << c;
    }
    for (size_t k = 0; k < expected.size(); ++k) {
      const auto [tile, i] = expected[k];
      const std::string& in = tile == 0 ? in_a : in_b;
      const LasPoint& p = (tile == 0 ? points_a : points_b)[i];
      const size_t at = first + k * length;
      std::string source = in.substr(first + i * length, length);
      if (as_noise && ((tile == 0 && i == 1) || (tile == 1 && i == 3))) {
        source[15] = static_cast<char>(7);
      }
      EXPECT_EQ(out.substr(at + 12, length - 12), source.substr(12)) << "record " << k;
      // On the scale of 0.001 from a's offset: a's integers times 10, b's moved by 100 m in x.
      const int32_t x = tile == 0 ? 10 * p.x : p.x + 100000;
      const int32_t y = tile == 0 ? 10 * p.y : p.y;
      const int32_t z = tile == 0 ? 10 * p.z : p.z;
      EXPECT_EQ(Field<int32_t>(out, at), x) << "record " << k;
      EXPECT_EQ(Field<int32_t>(out, at + 4), y) << "record " << k;
      EXPECT_EQ(Field<int32_t>(out, at + 8), z) << "record " << k;
      first_returns += p.return_number == 1;
      const int32_t stored[3] = {x, y, z};
      for (int c = 0; c < 3; ++c) {
        const double v = stored[c] * 0.001 + a.offset[c];
        low[c] = std::min(low[c], v);
        high[c] = std::max(high[c], v);
      }
    }
    EXPECT_EQ(Field<uint32_t>(out, 111), first_returns) << "first returns";
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(Field<double>(out, 179 + 16 * c), high[c]) << "max of axis " << c;
      EXPECT_EQ(Field<double>(out, 187 + 16 * c), low[c]) << "min of axis " << c;
    }
  }
}

// LAS 1.4 tiles joined: the records of both, then the extended records once, their start moved
// past all the records; the 64-bit counts summed, the legacy ones left zero. Tiles whose
// extended records differ are refused.
TEST(LasCleaningTest, Las14TilesJoinWithTheirExtendedRecordsOnceAfterThePoints) {
  LasLayout layout;
  layout.version_minor = 4;
  layout.format = 7;
  layout.record_length = 36 + 4;
  layout.vlrs = LasVariableLengthRecord("LASF_Projection", 2112, "PROJCS[\"UTM 33N\"]", false);
  layout.vlr_count = 1;
  layout.after_points = LasVariableLengthRecord("tile_notes", 1, "a survey's notes", true);
  layout.evlr_count = 1;
  const std::string in_a = LasFile(layout, VariedPoints(3));
  const std::string in_b = LasFile(layout, VariedPoints(4));
  const std::string tile_a = TempPath("tile14_a.las"), tile_b = TempPath("tile14_b.las");
  WriteBytes(tile_a, in_a);
  WriteBytes(tile_b, in_b);
  const std::string written = TempPath("joined14.las");
  const absl::Status status = WriteCleanedLas({tile_a, tile_b}, std::vector<bool>(7, false),
                                              LasOutlierRecords::kLeftOut, written);
  ASSERT_TRUE(status.ok()) << status;
  const std::string out = ReadBytes(written);
  const size_t first = 375 + layout.vlrs.size();
  ASSERT_EQ(out.size(), first + 7 * 40 + layout.after_points.size());
  EXPECT_EQ(out.substr(first, 3 * 40), in_a.substr(first, 3 * 40)) << "a's records";
  EXPECT_EQ(out.substr(first + 3 * 40, 4 * 40), in_b.substr(first, 4 * 40)) << "b's records";
  const uint64_t evlr_start = Field<uint64_t>(out, 235);
  EXPECT_EQ(evlr_start, first + 7 * 40);
  EXPECT_EQ(out.substr(evlr_start), layout.after_points);
  EXPECT_EQ(Field<uint64_t>(out, 247), 7u) << "point count";
  EXPECT_EQ(Field<uint32_t>(out, 107), 0u) << "the legacy count stays zero";
  // Return numbers (VariedPoints): 1, 2, 3 in a, then 1, 2, 3, 1 in b.
  EXPECT_EQ(Field<uint64_t>(out, 255), 3u) << "first returns";
  EXPECT_EQ(Field<uint64_t>(out, 263), 2u) << "second returns";
  EXPECT_EQ(Field<uint64_t>(out, 271), 2u) << "third returns";

  LasLayout other = layout;
  other.after_points = LasVariableLengthRecord("tile_notes", 1, "another survey's", true);
  WriteBytes(tile_b, LasFile(other, VariedPoints(4)));
  const absl::Status refused = WriteCleanedLas({tile_a, tile_b}, std::vector<bool>(7, false),
                                               LasOutlierRecords::kLeftOut, written);
  EXPECT_EQ(refused.code(), absl::StatusCode::kFailedPrecondition) << refused;
  EXPECT_THAT(std::string(refused.message()), HasSubstr("what follows the points of '"));
}

// Tiles whose records cannot share one file are refused, saying which and why.
TEST(LasCleaningTest, TilesThatCannotShareAFileAreRefusedSayingWhy) {
  const auto joined = [](const LasLayout& a, const LasLayout& b) {
    const std::string tile_a = TempPath("refused_a.las"), tile_b = TempPath("refused_b.las");
    WriteBytes(tile_a, LasFile(a, VariedPoints(2)));
    WriteBytes(tile_b, LasFile(b, VariedPoints(2)));
    return WriteCleanedLas({tile_a, tile_b}, std::vector<bool>(4, false),
                           LasOutlierRecords::kLeftOut, TempPath("refused.las"));
  };
  const auto expect_refused = [](const absl::Status& status, absl::string_view why) {
    EXPECT_EQ(status.code(), absl::StatusCode::kFailedPrecondition) << status;
    EXPECT_THAT(std::string(status.message()), HasSubstr(std::string(why)));
  };
  LasLayout a;
  a.format = 1;
  LasLayout b = a;
  b.format = 3;
  b.record_length = 34 + 4;
  expect_refused(joined(a, b), "refused_b.las' has 4 extra bytes a record and '");
  b = a;
  b.vlrs = LasVariableLengthRecord("LASF_Projection", 2112, "PROJCS[\"UTM zone 33N\"]", false);
  b.vlr_count = 1;
  expect_refused(joined(a, b), "the coordinate systems or extra bytes of '");
  // Another kind of record (a description of the tile, say) does not matter.
  b.vlrs = LasVariableLengthRecord("tile_notes", 1, "tile 2", false);
  EXPECT_TRUE(joined(a, b).ok());
  b = a;
  b.offset[0] = 1.0e6;
  for (double& s : b.scale) s = 1e-4;
  expect_refused(joined(a, b), "do not fit LAS's 32-bit integers");
  a.format = 4;
  b = a;
  expect_refused(joined(a, b),
                 "refused_a.las' (point format 4) point into their own file's "
                 "waveform data");
}

// Tiles of other LAS versions and point formats are joined in the header of the first of the
// highest version, in the point format that holds every field of theirs.
TEST(LasCleaningTest, TilesOfOtherVersionsAndFormatsJoinInAFormatHoldingEveryField) {
  const std::vector<LasPoint> points = VariedPoints(3);
  // The tiles, each of `points`; the joined file, and how they were joined.
  const auto join = [&](const std::vector<std::string>& tiles, LasJoin* how) {
    const std::string written = TempPath("joined_formats.las");
    const absl::Status status = WriteCleanedLas(tiles, std::vector<bool>(3 * tiles.size(), false),
                                                LasOutlierRecords::kLeftOut, written, {}, how);
    EXPECT_TRUE(status.ok()) << status;
    return ReadBytes(written);
  };
  LasLayout gps, colour, extended;
  gps.format = 1;
  colour.format = 2;
  extended.version_minor = 4;
  extended.format = 6;
  extended.vlrs = LasVariableLengthRecord("tile_notes", 1, "LAS 1.4 tile", false);
  extended.vlr_count = 1;
  const std::string gps_tile = TempPath("gps.las"), colour_tile = TempPath("colour.las"),
                    extended_tile = TempPath("extended.las");
  WriteBytes(gps_tile, LasFile(gps, points));
  // The colour tile's scan angle rank: 25 degrees.
  std::string colour_bytes = LasFile(colour, points);
  for (size_t i = 0; i < 3; ++i) colour_bytes[227 + 26 * i + 16] = 25;
  WriteBytes(colour_tile, colour_bytes);
  WriteBytes(extended_tile, LasFile(extended, points));

  // LAS 1.2's formats 1 (GPS time) and 2 (colour): format 3, the fields a tile lacks zero.
  LasJoin how;
  const std::string legacy = join({gps_tile, colour_tile}, &how);
  EXPECT_EQ(how.point_format, 3);
  EXPECT_EQ(how.version_minor, 2);
  EXPECT_EQ(how.header_source, 0u);
  EXPECT_TRUE(how.converted);
  ASSERT_EQ(legacy.size(), 227 + 6 * 34u);
  EXPECT_EQ(legacy[104], 3);
  EXPECT_EQ(Field<uint16_t>(legacy, 105), 34);
  for (size_t i = 0; i < 6; ++i) {
    SCOPED_TRACE(absl::StrCat("record ", i));
    const LasPoint& p = points[i % 3];
    const size_t at = 227 + 34 * i;
    EXPECT_EQ(Field<int32_t>(legacy, at), p.x);
    EXPECT_EQ(Field<uint16_t>(legacy, at + 12), p.intensity);
    EXPECT_EQ(legacy[at + 14] & 7, p.return_number);
    EXPECT_EQ(legacy[at + 15] & 0x1F, p.classification);
    EXPECT_EQ(legacy[at + 16], i < 3 ? 0 : 25) << "scan angle rank";
    EXPECT_EQ(Field<double>(legacy, at + 20), i < 3 ? p.gps_time : 0.0);
    EXPECT_EQ(Field<uint16_t>(legacy, at + 28), i < 3 ? 0 : p.red);
    EXPECT_EQ(Field<uint16_t>(legacy, at + 32), i < 3 ? 0 : p.blue);
  }

  // With LAS 1.4's format 6 among them: format 7, in the LAS 1.4 tile's header and with its
  // variable-length records; the legacy returns, classes and scan angles as LAS 1.4 holds them.
  const std::string joined = join({colour_tile, extended_tile}, &how);
  EXPECT_EQ(how.point_format, 7);
  EXPECT_EQ(how.version_minor, 4);
  EXPECT_EQ(how.header_source, 1u);
  const std::string extended_bytes = ReadBytes(extended_tile);
  const size_t first = 375 + extended.vlrs.size();
  ASSERT_EQ(joined.size(), first + 6 * 36);
  EXPECT_EQ(joined.substr(375, extended.vlrs.size()), extended.vlrs);
  EXPECT_EQ(joined[104], 7);
  EXPECT_EQ(Field<uint64_t>(joined, 247), 6u);
  EXPECT_EQ(Field<uint32_t>(joined, 107), 0u) << "no legacy count for format 7";
  for (size_t i = 0; i < 6; ++i) {
    SCOPED_TRACE(absl::StrCat("record ", i));
    const LasPoint& p = points[i % 3];
    const size_t at = first + 36 * i;
    EXPECT_EQ(Field<int32_t>(joined, at + 4), p.y);
    EXPECT_EQ(joined[at + 14], static_cast<char>(p.return_number | p.returns << 4));
    EXPECT_EQ(joined[at + 16], static_cast<char>(p.classification));
    // 25 degrees in steps of 0.006 degrees.
    EXPECT_EQ(Field<int16_t>(joined, at + 18), i < 3 ? 4167 : 0);
    EXPECT_EQ(Field<double>(joined, at + 22), i < 3 ? 0.0 : p.gps_time);
    EXPECT_EQ(Field<uint16_t>(joined, at + 30), i < 3 ? p.red : 0);
  }
  // The LAS 1.4 tile's records but for the colour they gain: byte for byte.
  EXPECT_EQ(joined.substr(first + 3 * 36, 30), extended_bytes.substr(first, 30));
  const absl::StatusOr<PointCloud> read = ReadPointCloud(TempPath("joined_formats.las"));
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->size(), 6u);
  EXPECT_EQ(read->colors.size(), 6u);

  // Tiles of one format: no record converted.
  join({gps_tile, gps_tile}, &how);
  EXPECT_FALSE(how.converted);
  EXPECT_EQ(how.point_format, 1);

  // GPS times are of one kind in a file (the header's global encoding, bit 0: adjusted
  // standard GPS time, else GPS week time): the joined header says the kind of the tile that
  // has them; tiles of both kinds are refused.
  std::string standard_bytes = LasFile(gps, points);
  standard_bytes[6] = 1;
  const std::string standard_tile = TempPath("standard_time.las");
  WriteBytes(standard_tile, standard_bytes);
  EXPECT_EQ(join({colour_tile, standard_tile}, &how)[6], 1);
  EXPECT_EQ(how.header_source, 0u);
  const absl::Status mixed_times =
      WriteCleanedLas({gps_tile, standard_tile}, std::vector<bool>(6, false),
                      LasOutlierRecords::kLeftOut, TempPath("mixed_times.las"));
  EXPECT_EQ(mixed_times.code(), absl::StatusCode::kFailedPrecondition) << mixed_times;
  EXPECT_THAT(std::string(mixed_times.message()),
              HasSubstr("standard_time.las' holds adjusted standard GPS time and '" + gps_tile +
                        "' GPS week time"));
}

// LAZ tiles are cleaned and joined a chunk at a time, and written a few megabytes of records at
// a time, compressed or not: the file is the one cleaned from the LAS files they compress, or
// that file compressed, byte for byte.
TEST(LasCleaningTest, LazTilesCleanAndJoinAsTheLasFilesTheyCompress) {
  // LAS 1.4 tiles of format 7 with a coordinate system and an extended record: 130,000 records
  // of 36 bytes, more than one block of records given to the writer, in chunks of 9,000.
  testing::LasScan scan = testing::Las14Scan(7, 70000);
  const std::string las_a = testing::ScanLasFile(scan);
  scan.records = 60000;
  scan.seed = 2;
  const std::string las_b = testing::ScanLasFile(scan);
  const std::string a = TempPath("lazjoin_a.las"), b = TempPath("lazjoin_b.las");
  const std::string a_laz = TempPath("lazjoin_a.laz"), b_laz = TempPath("lazjoin_b.laz");
  WriteBytes(a, las_a);
  WriteBytes(b, las_b);
  WriteBytes(a_laz, *io_internal::CompressLas(las_a, {9000}));
  WriteBytes(b_laz, *io_internal::CompressLas(las_b, {9000}));
  const absl::StatusOr<PointCloud> points_a = ReadPointCloud(a), points_b = ReadPointCloud(b);
  ASSERT_TRUE(points_a.ok() && points_b.ok());
  std::vector<bool> outliers(points_a->size() + points_b->size());
  for (size_t i = 0; i < outliers.size(); i += 7) outliers[i] = true;

  for (const LasOutlierRecords records :
       {LasOutlierRecords::kLeftOut, LasOutlierRecords::kClassifiedAsNoise}) {
    SCOPED_TRACE(records == LasOutlierRecords::kLeftOut ? "left out" : "as noise");
    const std::string from_las = TempPath("lazjoin_from_las.las");
    ASSERT_TRUE(WriteCleanedLas({a, b}, outliers, records, from_las).ok());
    const std::string expected = ReadBytes(from_las);
    ASSERT_GT(expected.size(), 375u + 100000u * 36u);
    const std::string expected_laz = *io_internal::CompressLas(expected);
    for (const std::vector<std::string>& sources :
         std::vector<std::vector<std::string>>{{a_laz, b_laz}, {a_laz, b}}) {
      SCOPED_TRACE(sources.back());
      const std::string las = TempPath("lazjoin.las"), laz = TempPath("lazjoin.laz");
      LasJoin join;
      const absl::Status to_las = WriteCleanedLas(sources, outliers, records, las, {}, &join);
      ASSERT_TRUE(to_las.ok()) << to_las;
      EXPECT_EQ(join.point_format, 7);
      EXPECT_TRUE(ReadBytes(las) == expected);
      const absl::Status to_laz = WriteCleanedLas(sources, outliers, records, laz);
      ASSERT_TRUE(to_laz.ok()) << to_laz;
      EXPECT_TRUE(ReadBytes(laz) == expected_laz);
    }
  }
}

TEST(LasCleaningTest, CopiesKeepEveryRecordCompressedOrNot) {
  LasLayout layout;
  layout.version_minor = 3;
  layout.format = 3;
  std::vector<LasPoint> points;
  for (int i = 0; i < 500; ++i) {
    LasPoint p{i * 13, -i * 7, i % 50};
    p.classification = i % 25 == 0 ? 7 : 2;  // Noise and withheld records are copied too.
    p.withheld = i % 40 == 1;
    p.gps_time = 1000 + 0.01 * i;
    p.red = static_cast<uint16_t>(i * 100);
    points.push_back(p);
  }
  const std::string source = TempPath("tile.las");
  WriteBytes(source, LasFile(layout, points));
  const std::string laz = TempPath("tile.laz"), back = TempPath("back.las");
  const absl::StatusOr<LasCopy> compressed = CopyLas(source, laz);
  ASSERT_TRUE(compressed.ok()) << compressed.status();
  EXPECT_EQ(compressed->records, 500u);
  EXPECT_EQ(compressed->read_bytes, ReadBytes(source).size());
  EXPECT_EQ(compressed->written_bytes, ReadBytes(laz).size());
  EXPECT_LT(compressed->written_bytes, compressed->read_bytes / 2);
  ASSERT_TRUE(CopyLas(laz, back).ok());
  EXPECT_TRUE(ReadBytes(back) == ReadBytes(source));
  const std::string again = TempPath("again.laz");
  ASSERT_TRUE(CopyLas(laz, again).ok());
  EXPECT_TRUE(ReadBytes(again) == ReadBytes(laz));

  // LAS 1.4's formats are copied so too; waveform records are not written as LAZ.
  layout.version_minor = 4;
  layout.format = 6;
  const std::string format6 = TempPath("format6.las"), format6_laz = TempPath("format6.laz");
  WriteBytes(format6, LasFile(layout, points));
  ASSERT_TRUE(CopyLas(format6, format6_laz).ok());
  ASSERT_TRUE(CopyLas(format6_laz, back).ok());
  EXPECT_TRUE(ReadBytes(back) == ReadBytes(format6));
  layout.format = 9;
  const std::string format9 = TempPath("format9.las");
  WriteBytes(format9, LasFile(layout, points));
  EXPECT_EQ(CopyLas(format9, TempPath("format9.laz")).status().code(),
            absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(CopyLas(TempPath("missing.las"), back).status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(CopyLas(source, TempPath("tile.xyz")).status().message()),
              HasSubstr("is not a .las or .laz file"));
}

// A copy is written a wave of chunks at a time: a source found broken before the first byte
// leaves the file at the path as it was, one found broken on the way leaves no part of a file.
TEST(LasCleaningTest, ACopyOfABrokenSourceLeavesNoPartOfAFile) {
  testing::LasScan scan;
  scan.format = 1;
  scan.records = 20000;
  const std::string las = testing::ScanLasFile(scan);
  std::string laz = *io_internal::CompressLas(las, {900});  // 23 chunks.
  // Garbage over chunks halfway through the file, after the first waves were written.
  const size_t middle = (Field<uint32_t>(laz, 96) + laz.size()) / 2;
  ASSERT_GT(laz.size(), middle + 20000);
  for (size_t i = middle; i < middle + 20000; i += 3) laz[i] = static_cast<char>(i);
  const std::string corrupt = TempPath("corrupt.laz"), output = TempPath("copied.las");
  WriteBytes(corrupt, laz);
  WriteBytes(output, "what was there");
  const absl::Status broken = CopyLas(corrupt, output).status();
  EXPECT_EQ(broken.code(), absl::StatusCode::kInvalidArgument) << broken;
  EXPECT_THAT(std::string(broken.message()), HasSubstr("'" + corrupt + "': "));
  EXPECT_THAT(std::string(broken.message()), HasSubstr("chunk"));
  EXPECT_FALSE(std::filesystem::exists(output));

  const std::string truncated = TempPath("truncated.las");
  WriteBytes(truncated, las.substr(0, 100));
  WriteBytes(output, "what was there");
  for (const std::string& path : {output, TempPath("copied.laz")}) {
    const absl::Status refused = CopyLas(truncated, path).status();
    EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument) << refused;
    EXPECT_THAT(std::string(refused.message()), HasSubstr("'" + truncated + "': "));
  }
  EXPECT_EQ(ReadBytes(output), "what was there");
  EXPECT_FALSE(std::filesystem::exists(TempPath("copied.laz")));
}

// A file copied or cleaned onto itself (under another spelling of its path, too) is read whole
// before it is replaced: writing it would cut short the mapping it is read through.
TEST(LasCleaningTest, AFileCopiedOrCleanedOntoItselfKeepsItsRecords) {
  testing::LasScan scan;
  scan.format = 3;
  scan.records = 3000;
  const std::string las = testing::ScanLasFile(scan);
  const std::string path = TempPath("itself.las");
  const std::string other_spelling = std::filesystem::path(path).parent_path().string() + "/./" +
                                     std::filesystem::path(path).filename().string();
  WriteBytes(path, las);
  const absl::StatusOr<LasCopy> copied = CopyLas(path, other_spelling);
  ASSERT_TRUE(copied.ok()) << copied.status();
  EXPECT_EQ(copied->records, 3000u);
  EXPECT_TRUE(ReadBytes(path) == las);

  const std::string laz = TempPath("itself.laz");
  WriteBytes(laz, *io_internal::CompressLas(las, {700}));
  ASSERT_TRUE(CopyLas(laz, laz).ok());  // Compressed again, in chunks of 50,000.
  EXPECT_TRUE(*io_internal::DecompressLaz(ReadBytes(laz)) == las);

  const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
  ASSERT_TRUE(read.ok()) << read.status();
  std::vector<bool> outliers(read->size(), false);
  outliers[5] = true;
  const absl::Status in_place =
      WriteCleanedLas({path}, outliers, LasOutlierRecords::kLeftOut, path);
  ASSERT_TRUE(in_place.ok()) << in_place;
  const absl::StatusOr<PointCloud> cleaned = ReadPointCloud(path);
  ASSERT_TRUE(cleaned.ok()) << cleaned.status();
  EXPECT_EQ(cleaned->size(), read->size() - 1);
}

TEST(LasCleaningTest, FlagsThatDoNotFitAndSourcesThatAreNoLasFileAreRefused) {
  LasLayout layout;
  std::vector<LasPoint> points = VariedPoints(4);
  points[1].classification = 18;  // High noise: not one of the points to flag.
  const std::string source = TempPath("source.las");
  WriteBytes(source, LasFile(layout, points));
  const std::string written = TempPath("written.las");

  // Found once records were written: no part of a file is left.
  WriteBytes(written, "what was there");
  absl::Status status =
      WriteCleanedLas({source}, {true, true, true, true}, LasOutlierRecords::kLeftOut, written);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("4 flags for the 3 points read from '" + source +
                        "' (withheld, noise or other classes left out)"));
  EXPECT_THAT(std::string(status.message()), HasSubstr("source.las"));
  EXPECT_FALSE(std::filesystem::exists(written));

  status = WriteCleanedLas({source}, {true, true, true}, LasOutlierRecords::kLeftOut, written);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("no point of '" + source + "' is kept"));

  const std::string text = TempPath("points.xyz");
  WriteBytes(text, "0 0 0\n1 1 1\n");
  status = WriteCleanedLas({text}, {false, false}, LasOutlierRecords::kLeftOut, written);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("is not a .las or .laz file"));

  // Found before any record: the file at the path stays as it was.
  const std::string fake = TempPath("fake.las");
  WriteBytes(fake, std::string(300, 'x'));
  WriteBytes(written, "what was there");
  status = WriteCleanedLas({fake}, {false}, LasOutlierRecords::kClassifiedAsNoise, written);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("no LASF signature"));
  EXPECT_EQ(ReadBytes(written), "what was there");
  LasLayout waveform;
  waveform.version_minor = 4;
  waveform.format = 9;
  const std::string format9 = TempPath("format9.las"), written_laz = TempPath("written.laz");
  WriteBytes(format9, LasFile(waveform, VariedPoints(3)));
  WriteBytes(written_laz, "what was there");
  status =
      WriteCleanedLas({format9}, {false, true, false}, LasOutlierRecords::kLeftOut, written_laz);
  EXPECT_EQ(status.code(), absl::StatusCode::kFailedPrecondition) << status;
  EXPECT_THAT(std::string(status.message()), HasSubstr("writing point format 9"));
  EXPECT_EQ(ReadBytes(written_laz), "what was there");

  status =
      WriteCleanedLas({TempPath("missing.las")}, {false}, LasOutlierRecords::kLeftOut, written);
  EXPECT_EQ(status.code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace neuralmesh
