#include "core/sampling/off_core_sampler.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "core/io/internal/las.h"
#include "core/io/internal/las_layout.h"
#include "core/io/internal/laz.h"
#include "core/io/internal/pcd.h"
#include "core/io/internal/ply.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/las_file.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh {
namespace {

// A scan line in UTM millimetres: record i at x = 500000 + i / 100 (so a sample names its
// record), y = 4100000 + (i % 7), z = 80; every 10th record withheld, every 7th (not withheld)
// classified as low noise (7), every 5th else as building (6), the rest ground (2).
testing::LasLayout Layout() { return testing::UtmMillimetreLayout(6); }

std::vector<testing::LasPoint> ScanLine(int n) {
  std::vector<testing::LasPoint> points;
  for (int i = 0; i < n; ++i) {
    testing::LasPoint p{};
    p.x = 10 * i;
    p.y = 1000 * (i % 7);
    p.z = 80000;
    p.withheld = i % 10 == 0;
    p.classification = i % 7 == 0 ? 7 : i % 5 == 0 ? 6 : 2;
    points.push_back(p);
  }
  return points;
}

std::string Write(const std::string& name, const std::string& bytes) {
  const std::string path = testing::ProcessTempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

std::unique_ptr<OffCoreSampler> Open(const std::string& path,
                                     const std::optional<LasClasses>& classes = std::nullopt) {
  absl::StatusOr<std::unique_ptr<OffCoreSampler>> sampler = OffCoreSampler::Open(path, classes);
  EXPECT_TRUE(sampler.ok()) << sampler.status();
  return sampler.ok() ? *std::move(sampler) : nullptr;
}

// The record a sample of ScanLine came from, relative to `origin`.
int RecordOf(const Vec3& sample, const Origin& origin) {
  return static_cast<int>(std::lround((sample[0] + origin[0] - 500000) * 100));
}

TEST(OffCoreSamplerTest, DrawsEveryKeptRecordAlikeAndNoOther) {
  const std::vector<testing::LasPoint> points = ScanLine(300);
  const std::string path = Write("line.las", testing::LasFile(Layout(), points));
  for (bool buildings_only : {false, true}) {
    std::optional<LasClasses> classes;
    if (buildings_only) {
      classes.emplace();
      (*classes)[6] = true;
    }
    auto sampler = Open(path, classes);
    ASSERT_NE(sampler, nullptr);
    EXPECT_EQ(sampler->records(), 300u);
    const auto kept = [&](int i) {
      const testing::LasPoint& p = points[i];
      return !p.withheld && (buildings_only ? p.classification == 6 : p.classification != 7);
    };
    int kept_count = 0;
    for (int i = 0; i < 300; ++i) kept_count += kept(i);
    EXPECT_NEAR(sampler->kept_share(), kept_count / 300.0, 0.03);

    const int draws = 200000;
    Random rng(3);
    std::map<int, int> counts;
    for (int d = 0; d < draws; ++d) ++counts[RecordOf(sampler->Sample(rng), sampler->origin())];
    EXPECT_EQ(counts.size(), static_cast<size_t>(kept_count)) << "no sample off the records";
    const double expected = static_cast<double>(draws) / kept_count;
    for (int i = 0; i < 300; ++i) {
      if (kept(i)) {
        EXPECT_NEAR(counts[i], expected, 0.2 * expected) << "record " << i;
      } else {
        EXPECT_EQ(counts[i], 0) << "record " << i << " is left out when the file is read";
      }
    }
  }
}

// A file cut short while it is sampled (another program rewriting it): samples past its new
// end read zeros instead of crashing the process, and CheckSource says the samples are no
// longer the file's.
TEST(OffCoreSamplerTest, AFileThatShrinksWhileSampledIsReportedNotACrash) {
  const std::string path = Write("shrinks.las", testing::LasFile(Layout(), ScanLine(100000)));
  auto sampler = Open(path);
  ASSERT_NE(sampler, nullptr);
  Random rng(5);
  for (int i = 0; i < 1000; ++i) sampler->Sample(rng);
  EXPECT_TRUE(sampler->CheckSource().ok()) << sampler->CheckSource();
  ASSERT_EQ(::truncate(path.c_str(), 300000), 0);  // A tenth of the records left.
  int past_the_end = 0;
  for (int i = 0; i < 1000; ++i) {
    past_the_end += RecordOf(sampler->Sample(rng), sampler->origin()) > 10000;
  }
  EXPECT_EQ(past_the_end, 0) << "zeroed records give points at the offset, not past the end";
  const absl::Status source = sampler->CheckSource();
  EXPECT_EQ(source.code(), absl::StatusCode::kDataLoss) << source;
  EXPECT_TRUE(absl::StrContains(source.message(), "shrank from ")) << source;
}

TEST(OffCoreSamplerTest, SamplesAreTheRecordsAsReadingTheFileGivesThem) {
  const std::string bytes = testing::LasFile(Layout(), ScanLine(5000));
  const std::string path = Write("georeferenced.las", bytes);
  auto sampler = Open(path);
  ASSERT_NE(sampler, nullptr);
  absl::StatusOr<io_internal::ParsedGeometry> parsed = io_internal::ParseLas(bytes);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  EXPECT_EQ(sampler->origin(), parsed->origin) << "the same origin as the file read whole";
  EXPECT_NE(sampler->origin(), kNoOrigin) << "UTM coordinates need one";
  // The header's bounds: every record's, the ones left out too (record 0 is withheld).
  BoundingBox read;
  for (const Vec3f& p : parsed->positions) read.Extend(Vec3(p));
  const Vec3 all_min = Vec3(500000, 4100000, 80) - Vec3(sampler->origin().data());
  const Vec3 all_max = Vec3(500049.99, 4100006, 80) - Vec3(sampler->origin().data());
  for (int c = 0; c < 3; ++c) {
    EXPECT_LE(sampler->Bounds().min[c], read.min[c] + 1e-5) << "axis " << c;  // Floats.
    EXPECT_GE(sampler->Bounds().max[c], read.max[c] - 1e-5) << "axis " << c;
    EXPECT_NEAR(sampler->Bounds().min[c], all_min[c], 1e-6) << "axis " << c;
    EXPECT_NEAR(sampler->Bounds().max[c], all_max[c], 1e-6) << "axis " << c;
  }
  // Each sample is a record's coordinates, exactly: integers times the scale plus the offset.
  Random rng(5);
  for (int d = 0; d < 1000; ++d) {
    const Vec3 s = sampler->Sample(rng);
    const int i = RecordOf(s, sampler->origin());
    ASSERT_GE(i, 0);
    ASSERT_LT(i, 5000);
    EXPECT_EQ(s[0] + sampler->origin()[0], 10 * i * 0.001 + 500000);
    EXPECT_EQ(s[1] + sampler->origin()[1], 1000 * (i % 7) * 0.001 + 4100000);
    EXPECT_EQ(s[2] + sampler->origin()[2], 80000 * 0.001);
  }
}

TEST(OffCoreSamplerTest, ASeedGivesTheSameSamplesAndPrefetchingChangesNothing) {
  const std::string path = Write("seeded.las", testing::LasFile(Layout(), ScanLine(1000)));
  auto sampler = Open(path);
  ASSERT_NE(sampler, nullptr);
  Random a(9), b(9);
  for (int d = 0; d < 500; ++d) {
    sampler->PrefetchSample(a);
    const Vec3 first = sampler->Sample(a);
    EXPECT_EQ(first, sampler->Sample(b)) << "draw " << d;
  }
}

TEST(OffCoreSamplerTest, StaleHeaderBoundsAreNotTrusted) {
  std::string bytes = testing::LasFile(Layout(), ScanLine(5000));
  absl::StatusOr<io_internal::ParsedGeometry> parsed = io_internal::ParseLas(bytes);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  const double data_diagonal = 5000 * 0.01;  // Nearly all of it along x.
  // Bounds left zero, as some writers leave them; then bounds a thousand times too large.
  for (double stated : {0.0, 1e9}) {
    for (int k = 0; k < 6; ++k) {
      io_internal::StoreLittleEndian(k % 2 == 0 ? stated : -stated,
                                     io_internal::las_layout::kBounds + 8 * k, &bytes);
    }
    auto sampler = Open(Write("stale.las", bytes));
    ASSERT_NE(sampler, nullptr);
    EXPECT_EQ(sampler->origin(), parsed->origin) << "header bounds " << stated;
    EXPECT_LT(sampler->Bounds().diagonal(), 1.01 * data_diagonal) << "header bounds " << stated;
    EXPECT_GT(sampler->Bounds().diagonal(), 0.9 * data_diagonal) << "header bounds " << stated;
  }
}

TEST(OffCoreSamplerTest, RefusesWhatCannotBeSampledWhereItLies) {
  const auto expect_refused = [](const std::string& path, absl::StatusCode code,
                                 const std::string& words) {
    absl::StatusOr<std::unique_ptr<OffCoreSampler>> sampler = OffCoreSampler::Open(path);
    ASSERT_FALSE(sampler.ok()) << path;
    EXPECT_EQ(sampler.status().code(), code) << sampler.status();
    EXPECT_TRUE(absl::StrContains(sampler.status().message(), words)) << sampler.status();
  };
  expect_refused(testing::ProcessTempDir() + "/missing.las", absl::StatusCode::kNotFound,
                 "cannot open");
  expect_refused(Write("empty.las", ""), absl::StatusCode::kInvalidArgument, "is empty");
  expect_refused(Write("text.las", "x y z\n1 2 3\n"), absl::StatusCode::kInvalidArgument,
                 "no LASF signature");
  expect_refused(Write("points.xyz", "1 2 3\n"), absl::StatusCode::kInvalidArgument,
                 "binary PCD (.pcd), can be read where they lie");
  const std::string las = testing::LasFile(Layout(), ScanLine(1000));
  absl::StatusOr<std::string> laz = io_internal::CompressLas(las);
  ASSERT_TRUE(laz.ok()) << laz.status();
  expect_refused(Write("line.laz", *laz), absl::StatusCode::kInvalidArgument,
                 "cannot be read one at a time");
  expect_refused(Write("none.las", testing::LasFile(Layout(), {})),
                 absl::StatusCode::kInvalidArgument, "no point records");
  // Every record withheld, then one in 400 kept: each sample would read hundreds of records.
  std::vector<testing::LasPoint> points = ScanLine(4000);
  for (testing::LasPoint& p : points) p.withheld = true;
  expect_refused(Write("withheld.las", testing::LasFile(Layout(), points)),
                 absl::StatusCode::kInvalidArgument, "0 of 4096 records drawn");
  for (size_t i = 0; i < points.size(); i += 400) points[i].withheld = false;
  expect_refused(Write("sparse.las", testing::LasFile(Layout(), points)),
                 absl::StatusCode::kInvalidArgument, "read it whole");
  for (size_t i = 0; i < points.size(); i += 20) points[i].withheld = false;  // One in 20.
  for (testing::LasPoint& p : points) p.classification = 2;
  EXPECT_TRUE(OffCoreSampler::Open(Write("enough.las", testing::LasFile(Layout(), points))).ok())
      << "5% kept: about 20 records a sample";
}

// A binary PLY file: a 'camera' element of one 5-byte record before the vertices, each vertex
// `red`, x, y, z (doubles, or floats), `green`, `blue`, and an empty face list after them.
// Vertex i lies at (500000 + i / 100, 4100000 + (i % 7), 80) in doubles, or (i / 100, i % 7,
// 80) in floats.
std::string PlyFile(int n, bool doubles, bool big_endian, const std::string& vertex_extra = "") {
  std::string out = "ply\nformat ";
  out += big_endian ? "binary_big_endian" : "binary_little_endian";
  out += " 1.0\nelement camera 1\nproperty float a\nproperty uchar b\n";
  out += "element vertex " + std::to_string(n) + "\nproperty uchar red\n";
  for (const char* axis : {"x", "y", "z"}) {
    out += std::string("property ") + (doubles ? "double " : "float ") + axis + "\n";
  }
  out += "property uchar green\nproperty uchar blue\n" + vertex_extra;
  out += "element face 0\nproperty list uchar int vertex_indices\nend_header\n";
  out.append(5, '\x7f');
  const auto append = [&](auto value) {
    char bytes[sizeof(value)];
    std::memcpy(bytes, &value, sizeof(value));
    if (big_endian) std::reverse(bytes, bytes + sizeof(value));
    out.append(bytes, sizeof(value));
  };
  for (int i = 0; i < n; ++i) {
    out += static_cast<char>(i);
    const double p[3] = {(doubles ? 500000 : 0) + i / 100.0, (doubles ? 4100000.0 : 0.0) + i % 7,
                         80};
    for (double c : p) doubles ? append(c) : append(static_cast<float>(c));
    out += "\x01\x02";
  }
  return out;
}

TEST(OffCoreSamplerTest, PlyVerticesAreSampledAsParsePlyReadsThem) {
  for (bool doubles : {true, false}) {
    for (bool big_endian : {false, true}) {
      const std::string bytes = PlyFile(3000, doubles, big_endian);
      auto sampler = Open(Write("scan.ply", bytes));
      ASSERT_NE(sampler, nullptr);
      EXPECT_EQ(sampler->records(), 3000u);
      EXPECT_TRUE(sampler->has_colors());
      absl::StatusOr<io_internal::ParsedGeometry> parsed =
          io_internal::ParsePly(bytes, io_internal::FaceHandling::kSkip);
      ASSERT_TRUE(parsed.ok()) << parsed.status();
      EXPECT_EQ(sampler->origin(), parsed->origin) << "doubles " << doubles;
      EXPECT_EQ(sampler->origin() != kNoOrigin, doubles) << "UTM doubles need an origin";
      Random rng(2);
      for (int d = 0; d < 1000; ++d) {
        const Vec3 s = sampler->Sample(rng) + Vec3(sampler->origin().data());
        const int i = static_cast<int>(std::lround((s[0] - (doubles ? 500000 : 0)) * 100));
        ASSERT_GE(i, 0);
        ASSERT_LT(i, 3000);
        const double x = (doubles ? 500000 : 0) + i / 100.0;
        EXPECT_EQ(s[0], doubles ? x : static_cast<double>(static_cast<float>(x))) << i;
        EXPECT_EQ(s[1], (doubles ? 4100000 : 0) + i % 7) << i;
        EXPECT_EQ(s[2], 80) << i;
      }
    }
  }
  // A vertex with a coordinate that is not a number, and one with a coordinate no float holds
  // (either makes ParsePly refuse the file), are never drawn.
  std::string bytes = PlyFile(100, true, false);
  const double nan = std::nan(""), huge = 1e300;
  const size_t first_vertex = bytes.find("end_header\n") + 11 + 5;
  std::memcpy(&bytes[first_vertex + 27 * 50 + 1], &nan, sizeof(nan));
  std::memcpy(&bytes[first_vertex + 27 * 60 + 9], &huge, sizeof(huge));
  absl::StatusOr<io_internal::ParsedGeometry> refused =
      io_internal::ParsePly(bytes, io_internal::FaceHandling::kSkip);
  ASSERT_FALSE(refused.ok()) << "vertex 50's x is not a number";
  auto sampler = Open(Write("nan.ply", bytes));
  ASSERT_NE(sampler, nullptr);
  Random rng(4);
  for (int d = 0; d < 20000; ++d) {
    const Vec3 s = sampler->Sample(rng);
    ASSERT_TRUE(std::isfinite(s[0]) && std::fabs(s[1]) < 1e6) << "draw " << d;
  }
}

TEST(OffCoreSamplerTest, PlyFilesWithoutRecordsOfOneSizeAreRefusedSayingWhy) {
  const auto expect_refused = [](const std::string& name, const std::string& bytes,
                                 const std::string& words) {
    absl::StatusOr<std::unique_ptr<OffCoreSampler>> sampler =
        OffCoreSampler::Open(Write(name, bytes));
    ASSERT_FALSE(sampler.ok()) << name;
    EXPECT_EQ(sampler.status().code(), absl::StatusCode::kInvalidArgument) << sampler.status();
    EXPECT_TRUE(absl::StrContains(sampler.status().message(), words)) << sampler.status();
  };
  expect_refused("ascii.ply",
                 "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float "
                 "y\nproperty float z\nend_header\n1 2 3\n",
                 "ASCII");
  expect_refused("list.ply", PlyFile(10, true, false, "property list uchar int tags\n"),
                 "element 'vertex' has the list property 'tags'");
  const std::string whole = PlyFile(10, true, false);
  expect_refused("cut.ply", whole.substr(0, whole.size() - 1), "do not fit");
  expect_refused("no_vertex.ply",
                 "ply\nformat binary_little_endian 1.0\nelement point 1\nproperty float x\n"
                 "end_header\n1234",
                 "no 'vertex' element");
  expect_refused("no_z.ply",
                 "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
                 "property float y\nend_header\n12345678",
                 "no scalar property 'z'");
  expect_refused("no_vertices.ply", PlyFile(0, true, false), "no point records");
}

TEST(OffCoreSamplerTest, BinaryPcdPointsAreSampledAsParsePcdReadsThem) {
  // An organized cloud's empty pixels (NaN) among UTM points in doubles.
  PointCloud cloud;
  cloud.origin = {500000, 4100000, 0};
  for (int i = 0; i < 2000; ++i) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    cloud.positions.push_back(i % 4 == 3 ? Vec3f(nan, nan, nan)
                                         : Vec3f(i / 100.0f, static_cast<float>(i % 7), 80.f));
  }
  io_internal::GeometryView view;
  view.positions = cloud.positions;
  view.origin = cloud.origin;
  absl::StatusOr<std::string> bytes = io_internal::FormatPcd(view);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  absl::StatusOr<io_internal::ParsedGeometry> parsed = io_internal::ParsePcd(*bytes);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  ASSERT_EQ(parsed->left_out.invalid, 500u);
  auto sampler = Open(Write("scan.pcd", *bytes));
  ASSERT_NE(sampler, nullptr);
  EXPECT_EQ(sampler->records(), 2000u);
  EXPECT_NEAR(sampler->kept_share(), 0.75, 0.03);
  EXPECT_EQ(sampler->origin(), parsed->origin);
  Random rng(6);
  std::map<int, int> counts;
  for (int d = 0; d < 30000; ++d) {
    const Vec3 s = sampler->Sample(rng) + Vec3(sampler->origin().data());
    const int i = static_cast<int>(std::lround((s[0] - 500000) * 100));
    ASSERT_NE(i % 4, 3) << "an empty pixel drawn";
    EXPECT_EQ(s[1], 4100000 + i % 7);
    ++counts[i];
  }
  EXPECT_EQ(counts.size(), 1500u) << "every point drawn";

  for (PcdData data : {PcdData::kAscii, PcdData::kBinaryCompressed}) {
    absl::StatusOr<std::string> other = io_internal::FormatPcd(view, data);
    ASSERT_TRUE(other.ok()) << other.status();
    absl::StatusOr<std::unique_ptr<OffCoreSampler>> refused =
        OffCoreSampler::Open(Write("other.pcd", *other));
    ASSERT_FALSE(refused.ok());
    EXPECT_TRUE(absl::StrContains(refused.status().message(),
                                  "no point can be found without reading those before"))
        << refused.status();
  }
}

}  // namespace
}  // namespace neuralmesh
