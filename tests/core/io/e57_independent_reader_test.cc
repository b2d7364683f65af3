// E57 files read by an independent reader: web-e57, the Rust e57 crate compiled to WebAssembly
// (tests/tools/e57_reader.mjs, installed from npm by scripts/install-deps.sh). neuralmesh's
// written files must give web-e57 the points and colours that were written; the files that
// tests/testing/e57_file.h lays out (poses, spherical coordinates, invalid points, fields of 2
// to 64 bits split across packets) must give both readers the same points.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "core/io/point_cloud_io.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/e57_file.h"

namespace neuralmesh {
namespace {

using io_test::TempPath;
using testing::E57Field;
using testing::E57File;
using testing::E57Floats;
using testing::E57PackBits;
using testing::E57Scan;

struct ReferencePoint {
  std::array<double, 3> position;
  std::vector<int> color;  // Empty, or r g b.
};

// What web-e57 reads from `path`; fails the test when it cannot run or refuses the file.
std::vector<ReferencePoint> ReadWithWebE57(const std::string& path) {
  const io_test::CommandResult run =
      io_test::RunCommand("node tests/tools/e57_reader.mjs '" + path + "' XYZ 2>&1");
  EXPECT_EQ(run.status, 0) << "web-e57 (npm ci in tests/tools: scripts/install-deps.sh) failed: "
                           << run.output.substr(0, 2000);
  if (run.status != 0) return {};
  std::vector<ReferencePoint> points;
  for (absl::string_view line : absl::StrSplit(run.output, '\n', absl::SkipWhitespace())) {
    const std::vector<absl::string_view> tokens = absl::StrSplit(line, ' ', absl::SkipEmpty());
    ReferencePoint point;
    EXPECT_TRUE(tokens.size() == 3 || tokens.size() == 6) << line;
    for (size_t k = 0; k < tokens.size(); ++k) {
      double value = 0;
      EXPECT_TRUE(absl::SimpleAtod(tokens[k], &value)) << line;
      if (k < 3) {
        point.position[k] = value;
      } else {
        point.color.push_back(static_cast<int>(value));
      }
    }
    points.push_back(point);
  }
  return points;
}

// Both readers find the same points (to `tolerance`) and colours in the file at `path`.
void ExpectSamePoints(const std::string& path, double tolerance) {
  const absl::StatusOr<PointCloud> ours = ReadPointCloud(path);
  ASSERT_TRUE(ours.ok()) << ours.status();
  const std::vector<ReferencePoint> theirs = ReadWithWebE57(path);
  ASSERT_EQ(theirs.size(), ours->size());
  for (size_t i = 0; i < theirs.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(ours->origin[c] + ours->positions[i][c], theirs[i].position[c], tolerance)
          << "point " << i << " axis " << c;
    }
    if (!ours->colors.empty()) {
      ASSERT_EQ(theirs[i].color.size(), 3u) << "point " << i;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(ours->colors[i][c], theirs[i].color[c]) << i;
    }
  }
}

// Writes `cloud` to `name` and expects web-e57 to read its points, to `tolerance`, and its
// colours.
void ExpectWebE57ReadsWhatIsWritten(const PointCloud& cloud, const std::string& name,
                                    double tolerance) {
  const std::string path = TempPath(name);
  ASSERT_TRUE(WritePointCloud(cloud, path).ok());
  const std::vector<ReferencePoint> theirs = ReadWithWebE57(path);
  ASSERT_EQ(theirs.size(), cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(theirs[i].position[c], cloud.origin[c] + cloud.positions[i][c], tolerance)
          << "point " << i << " axis " << c;
    }
    ASSERT_EQ(theirs[i].color.size(), cloud.colors.empty() ? 0u : 3u) << "point " << i;
    for (size_t c = 0; c < theirs[i].color.size(); ++c) {
      EXPECT_EQ(theirs[i].color[c], cloud.colors[i][c]) << "point " << i;
    }
  }
  ExpectSamePoints(path, 2e-4);
}

