#include "core/io/internal/laz.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/las_layout.h"
#include "core/io/internal/laz_arithmetic_coder.h"
#include "core/io/internal/laz_integer_coder.h"
#include "core/io/internal/laz_items.h"
#include "core/io/internal/laz_layered_items.h"
#include "core/parallel_ranges.h"
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

enum ItemType : uint16_t {
  kByte = 0,
  kPoint10 = 6,
  kGpsTime11 = 7,
  kRgb12 = 8,
  kPoint14 = 10,
  kRgb14 = 11,
  kRgbNir14 = 12,
  kByte14 = 14
};
// The item version of formats 0-3 (those of formats 6-8 are 3 or 4).
constexpr uint16_t kPointwiseVersion = 2;

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
// times the compressed data, and grows wave by wave of chunks past it (a corrupt count).
constexpr uint64_t kReservedExpansion = 64;

// Chunks are coded in waves of this many per thread: each thread codes a run of consecutive
// chunks (independent by design), with coders of its own.
constexpr size_t kChunksPerThread = 4;

size_t ThreadCount(int threads) {
  return threads > 0 ? static_cast<size_t>(threads)
                     : std::max(1u, std::thread::hardware_concurrency());
}

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

// The record lengths of formats 0 to 8 without extra bytes (4 and 5 are not coded here).
constexpr size_t kBaseLength[] = {20, 28, 26, 34, 57, 63, 30, 36, 38};

bool IsLayered(int format) { return format >= 6; }

// The items of a record of point format 0 to 3 or 6 to 8 with `extra` bytes after its fields,
// in item `version` (2 for formats 0-3, 3 or 4 for 6-8).
std::vector<Item> ItemsOf(int format, size_t extra, uint16_t version) {
  std::vector<Item> items;
  const uint16_t extra_size = static_cast<uint16_t>(extra);
  if (IsLayered(format)) {
    items.push_back({kPoint14, laz::Point14Coder::kSize, version});
    if (format == 7) items.push_back({kRgb14, 6, version});
    if (format == 8) items.push_back({kRgbNir14, 8, version});
    if (extra > 0) items.push_back({kByte14, extra_size, version});
    return items;
  }
  items.push_back({kPoint10, laz::Point10Coder::kSize, version});
  if (format == 1 || format == 3) items.push_back({kGpsTime11, laz::GpsTimeCoder::kSize, version});
  if (format == 2 || format == 3) items.push_back({kRgb12, laz::Rgb12Coder::kSize, version});
  if (extra > 0) items.push_back({kByte, extra_size, version});
  return items;
}

}  // namespace

// Codes the records of one chunk: its first record raw, the others coded.
class ChunkCoder {
 public:
  virtual ~ChunkCoder() = default;
  // Appends the chunk of the `count` records at `records` to `out`.
  virtual void Encode(const uint8_t* records, uint64_t count, std::string* out) = 0;
  // Decodes `chunk` into `count` records at `out`; `name` names the chunk for messages.
  virtual absl::Status Decode(absl::string_view chunk, uint64_t count, uint8_t* out,
                              absl::string_view name) = 0;
  // Of the last Decode: the bytes of `chunk` its records took, and how many it read past the
  // end of `chunk` (0 for a whole chunk).
  size_t decoded_length() const { return decoded_length_; }
  size_t decoded_overrun() const { return decoded_overrun_; }

 protected:
  explicit ChunkCoder(size_t record_length) : record_length_(record_length) {}

  // Copies the chunk's first record to `out`.
  absl::Status DecodeFirst(absl::string_view chunk, uint8_t* out, absl::string_view name) const {
    if (chunk.size() < record_length_) {
      return Invalid(absl::StrCat(name, " has ", chunk.size(),
                                  " bytes, fewer than its first raw record's ", record_length_));
    }
    std::memcpy(out, chunk.data(), record_length_);
    return absl::OkStatus();
  }

  // Decodes records 1 to count - 1 with `decode_record`, stopping early once `overrun` says
  // the coded bytes ran out.
  template <typename DecodeRecord, typename Overrun>
  absl::Status DecodeRest(uint64_t count, uint8_t* out, absl::string_view name,
                          DecodeRecord decode_record, Overrun overrun) const {
    for (uint64_t i = 1; i < count; ++i) {
      decode_record(out + i * record_length_);
      if (i % kOverrunCheck == 0 && overrun() > kOverrunAllowed) break;
    }
    if (overrun() > kOverrunAllowed) {
      return Invalid(absl::StrCat(name, " ends ", overrun(), " bytes before its ", count,
                                  " records are decoded: the file is truncated or corrupt"));
    }
    return absl::OkStatus();
  }

  size_t record_length_;
  size_t decoded_length_ = 0;
  size_t decoded_overrun_ = 0;
};

