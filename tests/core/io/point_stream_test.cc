#include "core/io/point_stream.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "core/io/internal/laz.h"
#include "core/io/point_cloud_io.h"
#include "core/io/point_selection.h"
#include "core/random.h"
#include "core/rgb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/testing/las_file.h"
#include "tests/testing/las_scan.h"
#include "tests/testing/pipe.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh {
namespace {

using testing::Pipe;

// A LAS 1.4 scan line in UTM millimetres, every 10th record withheld and every 7th noise, and
// an extended variable-length record after the points, which is no record.
std::string ScanLas(int records) {
  testing::LasLayout layout = testing::UtmMillimetreLayout(6);
  std::string evlr(60, '\0');  // An EVLR's header: no payload.
  evlr.replace(2, 8, "scanner!");
  layout.after_points = evlr;
  layout.evlr_count = 1;
  std::vector<testing::LasPoint> points;
  for (int i = 0; i < records; ++i) {
    testing::LasPoint p{};
    p.x = 37 * i;
    p.y = 1000 * (i % 13);
    p.z = 80000 + i;
    p.withheld = i % 10 == 0;
    p.classification = i % 7 == 0 ? 7 : 2;
    points.push_back(p);
  }
  return testing::LasFile(layout, points);
}

// Reads `stream` to its end, writing `bytes` into `pipe` in pieces of the sizes `pieces` cycles
// through, a read after each; returns the last status.
absl::Status ReadInPieces(PointStream& stream, Pipe& pipe, absl::string_view bytes,
                          const std::vector<size_t>& pieces, StreamedPoints* points) {
  for (size_t at = 0, k = 0; at < bytes.size(); ++k) {
    const size_t size = std::min(pieces[k % pieces.size()], bytes.size() - at);
    pipe.Write(bytes.substr(at, size));
    at += size;
    absl::StatusOr<bool> more = stream.Read(absl::Milliseconds(100), points);
    if (!more.ok()) return more.status();
  }
  pipe.CloseWriteEnd();
  for (int i = 0; i < 100; ++i) {
    absl::StatusOr<bool> more = stream.Read(absl::Milliseconds(100), points);
    if (!more.ok()) return more.status();
    if (!*more) return absl::OkStatus();
  }
  return absl::DeadlineExceededError("the stream did not end");
}

// Streams `bytes` through a pipe in `pieces` and expects the points of `whole` (the same file
// read whole), colours too, having read `read_so_far`.
void ExpectStreamedAsRead(absl::string_view bytes, const PointCloud& whole,
                          const std::vector<size_t>& pieces, const std::string& read_so_far) {
  Pipe pipe;
  std::unique_ptr<PointStream> stream = OpenPointStream(pipe.read_end(), "standard input");
  StreamedPoints streamed;
  const std::vector<Vec3>& points = streamed.positions;
  const absl::Status read = ReadInPieces(*stream, pipe, bytes, pieces, &streamed);
  ASSERT_TRUE(read.ok()) << read;
  EXPECT_EQ(stream->ReadSoFar(), read_so_far) << "what follows the records is none";
  ASSERT_EQ(points.size(), whole.size()) << "withheld and noise records left out";
  for (size_t i = 0; i < points.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(static_cast<float>(points[i][c] - whole.origin[c]), whole.positions[i][c])
          << "point " << i;
    }
  }
  ASSERT_EQ(streamed.colors.size(), whole.colors.size());
  for (size_t i = 0; i < whole.colors.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(ChannelFromLevel(streamed.colors[i][c], stream->ColorScale(65535)),
                whole.colors[i][c])
          << "colour " << i;
    }
  }
}

TEST(LasPointStreamTest, ALasFileArrivingInPiecesGivesThePointsReadingItWholeDoes) {
  const std::string bytes = ScanLas(1000);
  const std::string path = testing::ProcessTempDir() + "/scan_line.las";
  std::ofstream(path, std::ios::binary) << bytes;
  absl::StatusOr<PointCloud> whole = ReadPointCloud(path);
  ASSERT_TRUE(whole.ok()) << whole.status();
  ASSERT_GT(whole->size(), 700u);
  for (const std::vector<size_t>& pieces :
       {std::vector<size_t>{1, 7, 100}, std::vector<size_t>{4096}, std::vector<size_t>{29, 31}}) {
    SCOPED_TRACE(pieces.front());
    ExpectStreamedAsRead(bytes, *whole, pieces, "1000 LAS records");
  }
}

