#include "core/io/internal/laz.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/las_layout.h"
#include "core/io/internal/laz_arithmetic_coder.h"
#include "core/io/internal/laz_integer_coder.h"
#include "core/io/internal/laz_items.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

using namespace las_layout;  // NOLINT: the header's field offsets.

constexpr absl::string_view kLaszipUser = "laszip encoded";
constexpr uint16_t kLaszipRecordId = 22204;
// The LASzip record's payload: compressor, coder, version (major, minor, revision), options,
// chunk size, the special extended records' count and offset, the item count; then per item
// its type, size and version.
constexpr size_t kLaszipFixedSize = 34;
constexpr size_t kLaszipItemSize = 6;

constexpr uint16_t kCompressorPointwise = 1;         // One stream, no chunk table (LASzip 1).
constexpr uint16_t kCompressorPointwiseChunked = 2;  // Formats 0-5.
constexpr uint16_t kCompressorLayeredChunked = 3;    // Formats 6-10 (LASzip 3).
constexpr uint32_t kVariableChunkSize = 0xFFFFFFFFu;

enum ItemType : uint16_t { kByte = 0, kPoint10 = 6, kGpsTime11 = 7, kRgb12 = 8 };
constexpr uint16_t kItemVersion = 2;

// Decompressed records above this many times the bytes that code them are a corrupt count:
// even constant records take some bits each.
constexpr uint64_t kMaxExpansion = 4096;

// Bytes past the end of a chunk that its decoder may read: the encoder ends a chunk with zeros
// enough for none. A corrupt chunk decodes to wide residuals whose raw bits run past its end
// within a few records; decoding checks every kOverrunCheck records, so that a chunk that
// claims more records than its bytes can hold costs about as much as its bytes.
constexpr size_t kOverrunAllowed = 4;
constexpr uint64_t kOverrunCheck = 256;

// Scans compress to a tenth of their size or so; the output is reserved for at most this many
// times the compressed data, and grows chunk by chunk past it (a corrupt count).
constexpr uint64_t kReservedExpansion = 64;

template <typename T>
T Load(absl::string_view data, size_t offset) {
  return LoadScalar<T>(data.data() + offset, /*big_endian=*/false);
}

absl::Status Invalid(absl::string_view message) {
  return absl::InvalidArgumentError(absl::StrCat("LAZ: ", message));
}

struct Item {
  uint16_t type = 0, size = 0, version = 0;
  bool operator==(const Item& other) const {
    return type == other.type && size == other.size && version == other.version;
  }
};

std::string ItemsText(const std::vector<Item>& items) {
  return absl::StrJoin(items, ", ", [](std::string* out, const Item& item) {
    absl::StrAppend(out, "type ", item.type, " of ", item.size, " bytes, version ", item.version);
  });
}

// What the public header says of the points, checked against the file's size.
struct Header {
  int minor = 0;
  size_t header_size = 0;
  size_t offset_to_points = 0;
  uint32_t vlr_count = 0;
  uint8_t format_byte = 0;
  size_t record_length = 0;
  uint64_t count = 0;
  uint64_t evlr_start = 0;  // LAS 1.4; 0 without extended records.
  int format() const { return format_byte & ~kCompressedBits; }
};

absl::StatusOr<Header> ReadHeader(absl::string_view data, absl::string_view what) {
  if (data.size() < kLegacyHeaderSize || data.substr(0, 4) != "LASF") {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": ",
        data.substr(0, 4) == "LASF" ? "the file ends within its header" : "no LASF signature"));
  }
  Header header;
  header.minor = static_cast<uint8_t>(data[kVersionMinor]);
  header.header_size = Load<uint16_t>(data, kHeaderSize);
  header.offset_to_points = Load<uint32_t>(data, kOffsetToPoints);
  header.vlr_count = Load<uint32_t>(data, kVlrCount);
  header.format_byte = static_cast<uint8_t>(data[kPointFormat]);
  header.record_length = Load<uint16_t>(data, kRecordLength);
  header.count = Load<uint32_t>(data, kLegacyPointCount);
  if (header.header_size < kLegacyHeaderSize || header.header_size > header.offset_to_points ||
      header.offset_to_points > data.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": a header of ", header.header_size, " bytes and points from byte ",
                     header.offset_to_points, " do not fit in the file's ", data.size(), " bytes"));
  }
  if (header.minor >= 4 && header.header_size >= kHeaderSize14) {
    const uint64_t count14 = Load<uint64_t>(data, kPointCount);
    if (count14 != 0) header.count = count14;
    header.evlr_start = Load<uint64_t>(data, kEvlrStart);
  }
  if (header.record_length == 0) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": records of 0 bytes"));
  }
  return header;
}

