// Leica PTX scans (core/io/internal/ptx.h) through ReadPointCloud: several scans moved into
// their registered, georeferenced frame by their transformations, empty grid cells left out,
// colours, and malformed files refused with what is wrong; clouds written as one scan and read
// back.
#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/point_cloud_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"

namespace neuralmesh {
namespace {

using io_test::ReadCloudFrom;
using io_test::TempPath;
using ::testing::HasSubstr;

// A scan's header: the grid, the scanner's pose (which readers take from the matrix), and the
// matrix as PTX writes it, a column a line, the translation last.
std::string Header(int columns, int rows, const std::string& matrix_columns) {
  return absl::StrCat(columns, "\n", rows, "\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n", matrix_columns);
}

constexpr char kIdentityAt[] = "1 0 0 0\n0 1 0 0\n0 0 1 0\n500100 4100200 0 1\n";
// 90 degrees about z (x goes to y, y to -x), then a translation.
constexpr char kTurnedAt[] = "0 1 0 0\n-1 0 0 0\n0 0 1 0\n500150 4100250 5 1\n";

TEST(PtxIoTest, ScansAreMovedIntoTheirRegisteredFrameAndEmptyCellsLeftOut) {
  const std::string ptx =
      absl::StrCat(Header(2, 2, kIdentityAt), "1 2 3 0.5\n0 0 0 0.5\n-1.5 0.25 8 0.25\n\n4 5 6 1\n",
                   Header(2, 1, kTurnedAt), "1 2 3 0.5\n10 0 -1 0.75\n");
  PointsLeftOut left_out;
  const absl::StatusOr<PointCloud> cloud = ReadCloudFrom("two_scans.ptx", ptx, &left_out);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(cloud->origin, (Origin{500000, 4100000, 0}));
  const std::vector<Vec3f> expected = {Vec3f(101, 202, 3), Vec3f(98.5f, 200.25f, 8),
                                       Vec3f(104, 205, 6), Vec3f(148, 251, 8), Vec3f(150, 260, 4)};
  EXPECT_EQ(cloud->positions, expected);
  EXPECT_TRUE(cloud->colors.empty());
  EXPECT_TRUE(cloud->weights.empty()) << "intensity is not a confidence";
  EXPECT_EQ(left_out.invalid, 1u);
}

TEST(PtxIoTest, ColoursAreTakenWhenEveryPointHasThem) {
  const std::string identity = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  const std::string colored = absl::StrCat(Header(1, 3, identity), "1 0 0 0.5 255 0 128\n",
                                           "0 0 0 0.5 0 0 0\n", "0 1 0 0.5 1 2 3\n");
  const absl::StatusOr<PointCloud> cloud = ReadCloudFrom("colored.ptx", colored);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(cloud->positions, (std::vector<Vec3f>{Vec3f(1, 0, 0), Vec3f(0, 1, 0)}));
  EXPECT_EQ(cloud->colors, (std::vector<Rgb>{{255, 0, 128}, {1, 2, 3}}));
  EXPECT_EQ(cloud->origin, kNoOrigin);

  // A second scan without colours: the file's colours are left out.
  const absl::StatusOr<PointCloud> mixed =
      ReadCloudFrom("mixed.ptx", absl::StrCat(colored, Header(1, 1, identity), "0 0 1 0.5\n"));
  ASSERT_TRUE(mixed.ok()) << mixed.status();
  EXPECT_EQ(mixed->size(), 3u);
  EXPECT_TRUE(mixed->colors.empty());
}

// A georeferenced, coloured cloud written as one scan (WritePointCloud) reads back to the same
// points and colours; each point's line carries an intensity of 0.5.
TEST(PtxIoTest, WrittenCloudsReadBackToTheSamePointsAndColours) {
  PointCloud cloud;
  cloud.origin = {500000, 4100000, 0};
  cloud.positions = {Vec3f(100.25f, 200.5f, 3), Vec3f(-7.125f, 0.375f, -1), Vec3f(1e-3f, 2, 3)};
  cloud.colors = {{255, 0, 10}, {1, 2, 3}, {40, 50, 60}};
  const std::string path = TempPath("written.ptx");
  ASSERT_TRUE(WritePointCloud(cloud, path).ok());
  const std::string text = io_test::ReadBytes(path);
  EXPECT_TRUE(absl::StartsWith(text, "3\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n"
                                     "0 1 0 0\n0 0 1 0\n0 0 0 1\n500100.25 4100200.5 3 0.5 "
                                     "255 0 10\n"))
      << text;
  const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
  ASSERT_TRUE(read.ok()) << read.status();
  // The reader picks an origin of its own; the points stay where they were, to a float's
  // resolution about that origin.
  ASSERT_EQ(read->size(), cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(read->origin[c] + read->positions[i][c],
                  cloud.origin[c] + cloud.positions[i][c], 1e-4)
          << "point " << i << ", axis " << c;
    }
  }
  EXPECT_EQ(read->colors, cloud.colors);
}

// PTX reserves (0, 0, 0) for an empty cell of its grid: a point there is written in a scan of
// its own, translated by 1 in x, where it lies at (-1, 0, 0); the points read back whole and
// in their order.
TEST(PtxIoTest, APointAtZeroIsWrittenInAScanOfItsOwnSoThatItIsKept) {
  PointCloud cloud;
  cloud.positions = {Vec3f(2.5f, 1, 0), Vec3f(0, 0, 0), Vec3f(-3.25f, 0, 1)};
  const std::string path = TempPath("at_zero.ptx");
  ASSERT_TRUE(WritePointCloud(cloud, path).ok());
  const std::string axes = "1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n";
  EXPECT_EQ(io_test::ReadBytes(path),
            "1\n1\n0 0 0\n" + axes + "0 0 0 1\n2.5 1 0 0.5\n" +  //
                "1\n1\n1 0 0\n" + axes + "1 0 0 1\n-1 0 0 0.5\n" +    //
                "1\n1\n0 0 0\n" + axes + "0 0 0 1\n-3.25 0 1 0.5\n");
  PointsLeftOut left_out;
  const absl::StatusOr<PointCloud> read = ReadPointCloud(path, &left_out);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->positions, cloud.positions);
  EXPECT_EQ(left_out.invalid, 0u);
}