// A LAZ stream (`laszip -stdout`, `pdal translate`) gives the points of the LAS file it holds,
// its chunks decoded as each arrives whole: layered chunks (LAS 1.4's formats 6-8) and
// pointwise ones (formats 0-3), of 1 to 1,000 records, however its bytes are cut.
TEST(LasPointStreamTest, ALazFileArrivingInPiecesGivesThePointsOfItsLasFile) {
  testing::LasScan scan;
  scan.format = 3;
  scan.records = 3000;
  scan.random_every = 53;
  for (const std::string& las : {ScanLas(1000), testing::ScanLasFile(scan)}) {
    const std::string path = testing::ProcessTempDir() + "/streamed.las";
    std::ofstream(path, std::ios::binary) << las;
    absl::StatusOr<PointCloud> whole = ReadPointCloud(path);
    ASSERT_TRUE(whole.ok()) << whole.status();
    for (const uint32_t chunk_size : {1000u, 77u, 1u}) {
      absl::StatusOr<std::string> laz =
          io_internal::CompressLas(las, io_internal::LazWriteOptions{chunk_size});
      ASSERT_TRUE(laz.ok()) << laz.status();
      for (const std::vector<size_t>& pieces :
           {std::vector<size_t>{1, 7, 100}, std::vector<size_t>{20000}}) {
        if (chunk_size == 1 && pieces.front() == 1) continue;  // A byte at a time: slow.
        SCOPED_TRACE(absl::StrCat("chunks of ", chunk_size, ", pieces of ", pieces.front()));
        ExpectStreamedAsRead(*laz, *whole, pieces,
                             absl::StrCat(las.size() > 100000 ? 3000 : 1000, " LAS records"));
      }
    }
  }
}

// The last chunk, which holds fewer records than the others, is decoded once its bytes have
// come, before the chunk table after it and the stream's end.
TEST(LasPointStreamTest, ALazStreamsLastChunkIsDecodedBeforeTheStreamEnds) {
  testing::LasScan scan;  // Chunks of tens of kilobytes, as a scan's are.
  scan.format = 1;
  scan.records = 23000;
  const std::string las = testing::ScanLasFile(scan);
  const std::string path = testing::ProcessTempDir() + "/last_chunk.las";
  std::ofstream(path, std::ios::binary) << las;
  const absl::StatusOr<PointCloud> whole = ReadPointCloud(path);
  ASSERT_TRUE(whole.ok()) << whole.status();
  const absl::StatusOr<std::string> laz =
      io_internal::CompressLas(las, io_internal::LazWriteOptions{10000});
  ASSERT_TRUE(laz.ok()) << laz.status();
  const absl::StatusOr<io_internal::LazChunks> chunks = io_internal::LazChunks::Open(*laz);
  ASSERT_TRUE(chunks.ok()) << chunks.status();
  ASSERT_EQ(chunks->size(), 3u);
  ASSERT_EQ(chunks->records_in(2), 3000u);
  ASSERT_GT(chunks->chunk(2).size, 4096u);
  const size_t chunks_end = chunks->chunk(2).at + chunks->chunk(2).size;
  ASSERT_LT(chunks_end, laz->size()) << "the chunk table follows";

  Pipe pipe;
  std::unique_ptr<PointStream> stream = OpenPointStream(pipe.read_end(), "standard input");
  StreamedPoints streamed;
  for (size_t at = 0; at < chunks_end; at += 4096) {
    pipe.Write(absl::string_view(*laz).substr(at, std::min<size_t>(4096, chunks_end - at)));
    ASSERT_TRUE(stream->Read(absl::Milliseconds(100), &streamed).ok());
  }
  for (int i = 0; i < 3 && streamed.positions.size() < whole->size(); ++i) {
    ASSERT_TRUE(stream->Read(absl::Milliseconds(10), &streamed).ok());
  }
  EXPECT_EQ(streamed.positions.size(), whole->size()) << "every chunk's points, the stream open";
  pipe.Write(absl::string_view(*laz).substr(chunks_end));
  pipe.CloseWriteEnd();
  absl::StatusOr<bool> more = true;
  for (int i = 0; i < 100 && more.ok() && *more; ++i) {
    more = stream->Read(absl::Milliseconds(100), &streamed);
  }
  ASSERT_TRUE(more.ok() && !*more) << more.status();
  EXPECT_EQ(streamed.positions.size(), whole->size());
}