// Formats 0 to 3: the items after one another in one stream (item version 2).
class PointwiseChunkCoder : public ChunkCoder {
 public:
  PointwiseChunkCoder(int format, size_t record_length)
      : ChunkCoder(record_length),
        gps_time_(format == 1 || format == 3),
        rgb_(format == 2 || format == 3),
        bytes_(record_length - kBaseLength[format]) {}

  void Encode(const uint8_t* records, uint64_t count, std::string* out) override {
    out->append(reinterpret_cast<const char*>(records), record_length_);
    if (count == 1) return;
    Apply(records, [](auto& coder, const uint8_t* item) { coder.Reset(item); });
    laz::ArithmeticEncoder encoder(out);
    for (uint64_t i = 1; i < count; ++i) {
      Apply(records + i * record_length_,
            [&](auto& coder, const uint8_t* item) { coder.Encode(encoder, item); });
    }
    encoder.Done();
  }

  absl::Status Decode(absl::string_view chunk, uint64_t count, uint8_t* out,
                      absl::string_view name) override {
    decoded_length_ = record_length_;
    decoded_overrun_ = 0;
    NM_RETURN_IF_ERROR(DecodeFirst(chunk, out, name));
    if (count == 1) return absl::OkStatus();
    Apply(static_cast<const uint8_t*>(out),
          [](auto& coder, const uint8_t* item) { coder.Reset(item); });
    laz::ArithmeticDecoder decoder(chunk.substr(record_length_));
    const absl::Status decoded = DecodeRest(
        count, out, name,
        [&](uint8_t* record) {
          Apply(record, [&](auto& coder, uint8_t* item) { coder.Decode(decoder, item); });
        },
        [&] { return decoder.overrun(); });
    // The coder's stream ends exactly where its decoding ends (ArithmeticEncoder::Done).
    decoded_length_ = record_length_ + decoder.consumed();
    decoded_overrun_ = decoder.overrun();
    return decoded;
  }

 private:
  template <typename Byte, typename Function>
  void Apply(Byte* record, Function function) {
    size_t at = 0;
    function(point_, record);
    at += laz::Point10Coder::kSize;
    if (gps_time_) {
      function(gps_time_coder_, record + at);
      at += laz::GpsTimeCoder::kSize;
    }
    if (rgb_) {
      function(rgb_coder_, record + at);
      at += laz::Rgb12Coder::kSize;
    }
    if (bytes_.size() > 0) function(bytes_, record + at);
  }

  bool gps_time_, rgb_;
  laz::Point10Coder point_;
  laz::GpsTimeCoder gps_time_coder_{2};
  laz::Rgb12Coder rgb_coder_;
  laz::BytesCoder bytes_;
};

// Formats 6 to 8 (item versions 3 and 4): after the first record, the number of records, the
// size of every item's every layer, then the layers' bytes, all in item order.
class LayeredChunkCoder : public ChunkCoder {
 public:
  LayeredChunkCoder(int format, size_t record_length, uint16_t version)
      : ChunkCoder(record_length), point_(version) {
    if (format == 7 || format == 8) rgb_.emplace(/*near_infrared=*/format == 8, version);
    const size_t extra = record_length - kBaseLength[format];
    if (extra > 0) bytes_.emplace(extra, version);
  }

  void Encode(const uint8_t* records, uint64_t count, std::string* out) override {
    out->append(reinterpret_cast<const char*>(records), record_length_);
    uint32_t channel = 0;
    point_.StartEncoding(records, channel);
    if (rgb_) rgb_->StartEncoding(records + rgb_at(), channel);
    if (bytes_) bytes_->StartEncoding(records + bytes_at(), channel);
    for (uint64_t i = 1; i < count; ++i) {
      const uint8_t* record = records + i * record_length_;
      channel = 0;  // As LASzip passes it on (laz_layered_items.h).
      point_.Encode(record, channel);
      if (rgb_) rgb_->Encode(record + rgb_at(), channel);
      if (bytes_) bytes_->Encode(record + bytes_at(), channel);
    }
    std::vector<std::string> layers;
    ForEachLayers([&](laz::Layers& item_layers) { item_layers.FinishEncoding(&layers); });
    AppendLittleEndian(static_cast<uint32_t>(count), out);
    for (const std::string& layer : layers) {
      AppendLittleEndian(static_cast<uint32_t>(layer.size()), out);
    }
    for (const std::string& layer : layers) out->append(layer);
  }

