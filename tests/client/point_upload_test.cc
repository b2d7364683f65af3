#include "client/point_upload.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/internal/laz.h"
#include "core/io/point_cloud_io.h"
#include "core/io/spread_order.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/client/subprocess.h"
#include "tests/testing/las_file.h"
#include "tests/testing/pipe.h"
#include "tests/testing/shapes.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::client {
namespace {

using Point = std::tuple<float, float, float>;

std::vector<Point> PointsOf(const v1::PointBatch& batch) {
  const std::string& bytes = batch.packed().positions();
  std::vector<Point> points(bytes.size() / 12);
  for (size_t i = 0; i < points.size(); ++i) {
    float xyz[3];
    std::memcpy(xyz, bytes.data() + 12 * i, 12);
    points[i] = {xyz[0], xyz[1], xyz[2]};
  }
  return points;
}

// This test's directory, made once.
const std::string& Dir() {
  static const std::string* dir = new std::string(testing::MakeTempDir("point_upload"));
  return *dir;
}

// A georeferenced scan as a scanner leaves it, in strips: a building (class 6, a sphere of
// radius 10, its points sorted by height), each of its points followed by one of the ground
// (class 2), and every tenth building point withheld.
std::string WriteStripScan(const std::string& name, size_t building_points = 6000) {
  testing::LasLayout layout;
  layout.format = 1;
  for (double& s : layout.scale) s = 0.001;
  layout.offset[0] = 500000;
  layout.offset[1] = 4100000;
  std::vector<Vec3f> sphere = testing::ColoredUnitSpherePoints(building_points, 3).positions;
  std::sort(sphere.begin(), sphere.end(),
            [](const Vec3f& a, const Vec3f& b) { return a[2] < b[2]; });
  std::vector<testing::LasPoint> points;
  for (size_t i = 0; i < sphere.size(); ++i) {
    testing::LasPoint building{static_cast<int32_t>(std::lround(10000 * sphere[i][0])) + 12000,
                               static_cast<int32_t>(std::lround(10000 * sphere[i][1])) + 45000,
                               static_cast<int32_t>(std::lround(10000 * sphere[i][2])) + 80000};
    building.classification = 6;
    building.withheld = i % 10 == 9;
    points.push_back(building);
    testing::LasPoint ground{building.x * 2, building.y, 60000};
    ground.classification = 2;
    points.push_back(ground);
  }
  const std::string path = Dir() + "/" + name;
  std::ofstream(path, std::ios::binary) << testing::LasFile(layout, points);
  return path;
}

PointSelection Building() {
  PointSelection selection;
  selection.las_classes.emplace();
  selection.las_classes->set(6);
  return selection;
}

// Uploads the whole of `upload` in batches of `batch_size`, checking each batch, and expects
// the points sent to be those of `read`, each once, and the upload's counts to be the file's:
// its 12,000 records and 5,400 points.
void ExpectEveryPointOnce(PointUpload& upload, size_t batch_size, const PointCloud& read) {
  EXPECT_EQ(upload.total(), 12000u);
  std::vector<Point> sent;
  while (true) {
    if (upload.size().has_value()) {
      EXPECT_EQ(*upload.size(), 5400u) << "a count before the end";
    }
    absl::StatusOr<v1::PointBatch> batch = upload.Batch(sent.size(), batch_size);
    ASSERT_TRUE(batch.ok()) << batch.status();
    EXPECT_EQ(batch->first_point().value(), sent.size());
    const std::vector<Point> points = PointsOf(*batch);
    if (points.empty()) break;
    EXPECT_LE(points.size(), batch_size);
    sent.insert(sent.end(), points.begin(), points.end());
  }
  EXPECT_EQ(upload.size(), 5400u);
  EXPECT_EQ(upload.done(), 12000u);
  std::vector<Point> expected;
  for (const Vec3f& p : read.positions) expected.emplace_back(p[0], p[1], p[2]);
  std::sort(sent.begin(), sent.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(sent, expected) << "the points read whole, each once";
}

TEST(FileRecordsUploadTest, SendsEveryPointReadingTheFileWouldTakeOnce) {
  const std::string path = WriteStripScan("scan.las");
  absl::StatusOr<PointCloud> read = ReadPointCloud(path, nullptr, Building());
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), 5400u);
  absl::StatusOr<MappedPointFile> file = MappedPointFile::Open(path, Building().las_classes);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_EQ(file->origin(), read->origin);
  for (size_t batch_size : {size_t{1}, size_t{500}, size_t{7000}}) {
    SCOPED_TRACE(batch_size);
    FileRecordsUpload upload(*file);
    ExpectEveryPointOnce(upload, batch_size, *read);
  }
}