// A variable-length record: where it starts, its user and id, and its payload.
struct Vlr {
  size_t at = 0;
  absl::string_view user;
  uint16_t id = 0;
  absl::string_view payload;
  size_t end() const { return at + kVlrHeaderSize + payload.size(); }
};

absl::StatusOr<std::vector<Vlr>> ReadVlrs(absl::string_view data, const Header& header,
                                          absl::string_view what) {
  std::vector<Vlr> vlrs;
  size_t at = header.header_size;
  for (uint32_t i = 0; i < header.vlr_count; ++i) {
    if (at + kVlrHeaderSize > header.offset_to_points ||
        at + kVlrHeaderSize + Load<uint16_t>(data, at + kVlrLength) > header.offset_to_points) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": variable-length record ", i + 1, " of ", header.vlr_count,
                       " runs past the start of the points (byte ", header.offset_to_points, ")"));
    }
    Vlr vlr;
    vlr.at = at;
    vlr.user = data.substr(at + kVlrUser, 16);
    vlr.user = vlr.user.substr(0, vlr.user.find('\0'));
    vlr.id = Load<uint16_t>(data, at + kVlrRecordId);
    vlr.payload = data.substr(at + kVlrHeaderSize, Load<uint16_t>(data, at + kVlrLength));
    vlrs.push_back(vlr);
    at = vlr.end();
  }
  return vlrs;
}

// The items of a record of point format 0 to 3 with `extra` bytes after its fields.
std::vector<Item> ItemsOf(int format, size_t extra) {
  std::vector<Item> items = {{kPoint10, laz::Point10Coder::kSize, kItemVersion}};
  if (format == 1 || format == 3) {
    items.push_back({kGpsTime11, laz::GpsTime11Coder::kSize, kItemVersion});
  }
  if (format == 2 || format == 3) {
    items.push_back({kRgb12, laz::Rgb12Coder::kSize, kItemVersion});
  }
  if (extra > 0) items.push_back({kByte, static_cast<uint16_t>(extra), kItemVersion});
  return items;
}

// The record lengths of formats 0 to 3 without extra bytes.
constexpr size_t kBaseLength[] = {20, 28, 26, 34};

// Codes whole records of format 0 to 3, item after item.
class RecordCoder {
 public:
  RecordCoder(int format, size_t record_length)
      : gps_time_(format == 1 || format == 3),
        rgb_(format == 2 || format == 3),
        bytes_(record_length - kBaseLength[format]) {}

  void Reset(const uint8_t* first) {
    Apply(first, [](auto& coder, const uint8_t* item) { coder.Reset(item); });
  }
  void Encode(laz::ArithmeticEncoder& encoder, const uint8_t* record) {
    Apply(record, [&](auto& coder, const uint8_t* item) { coder.Encode(encoder, item); });
  }
  void Decode(laz::ArithmeticDecoder& decoder, uint8_t* record) {
    Apply(record, [&](auto& coder, uint8_t* item) { coder.Decode(decoder, item); });
  }

 private:
  template <typename Byte, typename Function>
  void Apply(Byte* record, Function function) {
    size_t at = 0;
    function(point_, record);
    at += laz::Point10Coder::kSize;
    if (gps_time_) {
      function(gps_time_coder_, record + at);
      at += laz::GpsTime11Coder::kSize;
    }
    if (rgb_) {
      function(rgb_coder_, record + at);
      at += laz::Rgb12Coder::kSize;
    }
    if (bytes_.size() > 0) function(bytes_, record + at);
  }

  bool gps_time_, rgb_;
  laz::Point10Coder point_;
  laz::GpsTime11Coder gps_time_coder_;
  laz::Rgb12Coder rgb_coder_;
  laz::BytesCoder bytes_;
};