  absl::Status Decode(absl::string_view chunk, uint64_t count, uint8_t* out,
                      absl::string_view name) override {
    decoded_length_ = record_length_;
    decoded_overrun_ = 0;
    NM_RETURN_IF_ERROR(DecodeFirst(chunk, out, name));
    size_t layer_count = 0;
    ForEachLayers([&](laz::Layers& item_layers) { layer_count += item_layers.count(); });
    // The number of records (which LASzip does not read either), then the layers' sizes: a
    // chunk of one record has them too (its layers are empty), which only a chunk read without
    // its table needs, for its length.
    size_t at = record_length_ + 4;
    if (chunk.size() < at + 4 * layer_count) {
      decoded_overrun_ = at + 4 * layer_count - chunk.size();
      if (count == 1) return absl::OkStatus();
      return Invalid(absl::StrCat(name, " ends within the sizes of its ", layer_count, " layers"));
    }
    std::vector<absl::string_view> layers(layer_count);
    size_t layer_at = at + 4 * layer_count;
    for (absl::string_view& layer : layers) {
      const uint32_t size = Load<uint32_t>(chunk, at);
      at += 4;
      if (size > chunk.size() - layer_at) {
        decoded_overrun_ = size - (chunk.size() - layer_at);
        if (count == 1) return absl::OkStatus();
        return Invalid(absl::StrCat(name, "'s layers run past its end (", chunk.size(), " bytes)"));
      }
      layer = chunk.substr(layer_at, size);
      layer_at += size;
    }
    decoded_length_ = layer_at;
    if (count == 1) return absl::OkStatus();
    if (layers[0].empty()) {
      return Invalid(absl::StrCat(name, " has no layer of returns, X and Y"));
    }
    uint32_t channel = 0;
    const absl::string_view* item_layers = layers.data();
    point_.StartDecoding(out, channel, item_layers);
    item_layers += point_.layers().count();
    if (rgb_) {
      rgb_->StartDecoding(out + rgb_at(), channel, item_layers);
      item_layers += rgb_->layers().count();
    }
    if (bytes_) bytes_->StartDecoding(out + bytes_at(), channel, item_layers);
    return DecodeRest(
        count, out, name,
        [&](uint8_t* record) {
          channel = 0;
          point_.Decode(record, channel);
          if (rgb_) rgb_->Decode(record + rgb_at(), channel);
          if (bytes_) bytes_->Decode(record + bytes_at(), channel);
        },
        [&] {
          size_t most = 0;
          ForEachLayers(
              [&](laz::Layers& item_layers) { most = std::max(most, item_layers.overrun()); });
          return most;
        });
  }

 private:
  size_t rgb_at() const { return laz::Point14Coder::kSize; }
  size_t bytes_at() const { return rgb_at() + (rgb_ ? rgb_->size() : 0); }

  template <typename Function>
  void ForEachLayers(Function function) {
    function(point_.layers());
    if (rgb_) function(rgb_->layers());
    if (bytes_) function(bytes_->layers());
  }

  laz::Point14Coder point_;
  std::optional<laz::Rgb14Coder> rgb_;
  std::optional<laz::Bytes14Coder> bytes_;
};

std::unique_ptr<ChunkCoder> MakeChunkCoder(int format, size_t record_length, uint16_t version) {
  if (IsLayered(format)) return std::make_unique<LayeredChunkCoder>(format, record_length, version);
  return std::make_unique<PointwiseChunkCoder>(format, record_length);
}

namespace {

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

// What the LASzip record says of the chunks.
struct Compression {
  uint32_t chunk_size = 0;
  uint16_t item_version = 0;
};

// Checks the LASzip record against the header.
absl::StatusOr<Compression> CheckLaszipRecord(absl::string_view payload, const Header& header) {
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
  const int format = header.format();
  if (format == 4 || format == 5 || format == 9 || format == 10) {
    return Invalid(absl::StrCat("point format ", format,
                                " (waveform packets) is not read here; decompress it first "
                                "(laszip, pdal translate)"));
  }
  if (format > 10) return Invalid(absl::StrCat("point format ", format, " is not 0 to 10"));
  if (compressor != kCompressorPointwise && compressor != kCompressorPointwiseChunked &&
      compressor != kCompressorLayeredChunked) {
    return Invalid(absl::StrCat("compressor ", compressor, " is not 1, 2 or 3"));
  }
  if (coder != 0) return Invalid(absl::StrCat("coder ", coder, " is not 0 (arithmetic)"));
  if ((compressor == kCompressorLayeredChunked) != IsLayered(format)) {
    return Invalid(absl::StrCat("compressor ", compressor, " does not code point format ", format,
                                ": formats 6 to 10 are compressed in layers (compressor 3), "
                                "formats 0 to 5 are not"));
  }
  const bool laszip1 =
      compressor == kCompressorPointwise ||
      std::any_of(items.begin(), items.end(), [](const Item& item) { return item.version == 1; });
  if (laszip1) {
    return Invalid(
        "the records are compressed as LASzip 1 did (one stream, or item coders of version 1), "
        "which is not read here; compress the file again with a newer laszip");
  }
  const uint16_t version = items.empty() ? 0 : items[0].version;
  const bool known_version =
      IsLayered(format) ? version == 3 || version == 4 : version == kPointwiseVersion;
  if (header.record_length < kBaseLength[format] || !known_version ||
      items != ItemsOf(format, header.record_length - kBaseLength[format], version)) {
    return Invalid(absl::StrCat("the LASzip record's items (", ItemsText(items),
                                ") do not code point format ", format, " in records of ",
                                header.record_length, " bytes"));
  }
  if (chunk_size == 0) return Invalid("the LASzip record's chunk size is 0");
  return Compression{chunk_size, version};
}

void SetUint32(uint32_t value, size_t at, std::string* out) { StoreLittleEndian(value, at, out); }
void SetUint64(uint64_t value, size_t at, std::string* out) { StoreLittleEndian(value, at, out); }

}  // namespace