// The file holds the building from its bottom to its top (60,000 points: 469 blocks of
// records); the upload's first batch of 10,000 points (87 blocks) already holds all of it.
// Each tenth of the building's height is a tenth of its points (a sphere's slabs of equal
// height have equal areas), and of the file: 47 blocks, in which the first 87 blocks of the
// order leave no gap longer than 3 / 87 of the file, 16 blocks. So at least two blocks of 128
// building points fall in each tenth; in the file's order, all would lie in the lowest one.
TEST(FileRecordsUploadTest, TheFirstBatchIsSpreadOverTheWholeFile) {
  absl::StatusOr<MappedPointFile> file =
      MappedPointFile::Open(WriteStripScan("strips.las", 60000), Building().las_classes);
  ASSERT_TRUE(file.ok()) << file.status();
  FileRecordsUpload upload(*file);
  absl::StatusOr<v1::PointBatch> first = upload.Batch(0, 10000);
  ASSERT_TRUE(first.ok()) << first.status();
  const std::vector<Point> points = PointsOf(*first);
  ASSERT_EQ(points.size(), 10000u);
  int per_tenth[10] = {};
  for (const Point& p : points) {
    const double height = std::get<2>(p) - 80;  // The origin's height is 0.
    ++per_tenth[std::clamp(static_cast<int>((height + 10) / 2), 0, 9)];
  }
  for (int tenth = 0; tenth < 10; ++tenth) {
    EXPECT_GE(per_tenth[tenth], 250) << "height tenth " << tenth << " of the building";
  }
  EXPECT_LT(upload.done(), 23000u) << "the records read for the first 10,000 points";
}

TEST(FileRecordsUploadTest, SkippingBackOrPastTheEndReadsTheOrderAgain) {
  absl::StatusOr<MappedPointFile> file =
      MappedPointFile::Open(WriteStripScan("again.las"), Building().las_classes);
  ASSERT_TRUE(file.ok()) << file.status();
  FileRecordsUpload upload(*file);
  absl::StatusOr<v1::PointBatch> first = upload.Batch(0, 3000);
  ASSERT_TRUE(first.ok());
  absl::StatusOr<v1::PointBatch> again = upload.Batch(1000, 1000);  // Back: read again.
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->first_point().value(), 1000u);
  const std::vector<Point> all = PointsOf(*first);
  EXPECT_EQ(PointsOf(*again), std::vector<Point>(all.begin() + 1000, all.begin() + 2000));

  FileRecordsUpload resumed(*file);
  ASSERT_TRUE(resumed.SkipTo(2000).ok());
  absl::StatusOr<v1::PointBatch> rest = resumed.Batch(2000, 1000);
  ASSERT_TRUE(rest.ok());
  EXPECT_EQ(PointsOf(*rest), std::vector<Point>(all.begin() + 2000, all.begin() + 3000));

  EXPECT_TRUE(resumed.SkipTo(5400).ok());
  absl::StatusOr<v1::PointBatch> none = resumed.Batch(5400, 10);
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->packed().positions().empty());
  const absl::Status past = resumed.SkipTo(5401);
  EXPECT_EQ(past.code(), absl::StatusCode::kOutOfRange) << past;
  EXPECT_EQ(past.message(), "the upload cannot start at point 5401 of 5400");
  EXPECT_EQ(resumed.size(), 5400u);
}

// Uploads `upload` in batches of 500 until a batch fails; expects that to happen before its
// end, with DATA_LOSS naming `path`, and no point sent to lie outside the scan's box (a
// zeroed record's point would lie at the LAS offset, far from it).
void ExpectShrinkToStopTheUpload(PointUpload& upload, const std::string& path) {
  absl::Status status = absl::OkStatus();
  uint64_t sent = 0;
  while (status.ok()) {
    absl::StatusOr<v1::PointBatch> batch = upload.Batch(sent, 500);
    status = batch.status();
    if (!batch.ok()) break;
    const std::vector<Point> points = PointsOf(*batch);
    ASSERT_FALSE(points.empty()) << "the upload ended without noticing the file shrank";
    for (const Point& p : points) ASSERT_GT(std::get<2>(p), 50.0) << "a zeroed record sent";
    sent += points.size();
  }
  EXPECT_EQ(status.code(), absl::StatusCode::kDataLoss) << status;
  EXPECT_THAT(std::string(status.message()), ::testing::HasSubstr("'" + path + "' shrank from "))
      << status;
}

