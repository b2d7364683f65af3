#include "core/io/point_text_stream.h"

#include <unistd.h>

#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/time/time.h"
#include "gtest/gtest.h"
#include "tests/testing/pipe.h"

namespace neuralmesh {
namespace {

using testing::Pipe;

TEST(PointTextStreamTest, ReadsPointsAsTheirLinesComplete) {
  Pipe pipe;
  PointTextStream stream(pipe.read_end(), "standard input");
  StreamedPoints read;
  std::vector<Vec3>& points = read.positions;
  absl::StatusOr<bool> more = stream.Read(absl::Milliseconds(10), &read);
  ASSERT_TRUE(more.ok()) << more.status();
  EXPECT_TRUE(*more) << "nothing arrived yet: the stream goes on";
  EXPECT_TRUE(points.empty());

  pipe.Write("# x y z\n1 2 3\n4.5,5.5,6.5,200,10,10\r\n\n7 8");
  more = stream.Read(absl::Milliseconds(100), &read);
  ASSERT_TRUE(more.ok()) << more.status();
  EXPECT_TRUE(*more);
  ASSERT_EQ(points.size(), 2u) << "the third line has not ended";
  EXPECT_EQ(points[1], Vec3(4.5, 5.5, 6.5));
  pipe.Write(" 9\n500000.25\t4100000.5\t80 # a comment\n10 11 12");
  pipe.CloseWriteEnd();
  while (*more) {
    more = stream.Read(absl::Milliseconds(100), &read);
    ASSERT_TRUE(more.ok()) << more.status();
  }
  ASSERT_EQ(points.size(), 5u) << "the last line is taken at the end without its newline";
  EXPECT_EQ(points[2], Vec3(7, 8, 9));
  EXPECT_EQ(points[3], Vec3(500000.25, 4100000.5, 80));
  EXPECT_EQ(points[4], Vec3(10, 11, 12));
  EXPECT_EQ(stream.lines(), 7u);
  EXPECT_TRUE(read.colors.empty()) << "further columns are ignored";
  more = stream.Read(absl::Milliseconds(10), &read);
  ASSERT_TRUE(more.ok());
  EXPECT_FALSE(*more);
}

// Reads what `text` holds, written at once and ended.
absl::StatusOr<StreamedPoints> ReadAll(absl::string_view text) {
  Pipe pipe;
  PointTextStream stream(pipe.read_end(), "standard input");
  pipe.Write(text);
  pipe.CloseWriteEnd();
  StreamedPoints read;
  for (absl::StatusOr<bool> more = true; *more;) {
    more = stream.Read(absl::Milliseconds(100), &read);
    if (!more.ok()) return more.status();
  }
  return read;
}

// A header comment before the first point naming the columns as an XYZ file's does brings the
// colours it names; a header of another number of columns, or one after the first point, is a
// comment like any other.
TEST(PointTextStreamTest, AHeaderNamingColourColumnsBringsTheColours) {
  absl::StatusOr<StreamedPoints> read =
      ReadAll("# a scan\n# x y z intensity r g b\n1 2 3 0.5 255 128 0\n4 5 6 0.7 10 20 30\n");
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), 2u);
  ASSERT_EQ(read->colors.size(), 2u);
  EXPECT_EQ(read->colors[0], (std::array<float, 3>{255, 128, 0}));
  EXPECT_EQ(read->colors[1], (std::array<float, 3>{10, 20, 30}));
  EXPECT_EQ(read->positions[1], Vec3(4, 5, 6));

  read = ReadAll("//X,Y,Z,R,G,B\n1,2,3,0.5,1,0\n");  // CloudCompare's, with fractions.
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->colors.size(), 1u);
  EXPECT_EQ(read->colors[0], (std::array<float, 3>{0.5f, 1, 0}));
  Pipe pipe;
  PointTextStream stream(pipe.read_end(), "standard input");
  EXPECT_EQ(stream.ColorScale(1), 1) << "fractions";
  EXPECT_EQ(stream.ColorScale(200), 255) << "levels";

  for (const char* no_colours :
       {"# x y z r g b\n1 2 3\n", "1 2 3 4 5 6\n# x y z r g b\n7 8 9 1 2 3\n",
        "# x y z nx ny nz\n1 2 3 0 0 1\n"}) {
    read = ReadAll(no_colours);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_TRUE(read->colors.empty()) << no_colours;
    EXPECT_FALSE(read->positions.empty());
  }

  read = ReadAll("# x y z r g b\n1 2 3 4 5 6\n7 8 9 10 11\n");
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(),
            "standard input, line 3: '7 8 9 10 11' has no blue in column 6, where the header "
            "names it (a finite number)");
}

TEST(PointTextStreamTest, ALineThatIsNoPointIsAnErrorNamingIt) {
  for (const char* bad : {"1 2\n", "1 2 x\n", "1 2 inf\n", "nan 1 2\n"}) {
    Pipe pipe;
    PointTextStream stream(pipe.read_end(), "standard input");
    pipe.Write(std::string("1 2 3\n") + bad);
    StreamedPoints read;
    absl::StatusOr<bool> more = stream.Read(absl::Milliseconds(100), &read);
    ASSERT_FALSE(more.ok()) << bad;
    EXPECT_EQ(more.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_TRUE(absl::StrContains(more.status().message(), "standard input, line 2: '"))
        << more.status();
  }
  Pipe pipe;
  PointTextStream stream(pipe.read_end(), "the scanner");
  StreamedPoints read;
  absl::StatusOr<bool> more = true;
  for (int i = 0; i < 40 && more.ok(); ++i) {
    pipe.Write(std::string(1 << 15, '1'));
    more = stream.Read(absl::Milliseconds(100), &read);
  }
  ASSERT_FALSE(more.ok()) << "a line without an end is no text of points";
  EXPECT_TRUE(absl::StrContains(more.status().message(), "the scanner, line 1: over"))
      << more.status();
}

TEST(PointTextStreamTest, TheOriginKeepsGeoreferencedPointsPrecise) {
  BoundingBox box;
  box.Extend(Vec3(500123.5, 4100456.25, 80));
  box.Extend(Vec3(500133.5, 4100466.25, 95));
  EXPECT_EQ(OriginOfStreamedPoints(box), (Origin{500000, 4100000, 0}));
  BoundingBox small;
  small.Extend(Vec3(-1, -1, -1));
  small.Extend(Vec3(1, 1, 1));
  EXPECT_EQ(OriginOfStreamedPoints(small), kNoOrigin);
}

}  // namespace
}  // namespace neuralmesh