bool IsLaz(absl::string_view data) {
  return data.size() > kPointFormat && data.substr(0, 4) == "LASF" &&
         (static_cast<uint8_t>(data[kPointFormat]) & kCompressedBits) != 0;
}

namespace {

// A LAZ file's header and its LASzip record (the last, if several), checked.
struct LazHeader {
  Header header;
  Vlr laszip;
  Compression compression;
};

absl::StatusOr<LazHeader> ReadLazHeader(absl::string_view laz) {
  LazHeader out;
  NM_ASSIGN_OR_RETURN(out.header, ReadHeader(laz, "LAZ"));
  if ((out.header.format_byte & kCompressedBits) == 0) {
    return Invalid("the point format carries no compression bits: a LAS file, not LAZ");
  }
  NM_ASSIGN_OR_RETURN(const std::vector<Vlr> vlrs, ReadVlrs(laz, out.header, "LAZ"));
  const auto laszip = std::find_if(vlrs.rbegin(), vlrs.rend(), [](const Vlr& vlr) {
    return vlr.user == kLaszipUser && vlr.id == kLaszipRecordId;
  });
  if (laszip == vlrs.rend()) {
    return Invalid(
        "no LASzip record (user \"laszip encoded\", record 22204) says how the "
        "points are compressed");
  }
  out.laszip = *laszip;
  NM_ASSIGN_OR_RETURN(out.compression, CheckLaszipRecord(out.laszip.payload, out.header));
  return out;
}

}  // namespace

namespace {

// The header and variable-length records of the LAS file that `laz` compresses: the point
// format without the compression bits, the LASzip record left out, the offset to the points
// moved.
std::string DecompressedLasHeader(absl::string_view laz, const LazHeader& laz_header) {
  const Header& header = laz_header.header;
  const Vlr& laszip = laz_header.laszip;
  const size_t laszip_size = laszip.end() - laszip.at;
  std::string las;
  absl::StrAppend(&las, laz.substr(0, laszip.at));
  absl::StrAppend(&las, laz.substr(laszip.end(), header.offset_to_points - laszip.end()));
  las[kPointFormat] = static_cast<char>(header.format());
  SetUint32(header.vlr_count - 1, kVlrCount, &las);
  SetUint32(static_cast<uint32_t>(header.offset_to_points - laszip_size), kOffsetToPoints, &las);
  return las;
}

}  // namespace

absl::StatusOr<LazChunks> LazChunks::Open(absl::string_view laz) {
  NM_ASSIGN_OR_RETURN(const LazHeader laz_header, ReadLazHeader(laz));
  const Header& header = laz_header.header;
  const Compression& compression = laz_header.compression;
  LazChunks out;
  out.laz_ = laz;
  out.points_end_ = header.evlr_start > header.offset_to_points && header.evlr_start <= laz.size()
                        ? static_cast<size_t>(header.evlr_start)
                        : laz.size();
  out.evlr_start_ = header.evlr_start;
  const uint64_t compressed = out.points_end_ - header.offset_to_points;
  if (header.count > (kMaxExpansion * compressed + (1u << 20)) / header.record_length) {
    return Invalid(absl::StrCat(header.count, " records of ", header.record_length,
                                " bytes cannot come from ", compressed,
                                " bytes of compressed data: the point count is corrupt"));
  }
  if (header.count > 0) {
    NM_ASSIGN_OR_RETURN(const std::vector<Chunk> chunks,
                        ReadChunkTable(laz, header, compression.chunk_size));
    uint64_t first = 0;
    for (const Chunk& chunk : chunks) {
      out.chunks_.push_back({chunk.at, chunk.size, chunk.count, first});
      first += chunk.count;
    }
  }
  out.format_ = header.format();
  out.record_length_ = header.record_length;
  out.item_version_ = compression.item_version;
  out.records_ = header.count;
  out.compressed_ = compressed;

  out.las_header_ = DecompressedLasHeader(laz, laz_header);
  // The extended records follow the records in the LAS file.
  if (!out.las_tail().empty()) {
    SetUint64(out.las_header_.size() + out.records_ * out.record_length_, kEvlrStart,
              &out.las_header_);
  }
  return out;
}