TEST(E57IndependentReaderTest, WrittenFilesGiveWebE57ThePointsAndColoursWritten) {
  // A UTM tile of 800 m: scales of 1e-5 m; half of that, and the float's rounding of the points.
  PointCloud cloud = io_test::RandomCloud(20000, 3, /*normals=*/true, /*weights=*/false);
  cloud.origin = {500000, 4100000, 250};
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud.positions[i] *= 400.0f;
    cloud.colors.push_back(
        {static_cast<uint8_t>(i * 3), static_cast<uint8_t>(i >> 4), static_cast<uint8_t>(i * 11)});
  }
  ExpectWebE57ReadsWhatIsWritten(cloud, "written.e57", 0.6e-5);
  // A unit-sized cloud without colours: scales of 1e-8, fields of about 27 bits.
  ExpectWebE57ReadsWhatIsWritten(io_test::RandomCloud(3000, 4, false, false), "small.e57", 0.6e-8);
}

TEST(E57IndependentReaderTest, BothReadersAgreeOnPosesSphericalCoordinatesAndPackedFields) {
  E57Scan cartesian;
  cartesian.records = 300;
  std::vector<uint64_t> x, y, z, state;
  for (uint64_t i = 0; i < cartesian.records; ++i) {
    x.push_back(i * 37 % 6001);
    y.push_back(i * 101 % 6001);
    z.push_back(i * 13 % 6001);
    state.push_back(i % 17 == 5 ? 2 : 0);
  }
  const std::string limits = "minimum=\"-1000\" maximum=\"5000\" scale=\"0.001\"";
  cartesian.fields = {
      {"<cartesianX type=\"ScaledInteger\" " + limits + " offset=\"0.25\"/>", E57PackBits(x, 13)},
      {"<cartesianY type=\"ScaledInteger\" " + limits + " offset=\"-2\"/>", E57PackBits(y, 13)},
      {"<cartesianZ type=\"ScaledInteger\" " + limits + "/>", E57PackBits(z, 13)},
      {"<cartesianInvalidState type=\"Integer\" minimum=\"0\" maximum=\"2\"/>",
       E57PackBits(state, 2)}};
  cartesian.bytes_per_packet = 97;  // web-e57 does not take empty and index packets between them.
  cartesian.elements =
      "<pose type=\"Structure\"><rotation type=\"Structure\"><w type=\"Float\">0.5</w>"
      "<x type=\"Float\">0.5</x><y type=\"Float\">-0.5</y><z type=\"Float\">0.5</z></rotation>"
      "<translation type=\"Structure\"><x type=\"Float\">500012.5</x>"
      "<y type=\"Float\">4100003</y><z type=\"Float\">100</z></translation></pose>";
  E57Scan spherical;
  spherical.records = 200;
  std::vector<double> range, azimuth, elevation;
  for (int i = 0; i < 200; ++i) {
    range.push_back(1 + 0.05 * i);
    azimuth.push_back(-3 + 0.03 * i);
    elevation.push_back(-1.5 + 0.015 * i);
  }
  spherical.fields = {{"<sphericalRange type=\"Float\"/>", E57Floats(range)},
                      {"<sphericalAzimuth type=\"Float\"/>", E57Floats(azimuth)},
                      {"<sphericalElevation type=\"Float\"/>", E57Floats(elevation)}};
  spherical.elements =
      "<pose type=\"Structure\"><translation type=\"Structure\"><x type=\"Float\">500100</x>"
      "<y type=\"Float\">4100050</y><z type=\"Float\">3</z></translation></pose>";
  const std::string path = TempPath("crafted.e57");
  io_test::WriteBytes(path, E57File({cartesian, spherical}));
  ExpectSamePoints(path, 2e-4);
}

}  // namespace
}  // namespace neuralmesh