// Where a chunk's bytes are and how many records it holds.
struct Chunk {
  size_t at = 0;
  size_t size = 0;
  uint64_t count = 0;
};

// The chunks as the chunk table lists them: the table's offset is the point data's first 8
// bytes, and the chunks follow those, one after another.
absl::StatusOr<std::vector<Chunk>> ReadChunkTable(absl::string_view laz, const Header& header,
                                                  uint32_t chunk_size) {
  const size_t chunks_start = header.offset_to_points + 8;
  if (chunks_start > laz.size()) return Invalid("the file ends before its chunk table's offset");
  int64_t table_at = Load<int64_t>(laz, header.offset_to_points);
  if (table_at == -1 && laz.size() >= chunks_start + 8) {
    // A writer that could not seek back put the offset in the file's last 8 bytes.
    table_at = Load<int64_t>(laz, laz.size() - 8);
  }
  if (table_at < static_cast<int64_t>(chunks_start) ||
      static_cast<uint64_t>(table_at) > laz.size() - 8) {
    return Invalid(absl::StrCat("the chunk table's offset ", table_at,
                                " is not within the points' data (bytes ", chunks_start, " to ",
                                laz.size(), ")"));
  }
  const size_t table = static_cast<size_t>(table_at);
  if (Load<uint32_t>(laz, table) != 0) {
    return Invalid(absl::StrCat("chunk table version ", Load<uint32_t>(laz, table), " is not 0"));
  }
  const uint32_t chunk_count = Load<uint32_t>(laz, table + 4);
  if (chunk_count > table - chunks_start) {
    return Invalid(absl::StrCat(chunk_count, " chunks do not fit in the ", table - chunks_start,
                                " bytes of the points' data"));
  }
  std::vector<Chunk> chunks(chunk_count);
  laz::ArithmeticDecoder decoder(laz.substr(table + 8));
  laz::IntegerCoder coder(32, 2);
  uint32_t last_count = 0, last_size = 0;
  size_t at = chunks_start;
  uint64_t remaining = header.count;
  for (uint32_t i = 0; i < chunk_count; ++i) {
    if (chunk_size == kVariableChunkSize) {
      last_count =
          static_cast<uint32_t>(coder.Decompress(decoder, static_cast<int32_t>(last_count), 0));
      chunks[i].count = last_count;
    } else {
      chunks[i].count = std::min<uint64_t>(chunk_size, remaining);
    }
    last_size =
        static_cast<uint32_t>(coder.Decompress(decoder, static_cast<int32_t>(last_size), 1));
    chunks[i].at = at;
    chunks[i].size = last_size;
    if (last_size > table - at) {
      return Invalid(absl::StrCat("chunk ", i + 1, " of ", chunk_count, " (", last_size,
                                  " bytes from byte ", at, ") runs past the chunk table at byte ",
                                  table));
    }
    if (chunks[i].count == 0 || chunks[i].count > remaining) {
      return Invalid(absl::StrCat(
          "the chunk table's ", chunk_count, " chunks of ",
          chunk_size == kVariableChunkSize ? std::string("listed sizes") : absl::StrCat(chunk_size),
          " records do not hold the header's ", header.count, " records"));
    }
    remaining -= chunks[i].count;
    at += last_size;
  }
  if (remaining != 0) {
    return Invalid(absl::StrCat("the chunk table's ", chunk_count, " chunks hold ",
                                header.count - remaining, " of the header's ", header.count,
                                " records"));
  }
  return chunks;
}