absl::Status LazChunks::Decode(size_t first, size_t last, char* out) const {
  // One coder for the run: making one costs more than decoding a chunk of a few records.
  const std::unique_ptr<ChunkCoder> coder = MakeChunkCoder(format_, record_length_, item_version_);
  for (size_t i = first; i < last; ++i) {
    const ChunkSpan& chunk = chunks_[i];
    NM_RETURN_IF_ERROR(coder->Decode(laz_.substr(chunk.at, chunk.size), chunk.records,
                                     reinterpret_cast<uint8_t*>(out),
                                     absl::StrCat("chunk ", i + 1, " of ", chunks_.size())));
    out += chunk.records * record_length_;
  }
  return absl::OkStatus();
}

absl::string_view LazChunks::las_tail() const {
  return evlr_start_ != 0 && points_end_ < laz_.size() ? laz_.substr(points_end_)
                                                       : absl::string_view();
}

absl::StatusOr<std::string> DecompressLaz(absl::string_view laz, const LazReadOptions& options) {
  NM_ASSIGN_OR_RETURN(const LazChunks chunks, LazChunks::Open(laz));
  const size_t record_length = chunks.record_length();
  std::string las;
  las.reserve(chunks.las_header().size() +
              std::min(chunks.records() * record_length,
                       kReservedExpansion * chunks.compressed_bytes() + (uint64_t{1} << 20)));
  las.append(chunks.las_header());
  // The chunks in waves of a few per thread, each thread decoding a run of them; the output
  // grows wave by wave.
  const size_t wave = kChunksPerThread * ThreadCount(options.threads);
  std::vector<absl::Status> statuses(chunks.size());
  for (size_t begin = 0; begin < chunks.size(); begin += wave) {
    const size_t end = std::min(chunks.size(), begin + wave);
    std::vector<size_t> chunk_at(end - begin);
    for (size_t i = begin; i < end; ++i) {
      chunk_at[i - begin] = las.size();
      las.resize(las.size() + chunks.records_in(i) * record_length);
    }
    // Each thread decodes a run of consecutive chunks, whose records follow one another.
    ForEachRange(end - begin, options.threads, 1, [&](size_t first, size_t last) {
      statuses[begin + first] = chunks.Decode(begin + first, begin + last, &las[chunk_at[first]]);
    });
    for (size_t i = begin; i < end; ++i) NM_RETURN_IF_ERROR(statuses[i]);
  }
  absl::StrAppend(&las, chunks.las_tail());
  return las;
}

absl::Status DecompressLazTo(absl::string_view laz, ByteSink* out, const LazReadOptions& options) {
  NM_ASSIGN_OR_RETURN(const LazChunks chunks, LazChunks::Open(laz));
  NM_RETURN_IF_ERROR(out->Append(chunks.las_header()));
  NM_RETURN_IF_ERROR(chunks.DecodeInOrder(
      [&](size_t, absl::string_view records) { return out->Append(records); }, options.threads));
  return out->Append(chunks.las_tail());
}

absl::Status LazChunks::DecodeInOrder(
    const std::function<absl::Status(size_t, absl::string_view)>& visit, int threads) const {
  const size_t wave = kChunksPerThread * ThreadCount(threads);
  std::vector<std::string> decoded(wave);
  std::vector<absl::Status> statuses(wave);
  for (size_t begin = 0; begin < size(); begin += wave) {
    const size_t end = std::min(size(), begin + wave);
    ForEachRange(end - begin, threads, 1, [&](size_t first, size_t last) {
      for (size_t i = first; i < last; ++i) {
        decoded[i].resize(records_in(begin + i) * record_length_);
        statuses[i] = Decode(begin + i, decoded[i].data());
      }
    });
    for (size_t i = begin; i < end; ++i) {
      NM_RETURN_IF_ERROR(statuses[i - begin]);
      NM_RETURN_IF_ERROR(visit(i, decoded[i - begin]));
    }
  }
  return absl::OkStatus();
}

LazStreamDecoder::LazStreamDecoder() = default;
LazStreamDecoder::LazStreamDecoder(LazStreamDecoder&&) noexcept = default;
LazStreamDecoder& LazStreamDecoder::operator=(LazStreamDecoder&&) noexcept = default;
LazStreamDecoder::~LazStreamDecoder() = default;