TEST(FileRecordsUploadTest, AFileThatShrinksDuringTheUploadStopsItWithDataLoss) {
  const std::string path = WriteStripScan("shrinks.las", 60000);
  absl::StatusOr<MappedPointFile> file = MappedPointFile::Open(path);
  ASSERT_TRUE(file.ok()) << file.status();
  FileRecordsUpload upload(*file);
  ASSERT_TRUE(upload.Batch(0, 1000).ok());
  ASSERT_EQ(::truncate(path.c_str(), 100000), 0);  // A LAS header and 3,000-odd records left.
  ExpectShrinkToStopTheUpload(upload, path);
}

// The scan of WriteStripScan as LAZ in chunks of 1,000 records.
std::string WriteStripScanLaz(const std::string& name, size_t building_points = 6000) {
  const std::string las = WriteStripScan(name + ".las", building_points);
  absl::StatusOr<std::string> laz =
      io_internal::CompressLas(testing::ReadWholeFile(las), io_internal::LazWriteOptions{1000});
  EXPECT_TRUE(laz.ok()) << laz.status();
  const std::string path = Dir() + "/" + name;
  std::ofstream(path, std::ios::binary) << *laz;
  return path;
}

TEST(LazFileUploadTest, SendsEveryPointReadingTheFileWouldTakeOnce) {
  const std::string path = WriteStripScanLaz("scan.laz");
  EXPECT_TRUE(IsLazFile(path));
  EXPECT_FALSE(IsLazFile(WriteStripScan("plain.las")));
  absl::StatusOr<PointCloud> read = ReadPointCloud(path, nullptr, Building());
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), 5400u);
  absl::StatusOr<MappedLazFile> file = MappedLazFile::Open(path, Building().las_classes);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_EQ(file->chunks(), 12u);
  EXPECT_EQ(file->origin(), read->origin);
  EXPECT_NEAR(file->kept_share(), 0.45, 0.01);
  for (size_t batch_size : {size_t{1}, size_t{500}, size_t{7000}}) {
    SCOPED_TRACE(batch_size);
    LazFileUpload upload(*file);
    ExpectEveryPointOnce(upload, batch_size, *read);
  }
}

// 60,000 building points in 120 chunks, bottom to top: the first batch holds the points of the
// first wave's eight chunks, spread over the building's height.
TEST(LazFileUploadTest, TheFirstBatchIsSpreadOverTheWaveOfChunks) {
  absl::StatusOr<MappedLazFile> file =
      MappedLazFile::Open(WriteStripScanLaz("strips.laz", 60000), Building().las_classes);
  ASSERT_TRUE(file.ok()) << file.status();
  LazFileUpload upload(*file);
  absl::StatusOr<v1::PointBatch> first = upload.Batch(0, 3000);
  ASSERT_TRUE(first.ok()) << first.status();
  const std::vector<Point> points = PointsOf(*first);
  ASSERT_EQ(points.size(), 3000u);
  EXPECT_EQ(upload.done(), 8000u) << "one wave of eight chunks decoded";
  int per_tenth[10] = {};
  for (const Point& p : points) {
    ++per_tenth[std::clamp(static_cast<int>((std::get<2>(p) - 70) / 2), 0, 9)];
  }
  EXPECT_GE(std::count_if(per_tenth, per_tenth + 10, [](int n) { return n > 0; }), 6)
      << "the first batch in at most five tenths of the building's height";
}