TEST(LasPointStreamTest, WhatIsNoLasStreamIsAnErrorSayingWhy) {
  const std::string bytes = ScanLas(100);
  const auto error_of = [](absl::string_view stream_bytes) {
    Pipe pipe;
    std::unique_ptr<PointStream> stream = OpenPointStream(pipe.read_end(), "the scanner");
    StreamedPoints streamed;
    return ReadInPieces(*stream, pipe, stream_bytes, {1000}, &streamed);
  };
  absl::Status status = error_of(bytes.substr(0, 300));
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
  EXPECT_EQ(status.message(), "the scanner: ended within the LAS header, after 300 bytes");
  status = error_of(bytes.substr(0, 375 + 30 * 4 + 12));
  EXPECT_EQ(status.message(), "the scanner: ended within LAS record 5 (12 of its 30 bytes)");
  status = error_of(bytes.substr(0, 375 + 30 * 4));
  EXPECT_EQ(status.message(),
            "the scanner: ended after 4 of the 100 LAS records its header states");

  // A LAZ stream cut short within a chunk, or between chunks.
  absl::StatusOr<std::string> laz =
      io_internal::CompressLas(bytes, io_internal::LazWriteOptions{50});
  ASSERT_TRUE(laz.ok()) << laz.status();
  status = error_of(laz->substr(0, laz->size() - 300));
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
  EXPECT_THAT(std::string(status.message()),
              ::testing::StartsWith("the scanner: LAZ: chunk 2 ends within"));
  const absl::StatusOr<io_internal::LazChunks> chunks = io_internal::LazChunks::Open(*laz);
  ASSERT_TRUE(chunks.ok()) << chunks.status();
  status = error_of(laz->substr(0, chunks->chunk(1).at));
  EXPECT_EQ(status.message(),
            "the scanner: ended after 50 of the 100 LAS records its header states");
  // A header that states no record count: where the chunks end is not known.
  std::string uncounted = *laz;
  for (const size_t count_at : {107, 247}) {
    std::fill(uncounted.begin() + count_at,
              uncounted.begin() + count_at + (count_at == 107 ? 4 : 8), '\0');
  }
  status = error_of(uncounted);
  EXPECT_THAT(std::string(status.message()), ::testing::HasSubstr("states no record count"));
}

// The records a LAS stream's header states are read, and what follows them is not (LAS 1.3's
// waveform packets); a header that states none is read to the stream's end.
TEST(LasPointStreamTest, TheHeadersCountSaysWhereTheRecordsEnd) {
  std::vector<testing::LasPoint> records;
  for (int i = 0; i < 50; ++i) records.push_back({100 * i, 200, 300 + i});
  testing::LasLayout layout;
  layout.version_minor = 3;
  layout.after_points = std::string(20 * 17, '\x7f');  // 17 records' worth of waveform bytes.
  const std::string with_waveforms = testing::LasFile(layout, records);
  const auto read = [](const std::string& bytes, StreamedPoints* streamed) {
    Pipe pipe;
    std::unique_ptr<PointStream> stream = OpenPointStream(pipe.read_end(), "standard input");
    return ReadInPieces(*stream, pipe, bytes, {100}, streamed);
  };
  StreamedPoints streamed;
  absl::Status status = read(with_waveforms, &streamed);
  ASSERT_TRUE(status.ok()) << status;
  ASSERT_EQ(streamed.size(), 50u) << "the waveform packets are no records";
  EXPECT_EQ(streamed.positions[49], Vec3(49, 2, 3.49));

  testing::LasLayout unstated;
  std::string bytes = testing::LasFile(unstated, records);
  bytes.replace(107, 4, std::string(4, '\0'));  // The legacy point count.
  streamed.clear();
  status = read(bytes, &streamed);
  ASSERT_TRUE(status.ok()) << status;
  EXPECT_EQ(streamed.size(), 50u) << "read to the end";
}