absl::StatusOr<LazStreamDecoder> LazStreamDecoder::Create(absl::string_view header) {
  NM_ASSIGN_OR_RETURN(const LazHeader laz_header, ReadLazHeader(header));
  if (laz_header.compression.chunk_size == kVariableChunkSize) {
    return Invalid(
        "chunks of varying size, whose sizes only the chunk table after them gives: not read "
        "as they arrive; write the file with chunks of one size");
  }
  if (laz_header.header.count == 0) {
    return Invalid(
        "the header states no record count: where the chunks end is not known before the "
        "chunk table that follows them");
  }
  LazStreamDecoder out;
  out.las_header_ = DecompressedLasHeader(header, laz_header);
  out.record_length_ = laz_header.header.record_length;
  out.chunk_size_ = laz_header.compression.chunk_size;
  out.records_left_ = laz_header.header.count;
  out.coder_ = MakeChunkCoder(laz_header.header.format(), out.record_length_,
                              laz_header.compression.item_version);
  return out;
}

absl::StatusOr<size_t> LazStreamDecoder::DecodeNext(absl::string_view bytes, bool ended,
                                                    std::string* records) {
  if (records_left_ == 0) return 0;
  // The point data start with the chunk table's offset (or -1, for the file's last bytes),
  // taken with the first chunk.
  const size_t offset_bytes = table_offset_skipped_ ? 0 : 8;
  if (bytes.size() < offset_bytes) {
    if (!ended) return 0;
    return Invalid("the stream ends before its chunk table's offset");
  }
  bytes.remove_prefix(offset_bytes);
  const uint64_t count = std::min<uint64_t>(chunk_size_, records_left_);
  const size_t at = records->size();
  records->resize(at + count * record_length_);
  const std::string name = absl::StrCat("chunk ", chunks_ + 1);
  const absl::Status decoded =
      coder_->Decode(bytes, count, reinterpret_cast<uint8_t*>(&(*records)[at]), name);
  // A chunk may take a little more than its records' bytes (incompressible ones); more than
  // that is no chunk.
  const uint64_t most = 2 * count * record_length_ + (uint64_t{1} << 16);
  if ((!decoded.ok() || coder_->decoded_overrun() > 0) && !ended && bytes.size() < most) {
    records->resize(at);
    return 0;  // Not all of the chunk has come.
  }
  if (!decoded.ok() || coder_->decoded_overrun() > 0) {
    records->resize(at);
    NM_RETURN_IF_ERROR(decoded);
    return Invalid(absl::StrCat(name, " ends ", coder_->decoded_overrun(),
                                " bytes before its records are decoded: the stream is cut short "
                                "or corrupt"));
  }
  ++chunks_;
  records_left_ -= count;
  table_offset_skipped_ = true;
  return offset_bytes + coder_->decoded_length();
}

absl::StatusOr<std::string> DescribeLazCompression(absl::string_view laz) {
  NM_ASSIGN_OR_RETURN(const LazHeader laz_header, ReadLazHeader(laz));
  const Header& header = laz_header.header;
  const Compression& compression = laz_header.compression;
  std::vector<Chunk> chunks;
  if (header.count > 0) {
    NM_ASSIGN_OR_RETURN(chunks, ReadChunkTable(laz, header, compression.chunk_size));
  }
  const absl::string_view payload = laz_header.laszip.payload;
  return absl::StrCat(
      "LASzip ", static_cast<uint8_t>(payload[4]), ".", static_cast<uint8_t>(payload[5]),
      " (revision ", Load<uint16_t>(payload, 6), "), ",
      Load<uint16_t>(payload, 0) == kCompressorLayeredChunked ? "layered" : "pointwise",
      " chunks, item version ", compression.item_version, ", ", chunks.size(),
      chunks.size() == 1 ? " chunk of " : " chunks of ",
      compression.chunk_size == kVariableChunkSize
          ? std::string("varying size")
          : absl::StrCat("up to ", compression.chunk_size, " records"));
}