// Checks the LASzip record against the header and returns its chunk size.
absl::StatusOr<uint32_t> CheckLaszipRecord(absl::string_view payload, const Header& header) {
  if (payload.size() < kLaszipFixedSize) {
    return Invalid(absl::StrCat("the LASzip record has ", payload.size(), " bytes, not ",
                                kLaszipFixedSize, " or more"));
  }
  const uint16_t compressor = Load<uint16_t>(payload, 0);
  const uint16_t coder = Load<uint16_t>(payload, 2);
  const uint32_t chunk_size = Load<uint32_t>(payload, 12);
  const uint16_t item_count = Load<uint16_t>(payload, 32);
  if (payload.size() < kLaszipFixedSize + kLaszipItemSize * item_count) {
    return Invalid(absl::StrCat("the LASzip record's ", item_count, " items do not fit in its ",
                                payload.size(), " bytes"));
  }
  std::vector<Item> items(item_count);
  for (uint16_t i = 0; i < item_count; ++i) {
    const size_t at = kLaszipFixedSize + kLaszipItemSize * i;
    items[i] = {Load<uint16_t>(payload, at), Load<uint16_t>(payload, at + 2),
                Load<uint16_t>(payload, at + 4)};
  }
  if (compressor == kCompressorLayeredChunked || header.format() >= 6) {
    return Invalid(absl::StrCat(
        "point format ", header.format(),
        " is compressed in layers (LASzip 3, LAS 1.4 formats 6 to 10), which is not read here; "
        "decompress it first (laszip, pdal translate)"));
  }
  if (header.format() >= 4) {
    return Invalid(absl::StrCat("point format ", header.format(),
                                " (waveform packets) is not read here; decompress it first "
                                "(laszip, pdal translate)"));
  }
  if (compressor != kCompressorPointwise && compressor != kCompressorPointwiseChunked) {
    return Invalid(absl::StrCat("compressor ", compressor, " is not 1, 2 or 3"));
  }
  if (coder != 0) return Invalid(absl::StrCat("coder ", coder, " is not 0 (arithmetic)"));
  const bool laszip1 =
      compressor == kCompressorPointwise ||
      std::any_of(items.begin(), items.end(), [](const Item& item) { return item.version == 1; });
  if (laszip1) {
    return Invalid(
        "the records are compressed as LASzip 1 did (one stream, or item coders of version 1), "
        "which is not read here; compress the file again with a newer laszip");
  }
  if (header.record_length < kBaseLength[header.format()] ||
      items != ItemsOf(header.format(), header.record_length - kBaseLength[header.format()])) {
    return Invalid(absl::StrCat("the LASzip record's items (", ItemsText(items),
                                ") do not code point format ", header.format(), " in records of ",
                                header.record_length, " bytes"));
  }
  if (chunk_size == 0) return Invalid("the LASzip record's chunk size is 0");
  return chunk_size;
}

// Decodes `chunk` (its first record raw, then the coded rest) into `count` records at `out`;
// the chunk is number `index` (from 0) of `chunks`, for messages.
absl::Status DecodeChunk(absl::string_view chunk, uint64_t count, RecordCoder& coder,
                         size_t record_length, uint8_t* out, size_t index, size_t chunks) {
  const auto name = [&] { return absl::StrCat("chunk ", index + 1, " of ", chunks); };
  if (chunk.size() < record_length) {
    return Invalid(absl::StrCat(name(), " has ", chunk.size(),
                                " bytes, fewer than its first raw record's ", record_length));
  }
  std::memcpy(out, chunk.data(), record_length);
  if (count == 1) return absl::OkStatus();
  coder.Reset(out);
  laz::ArithmeticDecoder decoder(chunk.substr(record_length));
  for (uint64_t i = 1; i < count; ++i) {
    coder.Decode(decoder, out + i * record_length);
    if (i % kOverrunCheck == 0 && decoder.overrun() > kOverrunAllowed) break;
  }
  if (decoder.overrun() > kOverrunAllowed) {
    return Invalid(absl::StrCat(name(), " ends ", decoder.overrun(), " bytes before its ", count,
                                " records are decoded: the file is truncated or corrupt"));
  }
  return absl::OkStatus();
}

void SetUint32(uint32_t value, size_t at, std::string* out) { StoreLittleEndian(value, at, out); }
void SetUint64(uint64_t value, size_t at, std::string* out) { StoreLittleEndian(value, at, out); }

}  // namespace

bool IsLaz(absl::string_view data) {
  return data.size() > kPointFormat && data.substr(0, 4) == "LASF" &&
         (static_cast<uint8_t>(data[kPointFormat]) & kCompressedBits) != 0;
}