TEST(LazFileUploadTest, SkippingBackDecodesAgainAndACorruptChunkIsAnError) {
  const std::string path = WriteStripScanLaz("again.laz");
  absl::StatusOr<MappedLazFile> file = MappedLazFile::Open(path, Building().las_classes);
  ASSERT_TRUE(file.ok()) << file.status();
  LazFileUpload upload(*file);
  absl::StatusOr<v1::PointBatch> all = upload.Batch(0, 5400);
  ASSERT_TRUE(all.ok()) << all.status();
  const std::vector<Point> points = PointsOf(*all);
  ASSERT_EQ(points.size(), 5400u);
  absl::StatusOr<v1::PointBatch> again = upload.Batch(1000, 3000);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(PointsOf(*again), std::vector<Point>(points.begin() + 1000, points.begin() + 4000));
  LazFileUpload resumed(*file);
  ASSERT_TRUE(resumed.SkipTo(4500).ok());
  absl::StatusOr<v1::PointBatch> rest = resumed.Batch(4500, 2000);
  ASSERT_TRUE(rest.ok()) << rest.status();
  EXPECT_EQ(PointsOf(*rest), std::vector<Point>(points.begin() + 4500, points.end()));
  EXPECT_EQ(resumed.SkipTo(5401).code(), absl::StatusCode::kOutOfRange);

  // The last chunk of the order, past the probe's, overwritten.
  std::string bytes = testing::ReadWholeFile(path);
  absl::StatusOr<io_internal::LazChunks> chunks = io_internal::LazChunks::Open(bytes);
  ASSERT_TRUE(chunks.ok()) << chunks.status();
  const io_internal::LazChunks::ChunkSpan& last = chunks->chunk(SpreadOrder(12, 1)[11]);
  for (size_t i = last.at + 30; i < last.at + last.size; ++i) bytes[i] = static_cast<char>(i * 7);
  const std::string corrupt = Dir() + "/corrupt.laz";
  std::ofstream(corrupt, std::ios::binary) << bytes;
  absl::StatusOr<MappedLazFile> opened = MappedLazFile::Open(corrupt, Building().las_classes);
  ASSERT_TRUE(opened.ok()) << opened.status();
  LazFileUpload broken(*opened);
  absl::Status status = absl::OkStatus();
  for (uint64_t first = 0; status.ok();) {
    absl::StatusOr<v1::PointBatch> batch = broken.Batch(first, 500);
    status = batch.status();
    if (!batch.ok() || batch->packed().positions().empty()) break;
    first += PointsOf(*batch).size();
  }
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
  EXPECT_THAT(std::string(status.message()), ::testing::HasSubstr(corrupt)) << status;
}

TEST(LazFileUploadTest, AFileThatShrinksDuringTheUploadStopsItWithDataLoss) {
  const std::string path = WriteStripScanLaz("shrinks.laz", 60000);
  absl::StatusOr<MappedLazFile> file = MappedLazFile::Open(path);
  ASSERT_TRUE(file.ok()) << file.status();
  LazFileUpload upload(*file);
  ASSERT_TRUE(upload.Batch(0, 1000).ok());
  ASSERT_EQ(::truncate(path.c_str(), 20000), 0);
  ExpectShrinkToStopTheUpload(upload, path);
}

// An upload's order is named for how it goes, over how many items, with a fingerprint of its
// first points: the same file and classes give the same order, other classes of the same
// records another fingerprint; describing the order leaves the upload as it was.
TEST(UploadOrderTest, TheFingerprintTellsOtherPointsInTheSameOrderApart) {
  const std::string las = WriteStripScan("order.las");
  PointSelection ground;
  ground.las_classes.emplace().set(2);
  absl::StatusOr<MappedPointFile> building = MappedPointFile::Open(las, Building().las_classes);
  absl::StatusOr<MappedPointFile> again = MappedPointFile::Open(las, Building().las_classes);
  absl::StatusOr<MappedPointFile> of_ground = MappedPointFile::Open(las, ground.las_classes);
  ASSERT_TRUE(building.ok() && again.ok() && of_ground.ok());
  FileRecordsUpload upload(*building), same(*again), other(*of_ground);
  absl::StatusOr<v1::UploadOrder> order = upload.DescribeOrder();
  ASSERT_TRUE(order.ok()) << order.status();
  EXPECT_EQ(order->name(), "file-records-spread-256");
  EXPECT_EQ(order->items(), 12000u);
  EXPECT_NE(order->fingerprint(), 0u);
  absl::StatusOr<v1::UploadOrder> same_order = same.DescribeOrder();
  ASSERT_TRUE(same_order.ok());
  EXPECT_EQ(same_order->fingerprint(), order->fingerprint());
  absl::StatusOr<v1::UploadOrder> other_order = other.DescribeOrder();
  ASSERT_TRUE(other_order.ok());
  EXPECT_EQ(other_order->name(), order->name());
  EXPECT_EQ(other_order->items(), order->items());
  EXPECT_NE(other_order->fingerprint(), order->fingerprint()) << "the ground's points";
  absl::StatusOr<PointCloud> read = ReadPointCloud(las, nullptr, Building());
  ASSERT_TRUE(read.ok()) << read.status();
  ExpectEveryPointOnce(upload, 1000, *read);

  // LAZ: the first points come from the first wave, which the upload keeps.
  absl::StatusOr<MappedLazFile> laz =
      MappedLazFile::Open(WriteStripScanLaz("order.laz"), Building().las_classes);
  ASSERT_TRUE(laz.ok()) << laz.status();
  LazFileUpload laz_upload(*laz);
  order = laz_upload.DescribeOrder();
  ASSERT_TRUE(order.ok()) << order.status();
  EXPECT_EQ(order->name(), "laz-chunks-spread-8");
  EXPECT_EQ(order->items(), 12000u);
  absl::StatusOr<v1::PointBatch> first = laz_upload.Batch(0, PointUpload::kFingerprintPoints);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(order->fingerprint(), OrderFingerprint(first->packed().positions()));
  ExpectEveryPointOnce(laz_upload, 700, *read);

  CloudUpload cloud_upload(*read, CloudUpload::Order::kSpread);
  order = cloud_upload.DescribeOrder();
  ASSERT_TRUE(order.ok()) << order.status();
  EXPECT_EQ(order->name(), "points-spread-256");
  EXPECT_EQ(order->items(), 5400u);
  first = cloud_upload.Batch(0, PointUpload::kFingerprintPoints);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(order->fingerprint(), OrderFingerprint(first->packed().positions()));
  CloudUpload stored(*read, CloudUpload::Order::kStored);
  absl::StatusOr<v1::UploadOrder> stored_order = stored.DescribeOrder();
  ASSERT_TRUE(stored_order.ok());
  EXPECT_EQ(stored_order->name(), "points-stored");
  EXPECT_NE(stored_order->fingerprint(), order->fingerprint())
      << "the same points, in another order";
}