absl::StatusOr<std::string> LazWriter::LazHead(absl::string_view las) const {
  NM_ASSIGN_OR_RETURN(const Header header, ReadHeader(las, "LAS"));
  NM_ASSIGN_OR_RETURN(const std::vector<Vlr> vlrs, ReadVlrs(las, header, "LAS"));
  const size_t vlrs_end = vlrs.empty() ? header.header_size : vlrs.back().end();

  // The LASzip record, after the others (padding before the points stays after it).
  const std::vector<Item> items = ItemsOf(format_, record_length_ - kBaseLength[format_], version_);
  std::string record(kVlrHeaderSize, '\0');
  record.replace(kVlrUser, kLaszipUser.size(), kLaszipUser.data(), kLaszipUser.size());
  StoreLittleEndian(kLaszipRecordId, kVlrRecordId, &record);
  StoreLittleEndian(static_cast<uint16_t>(kLaszipFixedSize + kLaszipItemSize * items.size()),
                    kVlrLength, &record);
  constexpr absl::string_view kDescription = "LAZ written by neuralmesh";
  record.replace(kVlrLength + 2, kDescription.size(), kDescription.data(), kDescription.size());
  const bool layered = IsLayered(format_);
  AppendLittleEndian(layered ? kCompressorLayeredChunked : kCompressorPointwiseChunked, &record);
  AppendLittleEndian(uint16_t{0}, &record);  // The arithmetic coder.
  // The LASzip version whose format this is: 2.2 (revision 0), or 3.4 (revision 3).
  record.append(layered ? std::string({3, 4, 3, 0}) : std::string({2, 2, 0, 0}));
  AppendLittleEndian(uint32_t{0}, &record);  // Options.
  AppendLittleEndian(options_.chunk_size, &record);
  AppendLittleEndian(int64_t{-1}, &record);  // No special extended records.
  AppendLittleEndian(int64_t{-1}, &record);
  AppendLittleEndian(static_cast<uint16_t>(items.size()), &record);
  for (const Item& item : items) {
    AppendLittleEndian(item.type, &record);
    AppendLittleEndian(item.size, &record);
    AppendLittleEndian(item.version, &record);
  }

  // The header, the variable-length records and the chunk table's offset.
  std::string head;
  absl::StrAppend(&head, las.substr(0, vlrs_end));
  head.append(record);
  absl::StrAppend(&head, las.substr(vlrs_end, header.offset_to_points - vlrs_end));
  head[kPointFormat] = static_cast<char>(header.format_byte | 0x80);
  SetUint32(header.vlr_count + 1, kVlrCount, &head);
  SetUint32(static_cast<uint32_t>(head.size()), kOffsetToPoints, &head);
  head.append(8, '\0');
  return head;
}

absl::Status LazWriter::Start(absl::string_view head) {
  NM_RETURN_IF_ERROR(CheckLasHead(head));
  NM_ASSIGN_OR_RETURN(const Header header, ReadHeader(head, "LAS"));
  if ((header.format_byte & kCompressedBits) != 0) {
    return absl::InvalidArgumentError("LAS: the points are compressed already (LAZ)");
  }
  if (header.format_byte > 8 || header.format_byte == 4 || header.format_byte == 5) {
    return absl::FailedPreconditionError(
        absl::StrCat("LAZ: writing point format ", int{header.format_byte},
                     " (waveform packets) is not supported (formats 0 to 3 and 6 to 8 are); "
                     "write .las"));
  }
  format_ = header.format_byte;
  record_length_ = header.record_length;
  if (record_length_ < kBaseLength[format_]) {
    return absl::InvalidArgumentError(absl::StrCat("LAS: records of ", record_length_,
                                                   " bytes are shorter than format ", format_,
                                                   "'s ", kBaseLength[format_]));
  }
  if (options_.chunk_size == 0) return absl::InvalidArgumentError("LAZ: a chunk size of 0");
  if (options_.layered_version != 3 && options_.layered_version != 4) {
    return absl::InvalidArgumentError(
        absl::StrCat("LAZ: item version ", options_.layered_version, " is not 3 or 4"));
  }
  version_ = IsLayered(format_) ? options_.layered_version : kPointwiseVersion;
  NM_ASSIGN_OR_RETURN(laz_head_, LazHead(head));
  started_ = std::string(head);
  wave_records_ = uint64_t{kChunksPerThread} * ThreadCount(options_.threads) * options_.chunk_size;
  return absl::OkStatus();
}

absl::Status LazWriter::CodeChunks(const char* records, uint64_t count) {
  // Each thread codes a run of the chunks into strings of their own, with coders of its own.
  const uint64_t chunk_count = (count + options_.chunk_size - 1) / options_.chunk_size;
  if (coded_.size() < chunk_count) coded_.resize(chunk_count);
  const uint8_t* bytes = reinterpret_cast<const uint8_t*>(records);
  ForEachRange(chunk_count, options_.threads, 1, [&](size_t first, size_t last) {
    const std::unique_ptr<ChunkCoder> coder = MakeChunkCoder(format_, record_length_, version_);
    for (size_t i = first; i < last; ++i) {
      const uint64_t from = i * options_.chunk_size;
      const uint64_t to = std::min<uint64_t>(count, from + options_.chunk_size);
      coded_[i].clear();
      coder->Encode(bytes + from * record_length_, to - from, &coded_[i]);
    }
  });
  for (size_t i = 0; i < chunk_count; ++i) {
    chunk_sizes_.push_back(static_cast<uint32_t>(coded_[i].size()));
    NM_RETURN_IF_ERROR(out_->Append(coded_[i]));
  }
  return absl::OkStatus();
}