absl::StatusOr<std::string> DecompressLaz(absl::string_view laz) {
  NM_ASSIGN_OR_RETURN(const Header header, ReadHeader(laz, "LAZ"));
  if ((header.format_byte & kCompressedBits) == 0) {
    return Invalid("the point format carries no compression bits: a LAS file, not LAZ");
  }
  NM_ASSIGN_OR_RETURN(const std::vector<Vlr> vlrs, ReadVlrs(laz, header, "LAZ"));
  const Vlr* laszip = nullptr;
  for (const Vlr& vlr : vlrs) {
    if (vlr.user == kLaszipUser && vlr.id == kLaszipRecordId) laszip = &vlr;
  }
  if (laszip == nullptr) {
    return Invalid(
        "no LASzip record (user \"laszip encoded\", record 22204) says how the "
        "points are compressed");
  }
  NM_ASSIGN_OR_RETURN(const uint32_t chunk_size, CheckLaszipRecord(laszip->payload, header));
  const size_t points_end =
      header.evlr_start > header.offset_to_points && header.evlr_start <= laz.size()
          ? static_cast<size_t>(header.evlr_start)
          : laz.size();
  const uint64_t compressed = points_end - header.offset_to_points;
  if (header.count > (kMaxExpansion * compressed + (1u << 20)) / header.record_length) {
    return Invalid(absl::StrCat(header.count, " records of ", header.record_length,
                                " bytes cannot come from ", compressed,
                                " bytes of compressed data: the point count is corrupt"));
  }
  std::vector<Chunk> chunks;
  if (header.count > 0) {
    NM_ASSIGN_OR_RETURN(chunks, ReadChunkTable(laz, header, chunk_size));
  }

  const size_t laszip_size = laszip->end() - laszip->at;
  std::string las;
  las.reserve(header.offset_to_points +
              std::min(header.count * header.record_length,
                       kReservedExpansion * compressed + (uint64_t{1} << 20)));
  absl::StrAppend(&las, laz.substr(0, laszip->at));
  absl::StrAppend(&las, laz.substr(laszip->end(), header.offset_to_points - laszip->end()));
  las[kPointFormat] = static_cast<char>(header.format());
  SetUint32(header.vlr_count - 1, kVlrCount, &las);
  SetUint32(static_cast<uint32_t>(header.offset_to_points - laszip_size), kOffsetToPoints, &las);
  RecordCoder coder(header.format(), header.record_length);
  for (size_t i = 0; i < chunks.size(); ++i) {
    const size_t chunk_at = las.size();
    las.resize(chunk_at + chunks[i].count * header.record_length);
    NM_RETURN_IF_ERROR(DecodeChunk(laz.substr(chunks[i].at, chunks[i].size), chunks[i].count, coder,
                                   header.record_length, reinterpret_cast<uint8_t*>(&las[chunk_at]),
                                   i, chunks.size()));
  }
  if (header.evlr_start != 0 && points_end < laz.size()) {
    SetUint64(las.size(), kEvlrStart, &las);
    absl::StrAppend(&las, laz.substr(points_end));
  }
  return las;
}