// A coloured scan of buildings and ground (LAS 1.4, format 7) read with classes: the records
// and colour levels reading the file with them gives; text with classes is refused.
TEST(LasPointStreamTest, ClassesChooseTheRecordsAndColoursComeWithThem) {
  std::vector<testing::LasPoint> records;
  for (int i = 0; i < 600; ++i) {
    testing::LasPoint p{};
    p.x = 41 * i;
    p.y = 1000 * (i % 17);
    p.z = 90000 + 3 * i;
    p.classification = i % 3 == 0 ? 6 : i % 3 == 1 ? 2 : 5;  // Building, ground, vegetation.
    p.withheld = i % 50 == 0;
    p.red = static_cast<uint16_t>(100 * i);
    p.green = static_cast<uint16_t>(65535 - 90 * i);
    p.blue = static_cast<uint16_t>(i);
    records.push_back(p);
  }
  const std::string bytes = testing::LasFile(testing::UtmMillimetreLayout(7), records);
  const std::string path = testing::ProcessTempDir() + "/coloured_scan.las";
  std::ofstream(path, std::ios::binary) << bytes;
  absl::StatusOr<LasClasses> classes = ParseLasClasses("2,6");
  ASSERT_TRUE(classes.ok());
  absl::StatusOr<PointCloud> whole = ReadPointCloud(path, nullptr, PointSelection{*classes});
  ASSERT_TRUE(whole.ok()) << whole.status();
  ASSERT_EQ(whole->colors.size(), whole->size());

  Pipe pipe;
  std::unique_ptr<PointStream> stream =
      OpenPointStream(pipe.read_end(), "standard input", *classes);
  StreamedPoints streamed;
  const absl::Status read = ReadInPieces(*stream, pipe, bytes, {333}, &streamed);
  ASSERT_TRUE(read.ok()) << read;
  ASSERT_EQ(streamed.size(), 392u) << "400 records of classes 2 and 6, 8 of them withheld";
  ASSERT_EQ(streamed.size(), whole->size());
  ASSERT_EQ(streamed.colors.size(), streamed.size());
  for (size_t i = 0; i < streamed.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(static_cast<float>(streamed.positions[i][c] - whole->origin[c]),
                whole->positions[i][c])
          << "point " << i;
    }
    const double scale = stream->ColorScale(65535);
    ASSERT_EQ(scale, 65535);
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(ChannelFromLevel(streamed.colors[i][c], scale), whole->colors[i][c])
          << "point " << i;
    }
  }
  EXPECT_EQ(streamed.colors[1], (std::array<float, 3>{300, 65535 - 270, 3}))
      << "the second point is record 3 (record 0 is withheld, record 2 vegetation)";

  Pipe text_pipe;
  std::unique_ptr<PointStream> text =
      OpenPointStream(text_pipe.read_end(), "the scanner", *classes);
  StreamedPoints none;
  const absl::Status refused = ReadInPieces(*text, text_pipe, "1 2 3\n", {6}, &none);
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument) << refused;
  EXPECT_EQ(refused.message(),
            "the scanner: text, whose points have no LAS classes to choose from; classes choose "
            "the records of a LAS stream");
  EXPECT_EQ(none.size(), 0u);
  EXPECT_EQ(stream->ColorScale(255), 255) << "8-bit levels in 16-bit fields";
}

// Streams whose header bytes are mangled at random: each is read to its end or refused with
// INVALID_ARGUMENT (AddressSanitizer's build checks that no byte is read out of bounds).
TEST(LasPointStreamTest, MangledHeadersAreReadOrRefused) {
  const std::string bytes = ScanLas(200);
  Random random(11);
  int refused = 0;
  for (int round = 0; round < 1500; ++round) {
    std::string mangled = bytes;
    for (int k = 0, n = 1 + static_cast<int>(random.NextIndex(4)); k < n; ++k) {
      mangled[random.NextIndex(400)] = static_cast<char>(random.NextIndex(256));
    }
    Pipe pipe;
    std::unique_ptr<PointStream> stream = OpenPointStream(pipe.read_end(), "standard input");
    StreamedPoints streamed;
    std::vector<Vec3>& points = streamed.positions;
    const absl::Status read = ReadInPieces(*stream, pipe, mangled, {4096}, &streamed);
    if (!read.ok()) {
      ASSERT_EQ(read.code(), absl::StatusCode::kInvalidArgument) << read;
      ++refused;
    }
    ASSERT_LE(points.size(), 200u) << "more points than records";
  }
  EXPECT_GT(refused, 0);
}

TEST(LasPointStreamTest, AStreamNotStartingLikeLasIsText) {
  for (const std::string text : {"1 2 3", "1 2 3\n4 5 6\n", "LAS 1 2\n"}) {
    SCOPED_TRACE(text);
    Pipe pipe;
    std::unique_ptr<PointStream> stream = OpenPointStream(pipe.read_end(), "standard input");
    StreamedPoints streamed;
    std::vector<Vec3>& points = streamed.positions;
    const absl::Status read = ReadInPieces(*stream, pipe, text, {2}, &streamed);
    if (text == "LAS 1 2\n") {
      EXPECT_EQ(read.code(), absl::StatusCode::kInvalidArgument) << read;
      EXPECT_TRUE(absl::StrContains(read.message(), "line 1")) << read;
      continue;
    }
    ASSERT_TRUE(read.ok()) << read;
    ASSERT_FALSE(points.empty());
    EXPECT_EQ(points[0], Vec3(1, 2, 3));
    EXPECT_EQ(stream->ReadSoFar(), points.size() == 1 ? "1 line" : "2 lines");
  }
}

}  // namespace
}  // namespace neuralmesh
