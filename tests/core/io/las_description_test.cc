// DescribeLasFile: what a LAS or LAZ file's header, records and compression say, for
// `neuralmesh stats`.
#include "core/io/las_description.h"

#include <string>
#include <vector>

#include "core/io/internal/laz.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/las_file.h"

namespace neuralmesh {
namespace {

using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;

TEST(LasDescriptionTest, HeaderRecordsAndCompressionAreDescribed) {
  testing::LasLayout layout;
  layout.version_minor = 2;
  layout.format = 1;
  layout.record_length = 28 + 4;
  layout.scale[2] = 0.001;
  layout.offset[0] = 500000;
  layout.vlrs = testing::LasVariableLengthRecord("LASF_Projection", 34735, std::string(16, '\1'),
                                                 /*extended=*/false);
  layout.vlr_count = 1;
  std::vector<testing::LasPoint> points(6, testing::LasPoint{1, 2, 3});
  points[0].classification = 2;
  points[1].classification = 2;
  points[2].classification = 7;
  points[5].withheld = true;
  std::string las = testing::LasFile(layout, points);
  las[6] = 1;  // Adjusted standard GPS time.
  const std::string las_path = TempPath("described.las"), laz_path = TempPath("described.laz");
  WriteBytes(las_path, las);
  WriteBytes(laz_path, *io_internal::CompressLas(las, {4}));

  for (const std::string& path : {las_path, laz_path}) {
    SCOPED_TRACE(path);
    const absl::StatusOr<LasDescription> described = DescribeLasFile(path);
    ASSERT_TRUE(described.ok()) << described.status();
    EXPECT_EQ(described->version_minor, 2);
    EXPECT_EQ(described->point_format, 1);
    EXPECT_EQ(described->record_length, 32u);
    EXPECT_EQ(described->extra_bytes, 4u);
    EXPECT_EQ(described->records, 6u);
    EXPECT_EQ(described->scale[2], 0.001);
    EXPECT_EQ(described->offset[0], 500000.0);
    EXPECT_EQ(described->coordinate_system, "GeoTIFF");
    EXPECT_TRUE(described->standard_gps_time);
    EXPECT_EQ(described->variable_length_records, 1u);
    EXPECT_EQ(described->withheld, 1u);
    ASSERT_EQ(described->records_by_class.size(), 256u);
    EXPECT_EQ(described->records_by_class[2], 2u);
    EXPECT_EQ(described->records_by_class[7], 1u);
    EXPECT_EQ(described->records_by_class[0], 3u);  // The withheld one among them.
    EXPECT_EQ(described->file_bytes, io_test::ReadBytes(path).size());
  }
  EXPECT_EQ(DescribeLasFile(las_path)->compression, "");
  EXPECT_EQ(DescribeLasFile(laz_path)->compression,
            "LASzip 2.2 (revision 0), pointwise chunks, item version 2, 2 chunks of up to 4 "
            "records");

  EXPECT_EQ(DescribeLasFile(TempPath("missing.las")).status().code(), absl::StatusCode::kNotFound);
  WriteBytes(TempPath("broken.laz"), io_test::ReadBytes(laz_path).substr(0, 400));
  const absl::Status broken = DescribeLasFile(TempPath("broken.laz")).status();
  EXPECT_EQ(broken.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(broken.message()), HasSubstr("broken.laz"));
  EXPECT_THAT(std::string(DescribeLasFile(TempPath("points.xyz")).status().message()),
              HasSubstr("is not a .las or .laz file"));
}

}  // namespace
}  // namespace neuralmesh