absl::StatusOr<std::string> CompressLas(absl::string_view las, const LazWriteOptions& options) {
  NM_ASSIGN_OR_RETURN(const Header header, ReadHeader(las, "LAS"));
  if ((header.format_byte & kCompressedBits) != 0) {
    return absl::InvalidArgumentError("LAS: the points are compressed already (LAZ)");
  }
  if (header.format_byte > 3) {
    return absl::FailedPreconditionError(
        absl::StrCat("LAZ: writing point format ", int{header.format_byte},
                     " is not supported (formats 0 to 3 are); write .las"));
  }
  const int format = header.format_byte;
  if (header.record_length < kBaseLength[format]) {
    return absl::InvalidArgumentError(absl::StrCat("LAS: records of ", header.record_length,
                                                   " bytes are shorter than format ", format, "'s ",
                                                   kBaseLength[format]));
  }
  if (header.count > (las.size() - header.offset_to_points) / header.record_length) {
    return absl::InvalidArgumentError(absl::StrCat(
        "LAS: ", header.count, " points of ", header.record_length, " bytes from byte ",
        header.offset_to_points, " do not fit in the file's ", las.size(), " bytes"));
  }
  if (options.chunk_size == 0) return absl::InvalidArgumentError("LAZ: a chunk size of 0");
  NM_ASSIGN_OR_RETURN(const std::vector<Vlr> vlrs, ReadVlrs(las, header, "LAS"));
  const size_t vlrs_end = vlrs.empty() ? header.header_size : vlrs.back().end();
  const size_t points_end = header.offset_to_points + header.count * header.record_length;

  // The LASzip record, after the others (padding before the points stays after it).
  const std::vector<Item> items = ItemsOf(format, header.record_length - kBaseLength[format]);
  std::string record(kVlrHeaderSize, '\0');
  record.replace(kVlrUser, kLaszipUser.size(), kLaszipUser.data(), kLaszipUser.size());
  StoreLittleEndian(kLaszipRecordId, kVlrRecordId, &record);
  StoreLittleEndian(static_cast<uint16_t>(kLaszipFixedSize + kLaszipItemSize * items.size()),
                    kVlrLength, &record);
  constexpr absl::string_view kDescription = "LAZ written by neuralmesh";
  record.replace(kVlrLength + 2, kDescription.size(), kDescription.data(), kDescription.size());
  AppendLittleEndian(kCompressorPointwiseChunked, &record);
  AppendLittleEndian(uint16_t{0}, &record);  // The arithmetic coder.
  record.append({2, 2, 0, 0});               // Version 2.2, revision 0.
  AppendLittleEndian(uint32_t{0}, &record);  // Options.
  AppendLittleEndian(options.chunk_size, &record);
  AppendLittleEndian(int64_t{-1}, &record);  // No special extended records.
  AppendLittleEndian(int64_t{-1}, &record);
  AppendLittleEndian(static_cast<uint16_t>(items.size()), &record);
  for (const Item& item : items) {
    AppendLittleEndian(item.type, &record);
    AppendLittleEndian(item.size, &record);
    AppendLittleEndian(item.version, &record);
  }

  std::string laz;
  absl::StrAppend(&laz, las.substr(0, vlrs_end));
  laz.append(record);
  absl::StrAppend(&laz, las.substr(vlrs_end, header.offset_to_points - vlrs_end));
  laz[kPointFormat] = static_cast<char>(header.format_byte | 0x80);
  SetUint32(header.vlr_count + 1, kVlrCount, &laz);
  SetUint32(static_cast<uint32_t>(laz.size()), kOffsetToPoints, &laz);
  const size_t table_offset_at = laz.size();
  laz.append(8, '\0');

  const uint8_t* records = reinterpret_cast<const uint8_t*>(las.data() + header.offset_to_points);
  RecordCoder coder(format, header.record_length);
  std::vector<uint32_t> chunk_sizes;
  for (uint64_t first = 0; first < header.count; first += options.chunk_size) {
    const uint64_t end = std::min<uint64_t>(header.count, first + options.chunk_size);
    const size_t chunk_at = laz.size();
    const uint8_t* record_at = records + first * header.record_length;
    laz.append(reinterpret_cast<const char*>(record_at), header.record_length);
    if (end - first > 1) {
      coder.Reset(record_at);
      laz::ArithmeticEncoder encoder(&laz);
      for (uint64_t i = first + 1; i < end; ++i) {
        coder.Encode(encoder, records + i * header.record_length);
      }
      encoder.Done();
    }
    chunk_sizes.push_back(static_cast<uint32_t>(laz.size() - chunk_at));
  }

  SetUint64(laz.size(), table_offset_at, &laz);
  AppendLittleEndian(uint32_t{0}, &laz);  // Version.
  AppendLittleEndian(static_cast<uint32_t>(chunk_sizes.size()), &laz);
  if (!chunk_sizes.empty()) {
    laz::ArithmeticEncoder encoder(&laz);
    laz::IntegerCoder sizes(32, 2);
    uint32_t last = 0;
    for (const uint32_t size : chunk_sizes) {
      sizes.Compress(encoder, static_cast<int32_t>(last), static_cast<int32_t>(size), 1);
      last = size;
    }
    encoder.Done();
  }
  if (header.evlr_start != 0 && header.evlr_start >= points_end && points_end < las.size()) {
    SetUint64(laz.size() + (header.evlr_start - points_end), kEvlrStart, &laz);
  }
  absl::StrAppend(&laz, las.substr(points_end));
  return laz;
}

}  // namespace neuralmesh::io_internal