TEST(PtxIoTest, MalformedFilesAreRefusedWithWhatIsWrong) {
  const std::string identity = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  const struct {
    const char* what;
    std::string text;
    const char* message;
  } cases[] = {
      {"columns", "abc\n1\n",
       "line 1: a scan begins with its number of columns, one "
       "non-negative integer, not 'abc'"},
      {"short header", "1\n1\n0 0 0\n1 0 0\n",
       "the file ends within a scan's header, before "
       "its scanner's Y axis"},
      {"matrix", Header(1, 1, "1 0 0\n"),
       "line 7: the transformation matrix takes 4 numbers, "
       "not 3"},
      {"NaN matrix", Header(1, 1, "1 0 0 0\n0 1 0 0\n0 0 nan 0\n0 0 0 1\n") + "1 1 1 1\n",
       "line 9: the transformation matrix has 'nan', not a finite number"},
      {"values", Header(1, 1, identity) + "1 2 3 4 5\n",
       "line 11: a point takes x y z, x y z intensity or x y z intensity r g b, not 5 values"},
      {"coordinate", Header(1, 1, identity) + "1 two 3 0.5\n",
       "line 11: coordinate 'two' is not a finite number"},
      {"colour", Header(1, 1, identity) + "1 2 3 0.5 256 0 0\n",
       "line 11: colour '256' is not a level from 0 to 255"},
      {"short scan", Header(2, 1, identity) + "1 2 3 0.5\n",
       "scan 1 ends after 1 of its 2 x 1 points"},
      {"all empty", Header(2, 1, identity) + "0 0 0 0.5\n0 0 0 0.5\n",
       "all 2 points are empty cells of their grids (0 0 0)"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const absl::StatusOr<PointCloud> cloud = ReadCloudFrom("bad.ptx", c.text);
    ASSERT_FALSE(cloud.ok());
    EXPECT_EQ(cloud.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(cloud.status().message()), HasSubstr(c.message));
    EXPECT_THAT(std::string(cloud.status().message()), HasSubstr("bad.ptx"));
  }
  EXPECT_TRUE(IsReadablePointCloudExtension("scan.PTX"));
}

}  // namespace
}  // namespace neuralmesh