absl::Status LazWriter::AppendRecords(absl::string_view records) {
  if (records.size() % record_length_ != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "LAS: ", records.size(), " bytes are not records of ", record_length_, " bytes"));
  }
  NM_RETURN_IF_ERROR(WriteHeadOnce(laz_head_));
  appended_ += records.size() / record_length_;
  const size_t wave_bytes = wave_records_ * record_length_;
  if (!pending_.empty()) {  // Completed first.
    const size_t taken = std::min(records.size(), wave_bytes - pending_.size());
    absl::StrAppend(&pending_, records.substr(0, taken));
    records.remove_prefix(taken);
    if (pending_.size() < wave_bytes) return absl::OkStatus();
    NM_RETURN_IF_ERROR(CodeChunks(pending_.data(), wave_records_));
    pending_.clear();
  }
  // Whole waves coded where they lie; the rest kept for the next records.
  for (; records.size() >= wave_bytes; records.remove_prefix(wave_bytes)) {
    NM_RETURN_IF_ERROR(CodeChunks(records.data(), wave_records_));
  }
  absl::StrAppend(&pending_, records);
  return absl::OkStatus();
}

absl::Status LazWriter::Finish(absl::string_view head, absl::string_view tail) {
  NM_RETURN_IF_ERROR(CheckFinishingLasHead(head, started_));
  NM_ASSIGN_OR_RETURN(const Header header, ReadHeader(head, "LAS"));
  if (header.count != appended_) {
    return absl::InvalidArgumentError(absl::StrCat("LAS: the head counts ", header.count,
                                                   " records and ", appended_, " were written"));
  }
  NM_RETURN_IF_ERROR(WriteHeadOnce(laz_head_));
  NM_RETURN_IF_ERROR(CodeChunks(pending_.data(), pending_.size() / record_length_));
  pending_.clear();
  pending_.shrink_to_fit();
  coded_.clear();

  NM_ASSIGN_OR_RETURN(std::string laz_head, LazHead(head));
  const uint64_t table_at = out_->size() - start_;
  SetUint64(table_at, laz_head.size() - 8, &laz_head);
  std::string table;
  AppendLittleEndian(uint32_t{0}, &table);  // Version.
  AppendLittleEndian(static_cast<uint32_t>(chunk_sizes_.size()), &table);
  if (!chunk_sizes_.empty()) {
    laz::ArithmeticEncoder encoder(&table);
    laz::IntegerCoder sizes(32, 2);
    uint32_t last = 0;
    for (const uint32_t size : chunk_sizes_) {
      sizes.Compress(encoder, static_cast<int32_t>(last), static_cast<int32_t>(size), 1);
      last = size;
    }
    encoder.Done();
  }
  const uint64_t points_end = header.offset_to_points + header.count * header.record_length;
  if (header.evlr_start != 0 && header.evlr_start >= points_end && !tail.empty()) {
    SetUint64(table_at + table.size() + (header.evlr_start - points_end), kEvlrStart, &laz_head);
  }
  NM_RETURN_IF_ERROR(out_->Append(table));
  NM_RETURN_IF_ERROR(out_->Append(tail));
  return out_->Patch(start_, laz_head);
}

absl::Status CompressLasTo(absl::string_view las, ByteSink* out, const LazWriteOptions& options) {
  NM_ASSIGN_OR_RETURN(const Header header, ReadHeader(las, "LAS"));
  const absl::string_view head = las.substr(0, header.offset_to_points);
  LazWriter writer(out, options);
  NM_RETURN_IF_ERROR(writer.Start(head));
  if (header.count > (las.size() - header.offset_to_points) / header.record_length) {
    return absl::InvalidArgumentError(absl::StrCat(
        "LAS: ", header.count, " points of ", header.record_length, " bytes from byte ",
        header.offset_to_points, " do not fit in the file's ", las.size(), " bytes"));
  }
  const size_t points_end = header.offset_to_points + header.count * header.record_length;
  NM_RETURN_IF_ERROR(writer.AppendRecords(
      las.substr(header.offset_to_points, points_end - header.offset_to_points)));
  return writer.Finish(head, las.substr(points_end));
}

absl::Status RecompressLazTo(absl::string_view laz, ByteSink* out, const LazWriteOptions& options) {
  NM_ASSIGN_OR_RETURN(const LazChunks chunks, LazChunks::Open(laz));
  LazWriter writer(out, options);
  NM_RETURN_IF_ERROR(writer.Start(chunks.las_header()));
  NM_RETURN_IF_ERROR(chunks.DecodeInOrder(
      [&](size_t, absl::string_view records) { return writer.AppendRecords(records); },
      options.threads));
  return writer.Finish(chunks.las_header(), chunks.las_tail());
}

absl::StatusOr<std::string> CompressLas(absl::string_view las, const LazWriteOptions& options) {
  StringSink laz;
  NM_RETURN_IF_ERROR(CompressLasTo(las, &laz, options));
  return std::move(laz.bytes());
}

}  // namespace neuralmesh::io_internal
