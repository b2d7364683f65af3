// LASzip-compressed LAS (core/io/internal/laz.h and its coders): the arithmetic and integer
// coders decode what they encoded, LAS files of every point format 0-3 come back from LAZ byte
// for byte (extra bytes, several chunks, LAS 1.4 with extended records, random records among
// scan-like ones), scans compress, ReadPointCloud and WritePointCloud take .laz, and malformed,
// truncated or corrupt files are refused or decoded without reading out of bounds.
// (laz_independent_reader_test.cc checks the files against laz-perf, an independent decoder.)
#include "core/io/internal/laz.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/byte_sink.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz_arithmetic_coder.h"
#include "core/io/internal/laz_integer_coder.h"
#include "core/io/las_cleaning.h"
#include "core/io/point_cloud_io.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/las_file.h"
#include "tests/testing/las_scan.h"

namespace neuralmesh {
namespace {

using io_internal::CompressLas;
using io_internal::DecompressLaz;
using io_internal::LazWriteOptions;
using io_internal::laz::ArithmeticDecoder;
using io_internal::laz::ArithmeticEncoder;
using io_internal::laz::BitModel;
using io_internal::laz::IntegerCoder;
using io_internal::laz::SymbolModel;
using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;
using testing::LasScan;
using testing::ScanLasFile;

// One coding operation of a random sequence: a bit of one of three models, a symbol of one of
// several alphabets, or raw bits, a short or an int.
struct Operation {
  int kind;   // 0 bit, 1 symbol, 2 raw bits, 3 short, 4 int.
  int model;  // Which bit or symbol model; the bit count for raw bits.
  uint32_t value;
};

TEST(LazCoderTest, ArithmeticCodingDecodesWhatWasEncoded) {
  const std::vector<uint32_t> alphabets = {2, 3, 17, 64, 256, 516, 2048};
  std::mt19937 random(7);
  std::vector<Operation> operations;
  for (int i = 0; i < 200000; ++i) {
    Operation op{static_cast<int>(random() % 5), 0, 0};
    if (op.kind == 0) {
      op.model = random() % 3;
      // Skewed bits, so that the models adapt far from one half.
      op.value = random() % 100 < 10u * (op.model + 1) ? 1 : 0;
    } else if (op.kind == 1) {
      op.model = random() % alphabets.size();
      // Small symbols mostly, as residuals are.
      const uint32_t n = alphabets[op.model];
      op.value = random() % 4 == 0 ? random() % n : random() % std::min<uint32_t>(n, 4);
    } else if (op.kind == 2) {
      op.model = 1 + random() % 32;
      op.value = op.model == 32 ? random() : random() & ((1u << op.model) - 1);
    } else {
      op.value = op.kind == 3 ? random() & 0xFFFF : random();
    }
    operations.push_back(op);
  }
  std::string coded = "prefix";
  {
    std::vector<BitModel> bits(3);
    std::vector<SymbolModel> symbols;
    for (uint32_t n : alphabets) symbols.emplace_back(n);
    ArithmeticEncoder encoder(&coded);
    for (const Operation& op : operations) {
      switch (op.kind) {
        case 0:
          encoder.EncodeBit(bits[op.model], op.value);
          break;
        case 1:
          encoder.EncodeSymbol(symbols[op.model], op.value);
          break;
        case 2:
          encoder.WriteBits(op.model, op.value);
          break;
        case 3:
          encoder.WriteShort(static_cast<uint16_t>(op.value));
          break;
        default:
          encoder.WriteInt(op.value);
          break;
      }
    }
    encoder.Done();
  }
  EXPECT_EQ(coded.substr(0, 6), "prefix");
  std::vector<BitModel> bits(3);
  std::vector<SymbolModel> symbols;
  for (uint32_t n : alphabets) symbols.emplace_back(n);
  ArithmeticDecoder decoder(absl::string_view(coded).substr(6));
  for (size_t i = 0; i < operations.size(); ++i) {
    const Operation& op = operations[i];
    uint32_t value = 0;
    switch (op.kind) {
      case 0:
        value = decoder.DecodeBit(bits[op.model]);
        break;
      case 1:
        value = decoder.DecodeSymbol(symbols[op.model]);
        break;
      case 2:
        value = decoder.ReadBits(op.model);
        break;
      case 3:
        value = decoder.ReadShort();
        break;
      default:
        value = decoder.ReadInt();
        break;
    }
    ASSERT_EQ(value, op.value) << "operation " << i << " of kind " << op.kind;
  }
  // It ends where the stream does, as LASzip's readers of chunk after chunk require.
  EXPECT_EQ(decoder.consumed(), coded.size() - 6);
  EXPECT_EQ(decoder.overrun(), 0u);
}

TEST(LazCoderTest, IntegersOfEveryMagnitudeComeBack) {
  std::mt19937 random(11);
  constexpr int32_t kMin = std::numeric_limits<int32_t>::min();
  constexpr int32_t kMax = std::numeric_limits<int32_t>::max();
  struct Value {
    int32_t predicted, real;
    uint32_t context;
  };
  for (const uint32_t bits : {16u, 32u}) {
    SCOPED_TRACE(absl::StrCat(bits, " bits"));
    std::vector<Value> values;
    const std::vector<int32_t> extremes = bits == 32
                                              ? std::vector<int32_t>{kMin, kMax, 0, -1, 1, kMin + 1}
                                              : std::vector<int32_t>{0, 65535, 1, 32768, 32767};
    for (int i = 0; i < 50000; ++i) {
      Value v{0, 0, static_cast<uint32_t>(random() % 3)};
      const auto draw = [&]() -> int32_t {
        if (random() % 10 == 0) return extremes[random() % extremes.size()];
        const int32_t near = static_cast<int32_t>(random() % 2000) - 1000;
        return bits == 32 ? static_cast<int32_t>(random()) >> (random() % 32)
                          : static_cast<int32_t>((30000 + near) & 0xFFFF);
      };
      v.predicted = draw();
      v.real = random() % 2 == 0 ? draw() : static_cast<int32_t>(v.predicted + random() % 5);
      if (bits == 16) v.real &= 0xFFFF;
      values.push_back(v);
    }
    std::string coded;
    {
      ArithmeticEncoder encoder(&coded);
      IntegerCoder coder(bits, 3);
      for (const Value& v : values) coder.Compress(encoder, v.predicted, v.real, v.context);
      encoder.Done();
    }
    ArithmeticDecoder decoder(coded);
    IntegerCoder coder(bits, 3);
    for (size_t i = 0; i < values.size(); ++i) {
      ASSERT_EQ(coder.Decompress(decoder, values[i].predicted, values[i].context), values[i].real)
          << "value " << i << " predicted " << values[i].predicted;
    }
  }
}

// Overwrites the little-endian value at `at`.
template <typename T>
std::string With(std::string bytes, size_t at, T value) {
  std::memcpy(&bytes[at], &value, sizeof value);
  return bytes;
}

// The points of `laz`, read a chunk at a time (ParseLas), are those of `las`, read whole, with
// the same colours, origin and records left out, with the default classes and with 1 and 2;
// and its description (DescribeLas, also a chunk at a time) is that of `las`.
void ExpectReadAlike(const std::string& las, const std::string& laz) {
  const absl::StatusOr<LasDescription> described = io_internal::DescribeLas(las);
  const absl::StatusOr<LasDescription> chunk_by_chunk = io_internal::DescribeLas(laz);
  ASSERT_EQ(chunk_by_chunk.status(), described.status());
  // The same, but for the size and compression of the file as stored.
  const auto expect_described_alike = [](const LasDescription& a, const LasDescription& b) {
    EXPECT_EQ(a.records_by_class, b.records_by_class);
    EXPECT_EQ(a.withheld, b.withheld);
    EXPECT_EQ(a.records, b.records);
    EXPECT_EQ(a.variable_length_records, b.variable_length_records);
    EXPECT_EQ(a.coordinate_system, b.coordinate_system);
    EXPECT_EQ(a.generating_software, b.generating_software);
    EXPECT_EQ(a.point_format, b.point_format);
    EXPECT_EQ(a.extra_bytes, b.extra_bytes);
    EXPECT_EQ(a.scale, b.scale);
    EXPECT_EQ(a.offset, b.offset);
  };
  if (described.ok()) {
    expect_described_alike(*chunk_by_chunk, *described);
    EXPECT_EQ(described->file_bytes, las.size());
    EXPECT_EQ(chunk_by_chunk->file_bytes, laz.size());
    EXPECT_EQ(described->compression, "");
    EXPECT_EQ(chunk_by_chunk->compression, *io_internal::DescribeLazCompression(laz));
  }
  for (const std::optional<LasClasses>& classes :
       {std::optional<LasClasses>(), std::optional<LasClasses>(LasClasses().set(1).set(2))}) {
    SCOPED_TRACE(classes.has_value() ? "classes 1 and 2" : "default classes");
    const absl::StatusOr<io_internal::ParsedGeometry> whole = io_internal::ParseLas(las, classes);
    const absl::StatusOr<io_internal::ParsedGeometry> chunked = io_internal::ParseLas(laz, classes);
    ASSERT_EQ(chunked.status(), whole.status());
    // Described in the pass that reads the points: as DescribeLas describes the file.
    for (const std::string* file : {&las, &laz}) {
      LasDescription in_passing;
      const absl::StatusOr<io_internal::ParsedGeometry> read =
          io_internal::ParseLas(*file, classes, &in_passing);
      ASSERT_EQ(read.status(), whole.status());
      if (!read.ok()) continue;
      EXPECT_EQ(read->positions, whole->positions);
      const LasDescription& alone = file == &las ? *described : *chunk_by_chunk;
      expect_described_alike(in_passing, alone);
      EXPECT_EQ(in_passing.file_bytes, alone.file_bytes);
      EXPECT_EQ(in_passing.compression, alone.compression);
    }
    if (!whole.ok()) continue;
    EXPECT_EQ(chunked->positions, whole->positions);
    EXPECT_EQ(chunked->colors, whole->colors);
    EXPECT_EQ(chunked->origin, whole->origin);
    EXPECT_EQ(chunked->left_out.withheld, whole->left_out.withheld);
    EXPECT_EQ(chunked->left_out.noise, whole->left_out.noise);
    EXPECT_EQ(chunked->left_out.other_class, whole->left_out.other_class);
    EXPECT_EQ(chunked->left_out.invalid, whole->left_out.invalid);
  }
}

// `las` through LAZ (chunks of `chunk_size`, formats 6-8 in item `version`) and back: the same
// bytes, and read alike (ExpectReadAlike). The same bytes when written a wave of chunks at a
// time (CompressLasTo, DecompressLazTo) after what a sink already holds, whose bytes the
// offsets do not count. Returns the LAZ file.
std::string ExpectSameThroughLaz(const std::string& las, uint32_t chunk_size = 50000,
                                 uint16_t version = 3) {
  const absl::StatusOr<std::string> laz = CompressLas(las, {chunk_size, version});
  EXPECT_TRUE(laz.ok()) << laz.status();
  if (!laz.ok()) return {};
  const absl::StatusOr<std::string> back = DecompressLaz(*laz);
  EXPECT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(back.ok() && *back == las)
      << "sizes " << las.size() << " and " << (back.ok() ? back->size() : 0);
  ExpectReadAlike(las, *laz);
  const std::string before = "bytes before the file";
  StringSink compressed, decompressed;
  EXPECT_TRUE(compressed.Append(before).ok());
  EXPECT_TRUE(decompressed.Append(before).ok());
  LazWriteOptions options{chunk_size, version};
  options.threads = 2;  // Several waves of chunks in files of more than 8 chunks.
  EXPECT_TRUE(io_internal::CompressLasTo(las, &compressed, options).ok());
  EXPECT_TRUE(compressed.bytes() == before + *laz);
  EXPECT_TRUE(io_internal::DecompressLazTo(*laz, &decompressed, {2}).ok());
  EXPECT_TRUE(decompressed.bytes() == before + las);
  return *laz;
}

// Records of the scans that go through LAZ in chunks of `chunk_size`: chunks of one record, each
// coded by coders of its own, get a few hundred (still several waves of chunks); the others
// enough for many records of every kind.
size_t RecordsForChunksOf(uint32_t chunk_size) { return chunk_size == 1 ? 300 : 2500; }

TEST(LazTest, EveryPointFormatComesBackByteForByte) {
  for (int format = 0; format <= 3; ++format) {
    for (const int extra : {0, 3}) {
      for (const uint32_t chunk_size : {50000u, 1000u, 1u}) {
        SCOPED_TRACE(
            absl::StrCat("format ", format, ", ", extra, " extra bytes, chunks of ", chunk_size));
        LasScan scan;
        scan.format = format;
        scan.extra_bytes = extra;
        scan.records = RecordsForChunksOf(chunk_size);
        scan.random_every = 97;
        scan.seed = format * 10 + extra;
        const std::string laz = ExpectSameThroughLaz(ScanLasFile(scan), chunk_size);
        EXPECT_EQ(io_test::Field<uint8_t>(laz, 104), format | 0x80);
      }
    }
  }
  for (const size_t records : {0, 1, 2}) {
    SCOPED_TRACE(absl::StrCat(records, " records"));
    LasScan scan;
    scan.format = 3;
    scan.records = records;
    ExpectSameThroughLaz(ScanLasFile(scan));
  }
}

TEST(LazTest, Las14PointFormatsComeBackByteForByte) {
  for (int format = 6; format <= 8; ++format) {
    for (const int channels : {1, 3}) {
      for (const int extra : {0, 3}) {
        for (const uint32_t chunk_size : {50000u, 700u, 1u}) {
          for (const uint16_t version : {3, 4}) {
            SCOPED_TRACE(absl::StrCat("format ", format, ", ", channels, " scanner channels, ",
                                      extra, " extra bytes, chunks of ", chunk_size, ", version ",
                                      version));
            LasScan scan;
            scan.format = format;
            scan.scanner_channels = channels;
            scan.extra_bytes = extra;
            scan.records = RecordsForChunksOf(chunk_size);
            scan.random_every = 89;
            scan.seed = format * 10 + channels + extra;
            const std::string laz = ExpectSameThroughLaz(ScanLasFile(scan), chunk_size, version);
            EXPECT_EQ(io_test::Field<uint8_t>(laz, 104), format | 0x80);
          }
        }
      }
    }
  }
  for (const size_t records : {0, 1, 2}) {
    SCOPED_TRACE(absl::StrCat(records, " records"));
    LasScan scan;
    scan.format = 8;
    scan.records = records;
    ExpectSameThroughLaz(ScanLasFile(scan));
  }
  // LAS 1.4's records of a scan with variable-length records before them and extended ones
  // after.
  LasScan scan = testing::Las14Scan(/*format=*/7, 3000);
  scan.scanner_channels = 2;
  const std::string laz = ExpectSameThroughLaz(ScanLasFile(scan), 1000);
  EXPECT_EQ(laz.substr(io_test::Field<uint64_t>(laz, 235)), scan.after_points);
}

TEST(LazTest, ChunksAreCodedAlikeOnAnyNumberOfThreads) {
  for (const int format : {1, 8}) {
    SCOPED_TRACE(absl::StrCat("format ", format));
    LasScan scan;
    scan.format = format;
    scan.scanner_channels = format == 8 ? 2 : 1;
    scan.records = 20000;
    scan.random_every = 101;
    const std::string las = ScanLasFile(scan);
    LazWriteOptions options;
    options.chunk_size = 900;  // 23 chunks: several waves of chunks on every thread count.
    options.threads = 1;
    const absl::StatusOr<std::string> one = CompressLas(las, options);
    ASSERT_TRUE(one.ok()) << one.status();
    for (const int threads : {2, 3, 0}) {
      options.threads = threads;
      const absl::StatusOr<std::string> laz = CompressLas(las, options);
      ASSERT_TRUE(laz.ok()) << laz.status();
      EXPECT_TRUE(*laz == *one) << threads << " threads";
      const absl::StatusOr<std::string> back = DecompressLaz(*one, {threads});
      ASSERT_TRUE(back.ok()) << back.status();
      EXPECT_TRUE(*back == las) << threads << " threads";
    }
    // A corrupt chunk is named alike: the first in the file's order.
    std::string corrupt = *one;
    const size_t points = io_test::Field<uint32_t>(corrupt, 96) + 8;
    for (size_t i = points + 5000; i < points + 60000; i += 3) corrupt[i] = static_cast<char>(i);
    const absl::StatusOr<std::string> serial = DecompressLaz(corrupt, {1});
    const absl::StatusOr<std::string> parallel = DecompressLaz(corrupt, {3});
    EXPECT_FALSE(serial.ok());
    EXPECT_EQ(serial.status(), parallel.status());
  }
}

TEST(LazTest, ItemVersionsThreeAndFourDifferWhereScannerChannelsSwitch) {
  // The LASzip record's items follow the LAS 1.4 header (375 bytes), the record's header (54)
  // and its fixed fields (34): POINT14's and RGB14's versions.
  constexpr size_t kVersions[] = {375 + 54 + 34 + 4, 375 + 54 + 34 + 6 + 4};
  for (const int channels : {1, 3}) {
    SCOPED_TRACE(absl::StrCat(channels, " scanner channels"));
    LasScan scan;
    scan.format = 7;
    scan.scanner_channels = channels;
    scan.records = 3000;
    const std::string las = ScanLasFile(scan);
    const std::string version3 = ExpectSameThroughLaz(las, 1000, 3);
    std::string version4 = ExpectSameThroughLaz(las, 1000, 4);
    for (const size_t at : kVersions) {
      EXPECT_EQ(io_test::Field<uint16_t>(version3, at), 3);
      EXPECT_EQ(io_test::Field<uint16_t>(version4, at), 4);
      version4 = With<uint16_t>(version4, at, 3);
    }
    // One scanner: the same records coded alike. Several: version 4 codes the colours of every
    // channel apart, where version 3 mixes them (and is then read as other colours).
    if (channels == 1) {
      EXPECT_TRUE(version4 == version3);
    } else {
      EXPECT_FALSE(version4 == version3);
      const absl::StatusOr<std::string> misread = DecompressLaz(version4);
      EXPECT_TRUE(!misread.ok() || *misread != las);
    }
  }
  EXPECT_EQ(CompressLas(ScanLasFile(LasScan{}), {50000, 5}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(LazTest, Las14FilesKeepTheirRecordsAndExtendedRecords) {
  LasScan scan = testing::Las14Scan(/*format=*/1, 3000);
  scan.extra_bytes = 2;
  const std::string laz = ExpectSameThroughLaz(ScanLasFile(scan), 1000);
  // The extended records follow the chunk table, where the header says they start.
  EXPECT_EQ(laz.substr(io_test::Field<uint64_t>(laz, 235)), scan.after_points);
}

TEST(LazTest, ScansCompressToAFractionOfTheirSize) {
  LasScan scan;
  scan.format = 3;
  scan.records = 100000;
  const std::string las = ScanLasFile(scan);
  const absl::StatusOr<std::string> laz = CompressLas(las);
  ASSERT_TRUE(laz.ok()) << laz.status();
  const double ratio = static_cast<double>(laz->size()) / las.size();
  std::printf("100,000 scan records of format 3: %zu bytes as LAS, %zu as LAZ (%.3f)\n", las.size(),
              laz->size(), ratio);
  EXPECT_LT(ratio, 0.25);
}

TEST(LazTest, ReadAndWrittenAsPointCloudsLikeLas) {
  LasScan scan;
  scan.format = 2;
  scan.records = 5000;
  const std::string las = ScanLasFile(scan);
  const absl::StatusOr<std::string> laz = CompressLas(las);
  ASSERT_TRUE(laz.ok()) << laz.status();
  const std::string las_path = TempPath("scan.las"), laz_path = TempPath("scan.LAZ");
  WriteBytes(las_path, las);
  WriteBytes(laz_path, *laz);
  const absl::StatusOr<PointCloud> from_las = ReadPointCloud(las_path);
  const absl::StatusOr<PointCloud> from_laz = ReadPointCloud(laz_path);
  ASSERT_TRUE(from_las.ok()) << from_las.status();
  ASSERT_TRUE(from_laz.ok()) << from_laz.status();
  EXPECT_EQ(from_laz->positions, from_las->positions);
  EXPECT_EQ(from_laz->colors, from_las->colors);
  EXPECT_EQ(from_laz->origin, from_las->origin);

  const std::string written = TempPath("written.laz");
  ASSERT_TRUE(WritePointCloud(*from_las, written).ok());
  EXPECT_TRUE(io_internal::IsLaz(io_test::ReadBytes(written)));
  const absl::StatusOr<PointCloud> back = ReadPointCloud(written);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->size(), from_las->size());
  EXPECT_EQ(back->colors, from_las->colors);
  for (size_t i = 0; i < back->size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(back->origin[c] + back->positions[i][c],
                  from_las->origin[c] + from_las->positions[i][c], 1e-3)
          << "point " << i;
    }
  }
  EXPECT_TRUE(IsReadablePointCloudExtension("tile.laz"));
  EXPECT_TRUE(IsWritablePointCloudExtension("tile.laz"));
}

TEST(LazTest, CleanedLasFilesAreReadFromAndWrittenToLaz) {
  LasScan scan;
  scan.format = 1;
  scan.records = 4000;
  const std::string las = ScanLasFile(scan);
  const std::string las_path = TempPath("tile.las"), laz_path = TempPath("tile.laz");
  WriteBytes(las_path, las);
  WriteBytes(laz_path, *CompressLas(las));
  const absl::StatusOr<PointCloud> cloud = ReadPointCloud(las_path);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  std::vector<bool> outliers(cloud->size(), false);
  for (size_t i = 0; i < outliers.size(); i += 10) outliers[i] = true;
  const std::string from_las = TempPath("clean.las"), from_laz = TempPath("clean.laz");
  ASSERT_TRUE(
      WriteCleanedLas({las_path}, outliers, LasOutlierRecords::kClassifiedAsNoise, from_las).ok());
  ASSERT_TRUE(
      WriteCleanedLas({laz_path}, outliers, LasOutlierRecords::kClassifiedAsNoise, from_laz).ok());
  const std::string written = io_test::ReadBytes(from_laz);
  ASSERT_TRUE(io_internal::IsLaz(written));
  const absl::StatusOr<std::string> back = DecompressLaz(written);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(*back == io_test::ReadBytes(from_las));

  // Waveform records are not written as LAZ: the records go to the point writers instead.
  testing::LasLayout layout;
  layout.version_minor = 4;
  layout.format = 9;
  const std::string format9 = TempPath("format9.las");
  WriteBytes(format9, testing::LasFile(layout, {{1, 2, 3}, {4, 5, 6}}));
  const absl::Status status =
      WriteCleanedLas({format9}, {false, false}, LasOutlierRecords::kLeftOut, TempPath("9.laz"));
  EXPECT_EQ(status.code(), absl::StatusCode::kFailedPrecondition) << status;
  EXPECT_THAT(std::string(status.message()), HasSubstr("writing point format 9"));
}

// The chunk table of `laz` (our writer's: chunks of `chunk_size`, the table's offset after the
// LASzip record) written again as LASzip writes it for chunks of varying size: the chunk size
// 2^32 - 1 in the LASzip record and each chunk's record count in the table.
std::string WithVariableChunks(const std::string& laz, uint32_t chunk_size, uint64_t records) {
  constexpr size_t kChunkSize = 227 + 54 + 12;
  const uint32_t offset_to_points = io_test::Field<uint32_t>(laz, 96);
  const int64_t table_at = io_test::Field<int64_t>(laz, offset_to_points);
  const uint32_t chunks = io_test::Field<uint32_t>(laz, table_at + 4);
  // Our table's chunk sizes.
  ArithmeticDecoder decoder(absl::string_view(laz).substr(table_at + 8));
  IntegerCoder sizes(32, 2);
  std::vector<uint32_t> bytes;
  for (uint32_t i = 0; i < chunks; ++i) {
    bytes.push_back(static_cast<uint32_t>(
        sizes.Decompress(decoder, static_cast<int32_t>(i > 0 ? bytes.back() : 0), 1)));
  }
  std::string out = With<uint32_t>(laz.substr(0, table_at + 8), kChunkSize, 0xFFFFFFFFu);
  ArithmeticEncoder encoder(&out);
  IntegerCoder table(32, 2);
  uint32_t last_count = 0, last_size = 0;
  for (uint32_t i = 0; i < chunks; ++i) {
    const uint32_t count =
        static_cast<uint32_t>(std::min<uint64_t>(chunk_size, records - uint64_t{i} * chunk_size));
    table.Compress(encoder, static_cast<int32_t>(last_count), static_cast<int32_t>(count), 0);
    table.Compress(encoder, static_cast<int32_t>(last_size), static_cast<int32_t>(bytes[i]), 1);
    last_count = count;
    last_size = bytes[i];
  }
  encoder.Done();
  return out;
}

TEST(LazTest, ChunksOfVaryingSizeAndATableOffsetAtTheEndAreRead) {
  LasScan scan;
  scan.format = 2;
  scan.records = 2600;
  const std::string las = ScanLasFile(scan);
  const std::string laz = *CompressLas(las, {1000});
  const absl::StatusOr<std::string> varying = DecompressLaz(WithVariableChunks(laz, 1000, 2600));
  ASSERT_TRUE(varying.ok()) << varying.status();
  EXPECT_TRUE(*varying == las);

  // A writer that cannot seek back leaves -1 where the table's offset goes and puts the offset
  // in the file's last 8 bytes.
  const uint32_t offset_to_points = io_test::Field<uint32_t>(laz, 96);
  const int64_t table_at = io_test::Field<int64_t>(laz, offset_to_points);
  std::string streamed = With<int64_t>(laz, offset_to_points, -1);
  streamed.append(reinterpret_cast<const char*>(&table_at), 8);
  const absl::StatusOr<std::string> from_end = DecompressLaz(streamed);
  ASSERT_TRUE(from_end.ok()) << from_end.status();
  EXPECT_TRUE(*from_end == las);
}

TEST(LazTest, MalformedFilesAreRefusedWithWhatIsWrong) {
  LasScan scan;
  scan.format = 1;
  scan.records = 3000;
  const std::string las = ScanLasFile(scan);
  const std::string laz = *CompressLas(las, {1000});
  // The LASzip record follows the header (227 bytes): 54 bytes of record header, then its
  // payload: compressor, coder, version, options, chunk size, ..., items from byte 34.
  constexpr size_t kPayload = 227 + 54;
  const uint32_t offset_to_points = io_test::Field<uint32_t>(laz, 96);
  const int64_t table_at = io_test::Field<int64_t>(laz, offset_to_points);
  struct Case {
    const char* what;
    std::string bytes;
    absl::StatusCode code;
    const char* message;
  };
  const Case cases[] = {
      {"no LASzip record", With<uint32_t>(laz, 100, 0), absl::StatusCode::kInvalidArgument,
       "no LASzip record"},
      {"layered compressor", With<uint16_t>(laz, kPayload, 3), absl::StatusCode::kInvalidArgument,
       "compressor 3 does not code point format 1"},
      {"format 6", With<uint8_t>(laz, 104, 6 | 0x80), absl::StatusCode::kInvalidArgument,
       "compressor 2 does not code point format 6"},
      {"format 5", With<uint8_t>(laz, 104, 5 | 0x80), absl::StatusCode::kInvalidArgument,
       "point format 5 (waveform packets)"},
      {"LASzip 1's items", With<uint16_t>(laz, kPayload + 34 + 4, 1),
       absl::StatusCode::kInvalidArgument, "compressed as LASzip 1 did"},
      {"LASzip 1's stream", With<uint16_t>(laz, kPayload, 1), absl::StatusCode::kInvalidArgument,
       "compressed as LASzip 1 did"},
      {"items of another format", With<uint8_t>(laz, 104, 0 | 0x80),
       absl::StatusCode::kInvalidArgument, "do not code point format 0 in records of 28 bytes"},
      {"chunk table outside the file", With<int64_t>(laz, offset_to_points, int64_t{1} << 40),
       absl::StatusCode::kInvalidArgument, "the chunk table's offset 1099511627776 is not within"},
      {"chunk table version", With<uint32_t>(laz, table_at, 7), absl::StatusCode::kInvalidArgument,
       "chunk table version 7 is not 0"},
      {"fewer records than counted", With<uint32_t>(laz, 107, 4000),
       absl::StatusCode::kInvalidArgument, "hold 3000 of the header's 4000 records"},
      {"a corrupt count", With<uint32_t>(laz, 107, 4000000000u), absl::StatusCode::kInvalidArgument,
       "the point count is corrupt"},
      {"zero chunk size", With<uint32_t>(laz, kPayload + 12, 0), absl::StatusCode::kInvalidArgument,
       "chunk size is 0"},
      // Chunks of 1,000 records said to hold 50,000 each: the first runs out of bytes.
      {
          "chunks that claim more records than they hold",
          With<uint32_t>(With<uint32_t>(laz, kPayload + 12, 50000), 107, 150000),
          absl::StatusCode::kInvalidArgument,
          "chunk 1 of 3 ends",
      },
      {"truncated chunks", laz.substr(0, offset_to_points + 400),
       absl::StatusCode::kInvalidArgument, "is not within the points' data"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const absl::StatusOr<std::string> back = DecompressLaz(c.bytes);
    ASSERT_FALSE(back.ok());
    EXPECT_EQ(back.status().code(), c.code) << back.status();
    EXPECT_THAT(std::string(back.status().message()), HasSubstr(c.message));
  }
  // Through ReadPointCloud, named.
  const std::string path = TempPath("waveform.laz");
  WriteBytes(path, With<uint8_t>(laz, 104, 9 | 0x80));
  const absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
  ASSERT_FALSE(cloud.ok());
  EXPECT_THAT(std::string(cloud.status().message()), HasSubstr("waveform.laz"));
  EXPECT_THAT(std::string(cloud.status().message()), HasSubstr("decompress it first"));
}

TEST(LazTest, MalformedLayersAreRefusedWithWhatIsWrong) {
  LasScan scan;
  scan.format = 7;
  scan.records = 3000;
  const std::string las = ScanLasFile(scan);
  const std::string laz = *CompressLas(las, {1000});
  // The LASzip record follows the LAS 1.4 header (375 bytes) and its record header (54).
  constexpr size_t kPayload = 375 + 54;
  ASSERT_EQ(io_test::Field<uint16_t>(laz, kPayload), 3);  // Layered.
  // The first chunk: its first record raw (36 bytes), the number of records, the sizes of 10
  // layers (9 of POINT14, 1 of RGB14), then their bytes.
  const size_t chunk = io_test::Field<uint32_t>(laz, 96) + 8;
  const size_t sizes = chunk + 36 + 4;
  EXPECT_EQ(io_test::Field<uint32_t>(laz, chunk + 36), 1000u);
  size_t layers = 0;
  for (int i = 0; i < 10; ++i) layers += io_test::Field<uint32_t>(laz, sizes + 4 * i);
  EXPECT_GT(io_test::Field<uint32_t>(laz, sizes), 40u);  // Returns, X and Y.
  ASSERT_TRUE(DecompressLaz(laz).ok());
  struct Case {
    const char* what;
    std::string bytes;
    const char* message;
  };
  const Case cases[] = {
      {"a layer past the chunk's end", With<uint32_t>(laz, sizes + 4, 1u << 30),
       "chunk 1 of 3's layers run past its end"},
      {"no layer of returns and X, Y", With<uint32_t>(laz, sizes, 0),
       "chunk 1 of 3 has no layer of returns, X and Y"},
      {"item version 5", With<uint16_t>(laz, kPayload + 34 + 4, 5),
       "do not code point format 7 in records of 36 bytes"},
      {"format 9", With<uint8_t>(laz, 104, 9 | 0x80), "point format 9 (waveform packets)"},
      {"a layer cut short", With<uint32_t>(laz, sizes, 20), "chunk 1 of 3 ends"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const absl::StatusOr<std::string> back = DecompressLaz(c.bytes);
    ASSERT_FALSE(back.ok());
    EXPECT_EQ(back.status().code(), absl::StatusCode::kInvalidArgument) << back.status();
    EXPECT_THAT(std::string(back.status().message()), HasSubstr(c.message));
  }
  // A layer's bytes garbled: refused as running out, or decoded to other records, never read
  // out of bounds (AddressSanitizer).
  std::string garbled = laz;
  for (size_t i = sizes + 40; i < sizes + 40 + layers; i += 7) garbled[i] = static_cast<char>(i);
  const absl::StatusOr<std::string> back = DecompressLaz(garbled);
  EXPECT_TRUE(!back.ok() || *back != las);
}

TEST(LazTest, CorruptChunksDecodeWithoutReadingOutOfBounds) {
  LasScan scan;
  scan.format = 3;
  scan.extra_bytes = 1;
  scan.records = 2000;
  const std::string las = ScanLasFile(scan);
  const std::string laz = *CompressLas(las, {500});
  const uint32_t offset_to_points = io_test::Field<uint32_t>(laz, 96);
  std::mt19937 random(3);
  int refused = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::string corrupt = laz;
    // A few bytes of the chunks changed: the file is refused, or its records come out wrong;
    // AddressSanitizer checks that no read leaves the file.
    for (int k = 0; k < 3; ++k) {
      corrupt[offset_to_points + 8 + random() % (laz.size() - offset_to_points - 40)] ^=
          static_cast<char>(1 + random() % 255);
    }
    const absl::StatusOr<std::string> back = DecompressLaz(corrupt);
    if (back.ok()) {
      EXPECT_EQ(back->size(), las.size());
    } else {
      ++refused;
      EXPECT_EQ(back.status().code(), absl::StatusCode::kInvalidArgument) << back.status();
    }
  }
  // Garbage decodes to wide residuals, whose raw bits run past the chunk's end: most
  // corruptions are noticed so.
  EXPECT_GT(refused, 150);
  for (size_t end = 300; end < laz.size(); end += 997) {
    EXPECT_FALSE(DecompressLaz(laz.substr(0, end)).ok()) << "truncated at " << end;
  }
}

// Takes `appends` pieces, then fails as a full disk does, and counts what it was given.
class FailingSink : public ByteSink {
 public:
  explicit FailingSink(int appends) : appends_(appends) {}
  absl::Status Append(absl::string_view bytes) override {
    ++calls_;
    if (calls_ > appends_) return absl::ResourceExhaustedError("the disk is full");
    size_ += bytes.size();
    return absl::OkStatus();
  }
  absl::Status Patch(size_t, absl::string_view) override {
    ++calls_;
    return absl::OkStatus();
  }
  size_t size() const override { return size_; }
  int calls() const { return calls_; }

 private:
  int appends_;
  int calls_ = 0;
  size_t size_ = 0;
};

TEST(LazTest, AFailingSinkStopsTheWritingWithItsError) {
  LasScan scan;
  scan.format = 1;
  scan.records = 20000;
  const std::string las = ScanLasFile(scan);
  const std::string laz = *CompressLas(las, {900});  // 23 chunks, in waves of 4 per thread.
  for (const int appends : {0, 1, 5, 12}) {
    SCOPED_TRACE(absl::StrCat(appends, " appends taken"));
    FailingSink compressed(appends);
    const absl::Status compressing = io_internal::CompressLasTo(las, &compressed, {900});
    EXPECT_EQ(compressing.code(), absl::StatusCode::kResourceExhausted);
    EXPECT_EQ(compressed.calls(), appends + 1);  // Nothing after the failure.
    FailingSink decompressed(appends);
    const absl::Status decompressing = io_internal::DecompressLazTo(laz, &decompressed);
    EXPECT_EQ(decompressing.code(), absl::StatusCode::kResourceExhausted);
    EXPECT_EQ(decompressed.calls(), appends + 1);
  }
}

// A LAS file written in pieces (LasFileWriter: the head, records a few at a time across waves
// of chunks, then the head again and what follows the records) is the file written whole: the
// LAZ writer's bytes are CompressLas's, the plain writer's the LAS file's. Nothing reaches the
// sink before the first records.
TEST(LazTest, WritersFedInPiecesWriteTheWholeFilesBytes) {
  for (const int format : {3, 7}) {
    SCOPED_TRACE(absl::StrCat("format ", format));
    LasScan scan = testing::Las14Scan(format, 5000);
    scan.version_minor = format == 3 ? 2 : 4;
    if (format == 3) {  // LAS 1.2: nothing after the points.
      scan.after_points.clear();
      scan.evlr_count = 0;
    }
    const std::string las = ScanLasFile(scan);
    const size_t points_at = io_test::Field<uint32_t>(las, 96);
    const size_t length = io_test::Field<uint16_t>(las, 105);
    const absl::string_view head = absl::string_view(las).substr(0, points_at);
    const absl::string_view records = absl::string_view(las).substr(points_at, 5000 * length);
    const absl::string_view tail = absl::string_view(las).substr(points_at + 5000 * length);
    LazWriteOptions options{300, 3};
    options.threads = 2;  // Waves of 2,400 records.
    const absl::StatusOr<std::string> whole = CompressLas(las, options);
    ASSERT_TRUE(whole.ok()) << whole.status();

    StringSink compressed, plain;
    ASSERT_TRUE(compressed.Append("before").ok());
    io_internal::LazWriter laz_writer(&compressed, options);
    io_internal::PlainLasWriter las_writer(&plain);
    for (io_internal::LasFileWriter* writer :
         std::vector<io_internal::LasFileWriter*>{&laz_writer, &las_writer}) {
      ASSERT_TRUE(writer->Start(head).ok());
      size_t at = 0;
      for (const size_t piece : {1, 2399, 1, 7, 1500, 1092}) {
        EXPECT_TRUE(writer->AppendRecords(records.substr(at * length, piece * length)).ok());
        at += piece;
      }
      ASSERT_EQ(at, 5000u);
      EXPECT_TRUE(writer->Finish(head, tail).ok());
    }
    EXPECT_TRUE(compressed.bytes() == "before" + *whole);
    EXPECT_TRUE(plain.bytes() == las);

    // Refused: records that are not whole, a head that counts others than were written, or of
    // another size, or that does not end where its points start.
    StringSink sink;
    io_internal::LazWriter refusing(&sink, options);
    ASSERT_TRUE(refusing.Start(head).ok());
    EXPECT_TRUE(sink.bytes().empty()) << "nothing before the records";
    const absl::Status half = refusing.AppendRecords(records.substr(0, length + length / 2));
    EXPECT_EQ(half.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(half.message()), HasSubstr("are not records of"));
    EXPECT_THAT(std::string(refusing.Finish(head, tail).message()),
                HasSubstr("the head counts 5000 records and 0 were written"));
    EXPECT_THAT(std::string(refusing.Finish(head.substr(0, points_at - 1), tail).message()),
                HasSubstr("says the points start at byte"));
    EXPECT_THAT(std::string(io_internal::PlainLasWriter(&sink).Start(las).message()),
                HasSubstr("says the points start at byte"));
  }
}

TEST(LazTest, CompressingRefusesWhatItDoesNotWrite) {
  testing::LasLayout layout;
  layout.format = 10;
  layout.version_minor = 4;
  const std::string format10 = testing::LasFile(layout, {{1, 2, 3}});
  const absl::StatusOr<std::string> laz = CompressLas(format10);
  ASSERT_FALSE(laz.ok());
  EXPECT_EQ(laz.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(laz.status().message()),
              HasSubstr("writing point format 10 (waveform packets) is not supported (formats 0 "
                        "to 3 and 6 to 8 are)"));
  LasScan scan;
  scan.records = 10;
  const std::string compressed = *CompressLas(ScanLasFile(scan));
  EXPECT_THAT(std::string(CompressLas(compressed).status().message()),
              HasSubstr("compressed already"));
  EXPECT_THAT(std::string(CompressLas(ScanLasFile(scan), {0}).status().message()),
              HasSubstr("a chunk size of 0"));
}

}  // namespace
}  // namespace neuralmesh
