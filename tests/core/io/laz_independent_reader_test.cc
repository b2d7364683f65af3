// LAZ files read by an independent decoder: laz-perf, the LASzip-compatible codec PDAL uses,
// compiled to WebAssembly (tests/tools/laz_reader.mjs, installed from npm by
// scripts/install-deps.sh). The LAZ files neuralmesh writes must give laz-perf every record of
// the LAS file they compress, byte for byte: each point format 0-3 and 6-8, extra bytes,
// several chunks, scanner channels, random records among scan-like ones, LAS 1.4, and the files
// WritePointCloud writes.
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "core/io/internal/laz.h"
#include "core/io/point_cloud_io.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/las_scan.h"

namespace neuralmesh {
namespace {

using io_test::ReadBytes;
using io_test::TempPath;
using io_test::WriteBytes;
using testing::LasScan;
using testing::ScanLasFile;

struct LazPerfRead {
  std::string summary;  // "FORMAT LENGTH COUNT".
  std::string records;
};

// What laz-perf reads from `path`; fails the test when it cannot run or refuses the file.
LazPerfRead ReadWithLazPerf(const std::string& path) {
  const std::string records = path + ".records";
  const io_test::CommandResult run =
      io_test::RunCommand("node tests/tools/laz_reader.mjs '" + path + "' '" + records + "' 2>&1");
  EXPECT_EQ(run.status, 0) << "laz-perf (npm ci in tests/tools: scripts/install-deps.sh) failed: "
                           << run.output;
  if (run.status != 0) return {};
  return {std::string(absl::StripAsciiWhitespace(run.output)), ReadBytes(records)};
}

// The LAS file's point records.
std::string RecordsOf(const std::string& las) {
  const uint64_t count =
      las[25] == 4 ? io_test::Field<uint64_t>(las, 247) : io_test::Field<uint32_t>(las, 107);
  return las.substr(io_test::Field<uint32_t>(las, 96), count * io_test::Field<uint16_t>(las, 105));
}

void ExpectLazPerfReadsTheRecords(const LasScan& scan, uint32_t chunk_size) {
  const std::string las = ScanLasFile(scan);
  const absl::StatusOr<std::string> laz = io_internal::CompressLas(las, {chunk_size});
  ASSERT_TRUE(laz.ok()) << laz.status();
  const std::string path = TempPath("scan.laz");
  WriteBytes(path, *laz);
  const LazPerfRead read = ReadWithLazPerf(path);
  EXPECT_EQ(read.summary, absl::StrCat(scan.format, " ", las[105] & 0xFF, " ", scan.records));
  const std::string records = RecordsOf(las);
  ASSERT_EQ(read.records.size(), records.size());
  // The first record that differs, if one does.
  const size_t length = records.size() / scan.records;
  for (size_t i = 0; i < scan.records; ++i) {
    ASSERT_EQ(read.records.substr(i * length, length), records.substr(i * length, length))
        << "record " << i;
  }
}

TEST(LazIndependentReaderTest, LazPerfReadsEveryRecordOfEachPointFormat) {
  for (int format = 0; format <= 3; ++format) {
    for (const int extra : {0, 2}) {
      for (const uint32_t chunk_size : {50000u, 700u}) {
        SCOPED_TRACE(
            absl::StrCat("format ", format, ", ", extra, " extra bytes, chunks of ", chunk_size));
        LasScan scan;
        scan.format = format;
        scan.extra_bytes = extra;
        scan.records = 3000;
        scan.random_every = 53;
        scan.seed = 100 + format;
        ExpectLazPerfReadsTheRecords(scan, chunk_size);
      }
    }
  }
}

TEST(LazIndependentReaderTest, LazPerfReadsEveryRecordOfLas14PointFormats) {
  for (int format = 6; format <= 8; ++format) {
    for (const int channels : {1, 4}) {
      SCOPED_TRACE(absl::StrCat("format ", format, ", ", channels, " scanner channels"));
      LasScan scan;
      scan.format = format;
      scan.scanner_channels = channels;
      scan.extra_bytes = format == 7 ? 0 : 2;
      scan.records = 3000;
      scan.random_every = 61;
      scan.seed = 200 + format * 10 + channels;
      ExpectLazPerfReadsTheRecords(scan, format == 8 ? 50000 : 700);
    }
  }
}

TEST(LazIndependentReaderTest, LazPerfReadsLas14FilesAndLongScans) {
  ExpectLazPerfReadsTheRecords(testing::Las14Scan(/*format=*/3, 2000), 50000);
  // Two chunks of the default size, GPS times switching sequences, no random records.
  LasScan longer;
  longer.format = 1;
  longer.records = 120000;
  ExpectLazPerfReadsTheRecords(longer, 50000);
}

TEST(LazIndependentReaderTest, WrittenPointCloudsGiveLazPerfTheirRecords) {
  PointCloud cloud = io_test::RandomCloud(5000, 5, /*normals=*/false, /*weights=*/false);
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud.colors.push_back({static_cast<uint8_t>(i), static_cast<uint8_t>(i * 7), 200});
  }
  const std::string las_path = TempPath("cloud.las"), laz_path = TempPath("cloud.laz");
  ASSERT_TRUE(WritePointCloud(cloud, las_path).ok());
  ASSERT_TRUE(WritePointCloud(cloud, laz_path).ok());
  const LazPerfRead read = ReadWithLazPerf(laz_path);
  EXPECT_EQ(read.summary, "2 26 5000");
  EXPECT_TRUE(read.records == RecordsOf(ReadBytes(las_path)));
}

}  // namespace
}  // namespace neuralmesh