// Georeferenced points written to a pipe in two parts: the first batch chooses the origin, a
// batch that is not full goes out once the flush time passes, and the upload's size is known
// at the end of the stream.
TEST(StreamUploadTest, SendsPointsAsTheyArriveRelativeToTheFirstPointsOrigin) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const std::string first = "500123.5 4100456.25 80\n500124.5 4100457.25 81\n";
  ASSERT_EQ(write(fds[1], first.data(), first.size()), static_cast<ssize_t>(first.size()));
  StreamUpload upload(OpenPointStream(fds[0], "standard input"), /*colors=*/false,
                      absl::Milliseconds(50));
  ASSERT_TRUE(upload.Start(1000).ok());
  EXPECT_EQ(upload.origin(), (Origin{500000, 4100000, 0}));
  EXPECT_EQ(upload.done(), 2u);
  EXPECT_FALSE(upload.size().has_value());
  const absl::Time before = absl::Now();
  absl::StatusOr<v1::PointBatch> batch = upload.Batch(0, 1000);
  ASSERT_TRUE(batch.ok()) << batch.status();
  EXPECT_LT(absl::Now() - before, absl::Seconds(1)) << "a batch that is not full waited";
  EXPECT_EQ(PointsOf(*batch), (std::vector<Point>{{123.5f, 456.25f, 80}, {124.5f, 457.25f, 81}}));

  const std::string second = "500125.5 4100458.25 82\n";
  ASSERT_EQ(write(fds[1], second.data(), second.size()), static_cast<ssize_t>(second.size()));
  close(fds[1]);
  batch = upload.Batch(2, 1000);
  ASSERT_TRUE(batch.ok()) << batch.status();
  EXPECT_EQ(batch->first_point().value(), 2u);
  EXPECT_EQ(PointsOf(*batch), (std::vector<Point>{{125.5f, 458.25f, 82}}));
  batch = upload.Batch(3, 1000);
  ASSERT_TRUE(batch.ok()) << batch.status();
  EXPECT_TRUE(batch->packed().positions().empty()) << "the end of the stream";
  EXPECT_EQ(upload.size(), 3u);
  absl::StatusOr<v1::UploadOrder> order = upload.DescribeOrder();
  ASSERT_TRUE(order.ok());
  EXPECT_EQ(order->name(), "stream");
  EXPECT_EQ(order->fingerprint(), 0u) << "a stream is not resumed";
  batch = upload.Batch(1, 1);  // Again, as after a lost connection.
  ASSERT_TRUE(batch.ok()) << batch.status();
  EXPECT_EQ(PointsOf(*batch), (std::vector<Point>{{124.5f, 457.25f, 81}}));
  EXPECT_EQ(upload.SkipTo(4).code(), absl::StatusCode::kOutOfRange);
  close(fds[0]);
}

// A LAS stream of 8-bit colour levels (format 2): with colours asked for, each batch carries
// its points' colours as they are; without, none.
TEST(StreamUploadTest, SendsTheColoursOfALasStreamWhenAsked) {
  std::vector<testing::LasPoint> records;
  for (int i = 0; i < 300; ++i) {
    testing::LasPoint p{};
    p.x = 100 * i;
    p.y = 7 * (i % 11);
    p.z = i % 5;
    p.red = static_cast<uint16_t>(i % 256);
    p.green = static_cast<uint16_t>(255 - i % 256);
    p.blue = 17;
    records.push_back(p);
  }
  testing::LasLayout layout;
  layout.format = 2;
  const std::string las = testing::LasFile(layout, records);
  for (const bool colors : {true, false}) {
    SCOPED_TRACE(colors ? "colours" : "no colours");
    testing::Pipe pipe;
    pipe.Write(las);
    pipe.CloseWriteEnd();
    StreamUpload upload(OpenPointStream(pipe.read_end(), "standard input"), colors);
    ASSERT_TRUE(upload.Start(100).ok());
    EXPECT_EQ(upload.has_colors(), colors);
    absl::StatusOr<v1::PointBatch> batch = upload.Batch(200, 1000);
    ASSERT_TRUE(batch.ok()) << batch.status();
    ASSERT_EQ(PointsOf(*batch).size(), 100u);
    const std::string& packed = batch->packed().colors();
    if (!colors) {
      EXPECT_TRUE(packed.empty());
    } else {
      ASSERT_EQ(packed.size(), 300u);
      for (int k = 0; k < 100; ++k) {
        const int i = 200 + k;
        ASSERT_EQ(static_cast<uint8_t>(packed[3 * k]), i % 256) << "point " << i;
        ASSERT_EQ(static_cast<uint8_t>(packed[3 * k + 1]), 255 - i % 256) << "point " << i;
        ASSERT_EQ(static_cast<uint8_t>(packed[3 * k + 2]), 17) << "point " << i;
      }
    }
  }
}

// Text whose header names colour columns: their fractions go as 8-bit channels.
TEST(StreamUploadTest, SendsTheColoursATextHeaderNames) {
  testing::Pipe pipe;
  pipe.Write("# x y z r g b\n0 0 0 1 0.5 0\n1 0 0 0 0 1\n");
  pipe.CloseWriteEnd();
  StreamUpload upload(OpenPointStream(pipe.read_end(), "standard input"), /*colors=*/true);
  ASSERT_TRUE(upload.Start(100).ok());
  EXPECT_TRUE(upload.has_colors());
  absl::StatusOr<v1::PointBatch> batch = upload.Batch(0, 100);
  ASSERT_TRUE(batch.ok()) << batch.status();
  EXPECT_EQ(batch->packed().colors(), std::string("\xff\x80\x00\x00\x00\xff", 6));
}

TEST(StreamUploadTest, APointFarFromTheOriginIsAnError) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const std::string text = "1 2 3\n4 5 6\n";
  ASSERT_EQ(write(fds[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  StreamUpload upload(OpenPointStream(fds[0], "standard input"));
  const absl::Status started = upload.Start(2);
  ASSERT_TRUE(started.ok()) << started;
  const std::string far = "1e300 0 0\n";
  ASSERT_EQ(write(fds[1], far.data(), far.size()), static_cast<ssize_t>(far.size()));
  close(fds[1]);
  absl::StatusOr<v1::PointBatch> batch = upload.Batch(0, 10);
  ASSERT_FALSE(batch.ok());
  EXPECT_EQ(batch.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(batch.status().message()),
              ::testing::HasSubstr("standard input, point 3: (1e+300, 0, 0) lies beyond a "
                                   "float's range from the origin the first points chose"));
  close(fds[0]);
}

// A binary big-endian PLY file of `cloud`: double x, y, z, then its colours as a ushort red,
// a float green and a uchar blue, and a property of no role between them.
std::string PlyOfMixedChannels(const PointCloud& cloud) {
  std::string out = absl::StrCat(
      "ply\nformat binary_big_endian 1.0\nelement vertex ", cloud.size(),
      "\nproperty double x\nproperty double y\nproperty double z\nproperty ushort red\n"
      "property short return_number\nproperty float green\nproperty uchar blue\nend_header\n");
  const auto append = [&out](auto value) {
    char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    std::reverse(bytes, bytes + sizeof value);
    out.append(bytes, sizeof value);
  };
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (int c = 0; c < 3; ++c) append(static_cast<double>(cloud.positions[i][c]));
    append(static_cast<uint16_t>(cloud.colors[i][0] * 257));
    append(static_cast<int16_t>(-7));
    append(static_cast<float>(cloud.colors[i][1] / 255.0));
    append(cloud.colors[i][2]);
  }
  return out;
}

// A LAS scan with 16-bit colours, its LAZ, and its points as PLY (uchar channels, and channels
// of three types) and PCD: with colours asked for, each point goes with the colour reading the
// file whole gives it; without, none go.
TEST(FileUploadTest, ColoursGoWithTheirPointsWhenAsked) {
  testing::LasLayout layout;
  layout.format = 3;
  std::vector<testing::LasPoint> records;
  const PointCloud colored = testing::ColoredUnitSpherePoints(3000, 4);
  for (size_t i = 0; i < colored.size(); ++i) {
    testing::LasPoint p{static_cast<int32_t>(std::lround(colored.positions[i][0] * 100)),
                        static_cast<int32_t>(std::lround(colored.positions[i][1] * 100)),
                        static_cast<int32_t>(std::lround(colored.positions[i][2] * 100))};
    p.red = colored.colors[i][0] * 257;
    p.green = colored.colors[i][1] * 257;
    p.blue = colored.colors[i][2] * 257;
    p.classification = i % 3 == 0 ? 7 : 2;  // A third noise, left out.
    records.push_back(p);
  }
  const std::string las = Dir() + "/colored.las";
  std::ofstream(las, std::ios::binary) << testing::LasFile(layout, records);
  absl::StatusOr<std::string> laz =
      io_internal::CompressLas(testing::ReadWholeFile(las), io_internal::LazWriteOptions{400});
  ASSERT_TRUE(laz.ok()) << laz.status();
  const std::string laz_path = Dir() + "/colored.laz";
  std::ofstream(laz_path, std::ios::binary) << *laz;
  absl::StatusOr<PointCloud> read = ReadPointCloud(las);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), 2000u);
  std::vector<std::pair<Point, Rgb>> expected;
  for (size_t i = 0; i < read->size(); ++i) {
    const Vec3f& p = read->positions[i];
    expected.push_back({{p[0], p[1], p[2]}, read->colors[i]});
  }
  std::sort(expected.begin(), expected.end());
  // Every point of `upload` with its colour, or without one.
  const auto sent = [](PointUpload& upload, bool colors) {
    absl::StatusOr<v1::PointBatch> batch = upload.Batch(0, 5000);
    EXPECT_TRUE(batch.ok()) << batch.status();
    const std::vector<Point> points = PointsOf(*batch);
    const std::string& bytes = batch->packed().colors();
    EXPECT_EQ(bytes.size(), colors ? 3 * points.size() : 0);
    std::vector<std::pair<Point, Rgb>> out;
    for (size_t i = 0; i < points.size(); ++i) {
      Rgb color = {0, 0, 0};
      if (colors) std::memcpy(color.data(), bytes.data() + 3 * i, 3);
      out.push_back({points[i], color});
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  const std::string mixed = Dir() + "/colored_mixed.ply";
  std::ofstream(mixed, std::ios::binary) << PlyOfMixedChannels(*read);
  for (const std::string& path : {las, Dir() + "/colored.ply", Dir() + "/colored.pcd", mixed}) {
    SCOPED_TRACE(path);
    if (path != las && path != mixed) {
      ASSERT_TRUE(WritePointCloud(*read, path).ok());
    }
    absl::StatusOr<PointCloud> whole = ReadPointCloud(path);
    ASSERT_TRUE(whole.ok()) << whole.status();
    ASSERT_EQ(whole->colors, read->colors) << "the file holds the scan's colours";
    absl::StatusOr<MappedPointFile> file = MappedPointFile::Open(path);
    ASSERT_TRUE(file.ok()) << file.status();
    EXPECT_TRUE(file->has_colors());
    FileRecordsUpload with(*file, /*colors=*/true);
    EXPECT_EQ(sent(with, true), expected);
    FileRecordsUpload without(*file);
    EXPECT_EQ(sent(without, false).size(), 2000u);
  }
  absl::StatusOr<MappedLazFile> laz_file = MappedLazFile::Open(laz_path);
  ASSERT_TRUE(laz_file.ok()) << laz_file.status();
  LazFileUpload laz_with(*laz_file, /*colors=*/true);
  EXPECT_EQ(sent(laz_with, true), expected);
  LazFileUpload laz_without(*laz_file);
  EXPECT_EQ(sent(laz_without, false).size(), 2000u);
}

// A cloud read whole goes as a file read where it lies does: each point once with what it
// carries, in an order whose first batch is spread over the whole cloud though its points are
// stored bottom to top.
TEST(CloudUploadTest, SendsEachPointOnceWithWhatItCarriesSpreadOverTheCloud) {
  PointCloud cloud = testing::ColoredUnitSpherePoints(60000, 1);
  std::vector<size_t> by_height(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) by_height[i] = i;
  std::sort(by_height.begin(), by_height.end(),
            [&](size_t a, size_t b) { return cloud.positions[a][2] < cloud.positions[b][2]; });
  PointCloud sorted;
  for (size_t i : by_height) {
    sorted.positions.push_back(cloud.positions[i]);
    sorted.colors.push_back(cloud.colors[i]);
    sorted.weights.push_back(static_cast<float>(sorted.weights.size()));  // Which point it is.
  }
  CloudUpload upload(sorted, CloudUpload::Order::kSpread);
  EXPECT_EQ(upload.size(), 60000u);
  EXPECT_EQ(upload.total(), 60000u);

  std::vector<int> sent(sorted.size(), 0);
  int per_tenth[10] = {};
  for (uint64_t first = 0;;) {
    absl::StatusOr<v1::PointBatch> batch = upload.Batch(first, 7000);
    ASSERT_TRUE(batch.ok()) << batch.status();
    EXPECT_EQ(batch->first_point().value(), first);
    const std::vector<Point> points = PointsOf(*batch);
    if (points.empty()) break;
    const std::string& colors = batch->packed().colors();
    const std::string& weights = batch->packed().weights();
    ASSERT_EQ(colors.size(), 3 * points.size());
    ASSERT_EQ(weights.size(), 4 * points.size());
    for (size_t j = 0; j < points.size(); ++j) {
      float weight;
      std::memcpy(&weight, weights.data() + 4 * j, 4);
      const size_t index = static_cast<size_t>(weight);
      ASSERT_LT(index, sorted.size());
      ++sent[index];
      EXPECT_EQ(points[j], Point(sorted.positions[index][0], sorted.positions[index][1],
                                 sorted.positions[index][2]));
      EXPECT_EQ(0, std::memcmp(colors.data() + 3 * j, sorted.colors[index].data(), 3));
      if (first == 0)
        ++per_tenth[std::clamp(static_cast<int>((std::get<2>(points[j]) + 1) * 5), 0, 9)];
    }
    first += points.size();
    EXPECT_EQ(upload.done(), first);
  }
  EXPECT_EQ(std::count(sent.begin(), sent.end(), 1), 60000) << "each point once";
  for (int tenth = 0; tenth < 10; ++tenth) {
    EXPECT_GE(per_tenth[tenth], 350) << "height tenth " << tenth << " in the first batch";
  }
  EXPECT_EQ(upload.SkipTo(60001).code(), absl::StatusCode::kOutOfRange);
  absl::StatusOr<v1::PointBatch> again = upload.Batch(30000, 10);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(PointsOf(*again).size(), 10u) << "a batch sent again after a lost connection";
}

TEST(CloudUploadTest, InItsStoredOrderTheCloudGoesAsItIs) {
  const PointCloud cloud = testing::ColoredUnitSpherePoints(1000, 1);
  CloudUpload upload(cloud, CloudUpload::Order::kStored);
  absl::StatusOr<v1::PointBatch> batch = upload.Batch(600, 500);
  ASSERT_TRUE(batch.ok()) << batch.status();
  EXPECT_EQ(batch->first_point().value(), 600u);
  const std::vector<Point> points = PointsOf(*batch);
  ASSERT_EQ(points.size(), 400u);
  for (size_t j = 0; j < points.size(); ++j) {
    const Vec3f& p = cloud.positions[600 + j];
    ASSERT_EQ(points[j], Point(p[0], p[1], p[2])) << j;
  }
  EXPECT_EQ(batch->packed().colors(),
            std::string(reinterpret_cast<const char*>(cloud.colors.data() + 600), 3 * 400));
  EXPECT_EQ(upload.done(), 1000u);
}

}  // namespace
}  // namespace neuralmesh::client
