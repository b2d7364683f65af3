#include "core/io/internal/las.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las_file_writer.h"
#include "core/io/internal/las_layout.h"
#include "core/io/internal/laz.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"
#include "core/rgb.h"
#include "core/status_macros.h"
#include "core/version.h"

namespace neuralmesh::io_internal {
namespace {

using namespace las_layout;  // NOLINT: the header's field offsets.

// The shortest record of each point format, and where its red channel is (0: no colour).
struct PointFormat {
  size_t length;
  size_t rgb;
};
constexpr PointFormat kFormats[] = {{20, 0}, {28, 0},  {26, 20}, {34, 28}, {57, 0}, {63, 28},
                                    {30, 0}, {36, 30}, {38, 30}, {59, 0},  {67, 30}};

template <typename T>
T Load(absl::string_view data, size_t offset) {
  return LoadScalar<T>(data.data() + offset, /*big_endian=*/false);
}

absl::Status Invalid(absl::string_view message) {
  return absl::InvalidArgumentError(absl::StrCat("LAS: ", message));
}

// The ASPRS classes of noise: 7, low point, and 18, high noise (LAS 1.4, Table 17).
constexpr int kLowNoiseClass = 7;
constexpr int kHighNoiseClass = 18;

enum RecordUsability { kUsable, kWithheld, kNoise, kOtherClass };

// Whether the record at `at` is to be used: the withheld flag (the specification: to be
// treated as deleted) leaves it out, and so does its class: one outside `classes`, or without
// them a noise class. Formats 0-5 hold the class in the low five bits of byte 15 and the
// withheld flag in its top bit; formats 6-10 the flag in bit 2 of byte 15 and the class in
// byte 16.
RecordUsability Usability(absl::string_view data, size_t at, int format,
                          const std::optional<LasClasses>& classes) {
  const uint8_t flags = static_cast<uint8_t>(data[at + 15]);
  const bool extended = format >= 6;
  if (extended ? (flags & 0x04) != 0 : (flags & 0x80) != 0) return kWithheld;
  const int classification = extended ? static_cast<uint8_t>(data[at + 16]) : flags & 0x1F;
  if (classes.has_value()) return (*classes)[classification] ? kUsable : kOtherClass;
  return classification == kLowNoiseClass || classification == kHighNoiseClass ? kNoise : kUsable;
}

// A fixed-size text field of the header, padded with zeros.
void AppendText(absl::string_view text, size_t size, std::string* out) {
  text = text.substr(0, size);
  out->append(text.data(), text.size());
  out->append(size - text.size(), '\0');
}

// The generating software field: this program and its version.
std::string GeneratingSoftware() { return absl::StrCat("neuralmesh ", NeuralmeshVersion()); }

// Writes the generating software field of a LAS file's header.
void SetGeneratingSoftware(std::string* file) {
  std::string software;
  AppendText(GeneratingSoftware(), 32, &software);
  file->replace(kGeneratingSoftware, 32, software);
}

// The return number of the record at `at`: the low three bits of byte 14 in formats 0-5, the
// low four in formats 6-10.
int ReturnNumber(absl::string_view data, size_t at, int format) {
  return static_cast<uint8_t>(data[at + 14]) & (format >= 6 ? 0x0F : 0x07);
}

// What the public header block says of the point records, checked against the file.
struct LasHeader {
  int minor = 0;  // Version 1.minor.
  size_t header_size = 0;
  size_t offset_to_points = 0;
  uint8_t format = 0;
  size_t record_length = 0;
  uint64_t count = 0;
  Point3d scale, offset;

  size_t points_end() const { return offset_to_points + count * record_length; }
  size_t record(uint64_t i) const { return offset_to_points + i * record_length; }
  double Coordinate(absl::string_view data, size_t at, int c) const {
    return Load<int32_t>(data, at + 4 * c) * scale[c] + offset[c];
  }
};

// The header of the LAS file `data` begins (its header and variable-length records at least,
// header_size bytes), checked against the file's size: `file_size`, or data.size() when it is
// the whole file.
absl::StatusOr<LasHeader> ReadHeader(absl::string_view data,
                                     size_t file_size = absl::string_view::npos) {
  if (file_size == absl::string_view::npos) file_size = data.size();
  if (data.size() < kLegacyHeaderSize || data.substr(0, 4) != "LASF") {
    return Invalid(data.size() >= 4 && data.substr(0, 4) == "LASF"
                       ? absl::StrCat("the file ends within its header (", data.size(), " bytes)")
                       : std::string("no LASF signature: not a LAS file"));
  }
  LasHeader header;
  const int major = static_cast<uint8_t>(data[kVersionMajor]);
  header.minor = static_cast<uint8_t>(data[kVersionMinor]);
  if (major != 1 || header.minor > 4) {
    return Invalid(absl::StrCat("version ", major, ".", header.minor, " is not 1.0 to 1.4"));
  }
  header.header_size = Load<uint16_t>(data, kHeaderSize);
  header.offset_to_points = Load<uint32_t>(data, kOffsetToPoints);
  const uint8_t format_byte = static_cast<uint8_t>(data[kPointFormat]);
  header.record_length = Load<uint16_t>(data, kRecordLength);
  if (header.header_size < kLegacyHeaderSize || header.header_size > file_size) {
    return Invalid(absl::StrCat("header size ", header.header_size, " is not between ",
                                kLegacyHeaderSize, " and the file's ", file_size, " bytes"));
  }
  if (format_byte & kCompressedBits) {
    return Invalid("the points are compressed (LAZ); DecompressLaz reads them");
  }
  if (format_byte > 10) {
    return Invalid(absl::StrCat("point data format ", int{format_byte}, " is not 0 to 10"));
  }
  header.format = format_byte;
  if (header.record_length < kFormats[format_byte].length) {
    return Invalid(absl::StrCat("records of ", header.record_length,
                                " bytes are shorter than format ", int{format_byte}, "'s ",
                                kFormats[format_byte].length));
  }
  header.count = Load<uint32_t>(data, kLegacyPointCount);
  if (header.minor >= 4 && header.header_size >= kHeaderSize14) {
    const uint64_t count14 = Load<uint64_t>(data, kPointCount);
    if (count14 != 0) header.count = count14;
  }
  if (header.offset_to_points < header.header_size || header.offset_to_points > file_size ||
      header.count > (file_size - header.offset_to_points) / header.record_length) {
    return Invalid(absl::StrCat(header.count, " points of ", header.record_length,
                                " bytes from byte ", header.offset_to_points,
                                " do not fit in the file's ", file_size, " bytes"));
  }
  for (int c = 0; c < 3; ++c) {
    header.scale[c] = Load<double>(data, kScale + 8 * c);
    header.offset[c] = Load<double>(data, kOffset + 8 * c);
    if (!(header.scale[c] != 0) || !std::isfinite(header.scale[c]) ||
        !std::isfinite(header.offset[c])) {
      return Invalid(absl::StrCat(
          "the scale and offset of axis ", absl::string_view("xyz").substr(c, 1), " (",
          header.scale[c], ", ", header.offset[c], ") are not finite numbers and a nonzero scale"));
    }
  }
  return header;
}

// The variable-length records that say how the point records are to be read: the coordinate
// system (user "LASF_Projection") and the extra bytes' description ("LASF_Spec", record 4),
// each as its user, record id and payload.
std::string InterpretingRecords(absl::string_view data, const LasHeader& header) {
  std::string out;
  size_t at = header.header_size;
  const uint32_t count = Load<uint32_t>(data, kVlrCount);
  for (uint32_t i = 0; i < count && at + kVlrHeaderSize <= header.offset_to_points; ++i) {
    absl::string_view user = data.substr(at + kVlrUser, 16);
    user = user.substr(0, user.find('\0'));
    const uint16_t id = Load<uint16_t>(data, at + kVlrRecordId);
    const size_t length = Load<uint16_t>(data, at + kVlrLength);
    if (at + kVlrHeaderSize + length > header.offset_to_points) break;
    if (user == "LASF_Projection" || (user == "LASF_Spec" && id == 4)) {
      absl::StrAppend(&out, data.substr(at + kVlrUser, 18),
                      data.substr(at + kVlrHeaderSize, length));
    }
    at += kVlrHeaderSize + length;
  }
  return out;
}

bool IsWaveformFormat(int format) { return format == 4 || format == 5 || format >= 9; }
bool HasGpsTime(int format) { return format != 0 && format != 2; }

// A LAZ file's chunks and the header of the LAS file they hold, checked as ReadHeader checks
// that file decompressed (DecompressLaz): for reading its records a chunk at a time.
struct LazRecords {
  LazChunks chunks;
  LasHeader header;
};

// DecompressLaz's checks of `laz` and its errors, then ReadHeader's of the LAS header it holds.
// Nothing for a header that says it is longer than the bytes before its records, which only
// the decompressed file can be checked against.
absl::StatusOr<std::optional<LazRecords>> OpenLazRecords(absl::string_view laz) {
  NM_ASSIGN_OR_RETURN(LazChunks chunks, LazChunks::Open(laz));
  const std::string& las_header = chunks.las_header();
  if (las_header.size() < kLegacyHeaderSize ||
      Load<uint16_t>(las_header, kHeaderSize) > las_header.size()) {
    return std::nullopt;
  }
  // The decompressed file's size: its header, records and extended records.
  const size_t file_size = las_header.size() + chunks.records() * chunks.record_length() +
                           chunks.las_tail().size();
  NM_ASSIGN_OR_RETURN(const LasHeader header, ReadHeader(las_header, file_size));
  return LazRecords{std::move(chunks), header};
}

// A LAS or LAZ file opened for a pass over its records (cleaning, joining, describing): its
// header, the bytes before and after its records (as in the LAS file a LAZ file compresses),
// and its records, where the file lies or decoded a chunk at a time (LAZ).
struct OpenedLas {
  LasHeader header;
  absl::string_view head, tail;
  absl::string_view records;      // LAS.
  std::optional<LazRecords> laz;  // LAZ.
  // A LAZ file whose header only the decompressed file can be checked against (OpenLazRecords).
  std::string decompressed;
};

// Opens the file `data` into `out` (whose views may point into it: it is not to be moved),
// with ReadHeader's and DecompressLaz's errors.
absl::Status OpenLas(absl::string_view data, OpenedLas* out) {
  if (IsLaz(data)) {
    NM_ASSIGN_OR_RETURN(std::optional<LazRecords> laz, OpenLazRecords(data));
    if (laz.has_value()) {
      out->laz = *std::move(laz);
      out->header = out->laz->header;
      out->head = out->laz->chunks.las_header();
      out->tail = out->laz->chunks.las_tail();
      return absl::OkStatus();
    }
    NM_ASSIGN_OR_RETURN(out->decompressed, DecompressLaz(data));
    data = out->decompressed;
  }
  NM_ASSIGN_OR_RETURN(out->header, ReadHeader(data));
  const LasHeader& header = out->header;
  out->head = data.substr(0, header.offset_to_points);
  out->records = data.substr(header.offset_to_points, header.count * header.record_length);
  out->tail = data.substr(header.points_end());
  return absl::OkStatus();
}

// Gives the records of `source` to `visit` in blocks, in order: LAZ's a chunk at a time
// (decoded a wave at a time: LazChunks::DecodeInOrder). Its first error, or a chunk's.
absl::Status ForEachRecordBlock(const OpenedLas& source,
                                const std::function<absl::Status(absl::string_view)>& visit) {
  if (!source.laz.has_value()) return visit(source.records);
  return source.laz->chunks.DecodeInOrder(
      [&](size_t, absl::string_view records) { return visit(records); });
}

// How the records of several files are put in one: in the header of the first file of the
// highest version among them (its variable-length records, offset and what follows its points),
// as records of the point format that holds every field any of them holds.
struct JoinLayout {
  size_t base = 0;  // The file whose header the joined file takes.
  uint8_t format = 0;
  size_t record_length = 0;
  size_t extra_bytes = 0;  // After the format's fields, in every file alike.
  // Whether the GPS times are adjusted standard GPS time (the header's global encoding bit 0),
  // when a file holds them.
  std::optional<bool> standard_gps_time;
};

// The layout of the files' records joined: formats 0 to 3 go to the one of 0 to 3 with a GPS
// time if one has it and a colour if one has it; with any of formats 6 to 8 among them, to the
// one of 6 to 8 with a colour (and 8 a near infrared) if one has it. FAILED_PRECONDITION saying
// why when they cannot share one file: other extra bytes or coordinate systems than the
// first's, other data after the points (extended records), GPS times of another kind (GPS week
// time or adjusted standard GPS time), or waveform packets, to which records point by their
// place in their own file.
absl::StatusOr<JoinLayout> PlanJoin(const std::vector<LasSource>& sources,
                                    const std::vector<OpenedLas>& opened) {
  const LasHeader& first = opened.front().header;
  const std::string a = absl::StrCat("'", sources.front().name, "'");
  JoinLayout join;
  join.extra_bytes = first.record_length - kFormats[first.format].length;
  const absl::string_view first_after = opened.front().tail;
  const std::string first_interpreting = InterpretingRecords(opened.front().head, first);
  bool extended = false, gps_time = false, rgb = false, near_infrared = false;
  // The kind of GPS time of the first file that holds one, and that file.
  std::optional<std::pair<bool, size_t>> time_kind;
  for (size_t s = 0; s < sources.size(); ++s) {
    const LasHeader& header = opened[s].header;
    const std::string b = absl::StrCat("'", sources[s].name, "'");
    const absl::string_view head = opened[s].head;
    if (sources.size() > 1 && IsWaveformFormat(header.format)) {
      return absl::FailedPreconditionError(
          absl::StrCat("the records of ", b, " (point format ", int{header.format},
                       ") point into their own file's waveform data"));
    }
    const size_t extra = header.record_length - kFormats[header.format].length;
    if (extra != join.extra_bytes) {
      return absl::FailedPreconditionError(
          absl::StrCat(b, " has ", extra, " extra bytes a record and ", a, " ", join.extra_bytes));
    }
    if (InterpretingRecords(head, header) != first_interpreting) {
      return absl::FailedPreconditionError(
          absl::StrCat("the coordinate systems or extra bytes of ", b, " and ", a, " differ"));
    }
    if (opened[s].tail != first_after) {
      return absl::FailedPreconditionError(absl::StrCat("what follows the points of ", b, " and ",
                                                        a, " (extended records) differs"));
    }
    if (HasGpsTime(header.format)) {
      const bool standard = (Load<uint16_t>(head, kGlobalEncoding) & 1) != 0;
      if (!time_kind.has_value()) {
        time_kind = {standard, s};
      } else if (time_kind->first != standard) {
        const auto kind = [](bool standard) {
          return standard ? "adjusted standard GPS time" : "GPS week time";
        };
        return absl::FailedPreconditionError(absl::StrCat(b, " holds ", kind(standard), " and '",
                                                          sources[time_kind->second].name, "' ",
                                                          kind(!standard)));
      }
    }
    if (header.minor > opened[join.base].header.minor) join.base = s;
    extended = extended || header.format >= 6;
    gps_time = gps_time || HasGpsTime(header.format);
    rgb = rgb || kFormats[header.format].rgb != 0;
    near_infrared = near_infrared || header.format == 8;
  }
  if (sources.size() == 1) {
    join.format = first.format;
  } else if (extended) {
    join.format = near_infrared ? 8 : rgb ? 7 : 6;
  } else {
    join.format = static_cast<uint8_t>((gps_time ? 1 : 0) + (rgb ? 2 : 0));
  }
  join.record_length = kFormats[join.format].length + join.extra_bytes;
  if (time_kind.has_value()) join.standard_gps_time = time_kind->first;
  return join;
}

// The fields of a point record of formats 0-3 and 6-8.
struct LasRecordFields {
  std::string xyz_intensity;  // 14 bytes, as stored.
  int return_number = 0, returns = 0;
  bool scan_direction = false, edge = false;
  // Synthetic, key point, withheld, overlap (LAS 1.4's order; the last only in formats 6-10).
  int classification_flags = 0;
  int scanner_channel = 0;
  int classification = 0;
  int user_data = 0;
  int16_t scan_angle = 0;  // In 0.006 degrees.
  std::string point_source = std::string(2, '\0');
  std::string gps_time = std::string(8, '\0');
  std::string rgb = std::string(6, '\0');
  std::string near_infrared = std::string(2, '\0');
};

LasRecordFields ReadRecordFields(absl::string_view record, int format) {
  LasRecordFields f;
  f.xyz_intensity = std::string(record.substr(0, 14));
  const uint8_t returns = static_cast<uint8_t>(record[14]),
                flags = static_cast<uint8_t>(record[15]);
  if (format >= 6) {
    f.return_number = returns & 0x0F;
    f.returns = returns >> 4;
    f.classification_flags = flags & 0x0F;
    f.scanner_channel = (flags >> 4) & 3;
    f.scan_direction = (flags >> 6) & 1;
    f.edge = flags >> 7;
    f.classification = static_cast<uint8_t>(record[16]);
    f.user_data = static_cast<uint8_t>(record[17]);
    f.scan_angle = Load<int16_t>(record, 18);
    f.point_source = std::string(record.substr(20, 2));
    f.gps_time = std::string(record.substr(22, 8));
    if (format == 8) f.near_infrared = std::string(record.substr(36, 2));
  } else {
    f.return_number = returns & 0x07;
    f.returns = (returns >> 3) & 0x07;
    f.scan_direction = (returns >> 6) & 1;
    f.edge = returns >> 7;
    f.classification = flags & 0x1F;
    f.classification_flags = flags >> 5;
    // The scan angle rank in whole degrees, from -90 to 90.
    f.scan_angle = static_cast<int16_t>(std::lround(static_cast<int8_t>(record[16]) / 0.006));
    f.user_data = static_cast<uint8_t>(record[17]);
    f.point_source = std::string(record.substr(18, 2));
    if (HasGpsTime(format)) f.gps_time = std::string(record.substr(20, 8));
  }
  if (kFormats[format].rgb != 0) f.rgb = std::string(record.substr(kFormats[format].rgb, 6));
  return f;
}

// Appends the fields as a record of `format`, one that holds each field the record they were
// read from holds (PlanJoin's), but for its extra bytes.
void AppendRecordFields(const LasRecordFields& f, int format, std::string* out) {
  *out += f.xyz_intensity;
  if (format >= 6) {
    *out += static_cast<char>(f.return_number | f.returns << 4);
    *out += static_cast<char>(f.classification_flags | f.scanner_channel << 4 |
                              f.scan_direction << 6 | f.edge << 7);
    *out += static_cast<char>(f.classification);
    *out += static_cast<char>(f.user_data);
    AppendLittleEndian(f.scan_angle, out);
    *out += f.point_source;
    *out += f.gps_time;
    if (format >= 7) *out += f.rgb;
    if (format == 8) *out += f.near_infrared;
  } else {  // From formats 0 to 3, whose fields fit.
    *out +=
        static_cast<char>(f.return_number | f.returns << 3 | f.scan_direction << 6 | f.edge << 7);
    *out += static_cast<char>(f.classification | f.classification_flags << 5);
    *out += static_cast<char>(static_cast<int8_t>(std::lround(f.scan_angle * 0.006)));
    *out += static_cast<char>(f.user_data);
    *out += f.point_source;
    if (HasGpsTime(format)) *out += f.gps_time;
    if (kFormats[format].rgb != 0) *out += f.rgb;
  }
}

}  // namespace

namespace {

// The error of a file whose `count` records are all left out.
absl::Status NothingKept(uint64_t count, const PointsLeftOut& left_out,
                         const std::optional<LasClasses>& classes) {
  return Invalid(absl::StrCat(
      "all ", count, " points are withheld (", left_out.withheld, ") or ",
      classes.has_value() ? absl::StrCat("of classes not asked for (", left_out.other_class, ")")
                          : absl::StrCat("classified as noise (", left_out.noise, ")")));
}

// The points of consecutive blocks of a LAS file's records (a file's whole block, or a LAZ
// file's chunks in order), read as ParseLas reads them in one pass: each kept record's integer
// coordinates are kept in its float's place until the origin, which the kept records' range
// decides, is known.
class LasPointCollector {
 public:
  // Room for `capacity` points.
  LasPointCollector(const LasHeader& header, const std::optional<LasClasses>& classes,
                    uint64_t capacity)
      : header_(header), classes_(classes), format_(kFormats[header.format]) {
    out_.positions.reserve(capacity);
    if (format_.rgb != 0) levels_.reserve(capacity);
  }

  // Takes the next records.
  void Take(absl::string_view records) {
    const size_t length = header_.record_length;
    for (size_t at = 0; at + length <= records.size(); at += length) {
      const RecordUsability usability = Usability(records, at, header_.format, classes_);
      out_.left_out.withheld += usability == kWithheld;
      out_.left_out.noise += usability == kNoise;
      out_.left_out.other_class += usability == kOtherClass;
      if (usability != kUsable) continue;
      std::array<int32_t, 3> integers;
      for (int c = 0; c < 3; ++c) {
        integers[c] = Load<int32_t>(records, at + 4 * c);
        const double coordinate = header_.Coordinate(records, at, c);
        low_[c] = std::min(low_[c], coordinate);
        high_[c] = std::max(high_[c], coordinate);
      }
      Vec3f& slot = out_.positions.emplace_back();
      static_assert(sizeof(slot) == sizeof(integers));
      std::memcpy(slot.data(), integers.data(), sizeof(integers));
      if (format_.rgb != 0) {
        std::array<uint16_t, 3>& rgb = levels_.emplace_back();
        for (int c = 0; c < 3; ++c) {
          rgb[c] = Load<uint16_t>(records, at + format_.rgb + 2 * c);
          largest_level_ = std::max(largest_level_, rgb[c]);
        }
      }
    }
  }

  // The points kept so far.
  uint64_t kept() const { return out_.positions.size(); }

  // The points taken, relative to their origin, with their colours. ParseLas's errors for
  // records all left out, and for a point a float cannot hold: `record_of_kept(k)` numbers the
  // record of kept point k, to name it.
  absl::StatusOr<ParsedGeometry> Finish(
      const std::function<uint64_t(uint64_t)>& record_of_kept) && {
    if (out_.positions.empty() && header_.count > 0) {
      return NothingKept(header_.count, out_.left_out, classes_);
    }
    if (!out_.positions.empty()) {
      const Point3d step = {std::fabs(header_.scale[0]), std::fabs(header_.scale[1]),
                            std::fabs(header_.scale[2])};
      out_.origin = OriginKeepingResolution(low_, high_, step);
    }
    for (size_t k = 0; k < out_.positions.size(); ++k) {
      std::array<int32_t, 3> integers;
      Vec3f& p = out_.positions[k];
      std::memcpy(integers.data(), p.data(), sizeof(integers));
      for (int c = 0; c < 3; ++c) {
        p[c] = NarrowToFloat(integers[c] * header_.scale[c] + header_.offset[c] - out_.origin[c]);
      }
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
        return Invalid(absl::StrCat("point ", record_of_kept(k), " lies beyond a float's range"));
      }
    }
    if (format_.rgb != 0) {
      const double max = LevelScale(largest_level_);
      out_.colors.reserve(levels_.size());
      for (const std::array<uint16_t, 3>& rgb : levels_) {
        out_.colors.push_back(RgbFromLevels(rgb, max));
      }
    }
    return std::move(out_);
  }

 private:
  const LasHeader& header_;
  const std::optional<LasClasses>& classes_;
  const PointFormat format_;
  ParsedGeometry out_;
  std::vector<std::array<uint16_t, 3>> levels_;  // Of the kept records, with format_.rgb.
  Point3d low_ = {INFINITY, INFINITY, INFINITY}, high_ = {-INFINITY, -INFINITY, -INFINITY};
  uint16_t largest_level_ = 0;
};

// The number of the record among `records`, the first numbered `first_record`, that is kept
// point `k`, the first of them kept being kept point `first_kept`.
uint64_t RecordOfKept(absl::string_view records, const LasHeader& header,
                      const std::optional<LasClasses>& classes, uint64_t first_record,
                      uint64_t first_kept, uint64_t k) {
  uint64_t record = first_record;
  for (size_t at = 0; at + header.record_length <= records.size();
       at += header.record_length, ++record) {
    if (Usability(records, at, header.format, classes) == kUsable && first_kept++ == k) break;
  }
  return record;
}

// What the header and variable-length records that `data` begins with say of a LAS file
// (DescribeLas), its records not counted yet.
LasDescription DescribeHeader(absl::string_view data, const LasHeader& header) {
  LasDescription out;
  out.version_minor = header.minor;
  out.point_format = header.format;
  out.record_length = header.record_length;
  out.extra_bytes = header.record_length - kFormats[header.format].length;
  out.records = header.count;
  out.scale = header.scale;
  out.offset = header.offset;
  absl::string_view software = data.substr(kGeneratingSoftware, 32);
  out.generating_software = std::string(software.substr(0, software.find('\0')));
  out.standard_gps_time = (Load<uint16_t>(data, kGlobalEncoding) & 1) != 0;
  out.variable_length_records = Load<uint32_t>(data, kVlrCount);
  size_t at = header.header_size;
  for (uint32_t i = 0;
       i < out.variable_length_records && at + kVlrHeaderSize <= header.offset_to_points; ++i) {
    absl::string_view user = data.substr(at + kVlrUser, 16);
    user = user.substr(0, user.find('\0'));
    const uint16_t id = Load<uint16_t>(data, at + kVlrRecordId);
    if (user == "LASF_Projection" && id == 2112) {
      out.coordinate_system = "WKT";
    } else if (user == "LASF_Projection" && id == 34735 && out.coordinate_system.empty()) {
      out.coordinate_system = "GeoTIFF";
    }
    at += kVlrHeaderSize + Load<uint16_t>(data, at + kVlrLength);
  }
  out.records_by_class.assign(256, 0);
  return out;
}

// Counts the withheld records and those of each class among `records`, consecutive records of
// the file `header` describes.
void CountClasses(absl::string_view records, const LasHeader& header, LasDescription* out) {
  const bool extended = header.format >= 6;
  for (size_t at = 0; at + header.record_length <= records.size(); at += header.record_length) {
    const uint8_t flags = static_cast<uint8_t>(records[at + 15]);
    out->withheld += extended ? (flags & 0x04) != 0 : (flags & 0x80) != 0;
    ++out->records_by_class[extended ? static_cast<uint8_t>(records[at + 16]) : flags & 0x1F];
  }
}

// DescribeLas's facts of the file as it is stored: its size and, for LAZ, its compression.
absl::Status DescribeStorage(absl::string_view data, LasDescription* out) {
  out->file_bytes = data.size();
  out->compression.clear();
  if (IsLaz(data)) {
    NM_ASSIGN_OR_RETURN(out->compression, DescribeLazCompression(data));
  }
  return absl::OkStatus();
}

// Reads a LAZ file as ParseLas reads the LAS file it compresses, without that file: its chunks
// are decoded a wave at a time (LazChunks::DecodeInOrder), and each chunk's records are taken
// as they come. `description` as ParseLas's.
absl::StatusOr<ParsedGeometry> ParseLaz(absl::string_view laz,
                                        const std::optional<LasClasses>& classes,
                                        LasDescription* description) {
  NM_ASSIGN_OR_RETURN(const std::optional<LazRecords> opened, OpenLazRecords(laz));
  if (!opened.has_value()) {
    NM_ASSIGN_OR_RETURN(const std::string las, DecompressLaz(laz));
    NM_ASSIGN_OR_RETURN(ParsedGeometry parsed, ParseLas(las, classes, description));
    if (description != nullptr) NM_RETURN_IF_ERROR(DescribeStorage(laz, description));
    return parsed;
  }
  const LazChunks& chunks = opened->chunks;
  const LasHeader& header = opened->header;
  if (description != nullptr) *description = DescribeHeader(chunks.las_header(), header);
  // Room for every record, unless the count is far beyond what the compressed bytes could
  // plausibly hold (then the vectors grow as the records come).
  const uint64_t plausible =
      (64 * chunks.compressed_bytes() + (uint64_t{1} << 20)) / header.record_length;
  LasPointCollector points(header, classes, std::min(header.count, plausible));
  std::vector<uint64_t> kept_before(chunks.size() + 1, 0);  // Kept points of earlier chunks.
  NM_RETURN_IF_ERROR(chunks.DecodeInOrder([&](size_t chunk, absl::string_view records) {
    points.Take(records);
    kept_before[chunk + 1] = points.kept();
    if (description != nullptr) CountClasses(records, header, description);
    return absl::OkStatus();
  }));
  if (description != nullptr) NM_RETURN_IF_ERROR(DescribeStorage(laz, description));
  return std::move(points).Finish([&](uint64_t k) {
    // Found again in its chunk, decoded once more.
    const size_t chunk = static_cast<size_t>(
        std::upper_bound(kept_before.begin(), kept_before.end(), k) - kept_before.begin() - 1);
    std::string records(chunks.records_in(chunk) * header.record_length, '\0');
    if (!chunks.Decode(chunk, records.data()).ok()) return chunks.first_record(chunk);
    return RecordOfKept(records, header, classes, chunks.first_record(chunk), kept_before[chunk],
                        k);
  });
}

}  // namespace

absl::StatusOr<ParsedGeometry> ParseLas(absl::string_view data,
                                        const std::optional<LasClasses>& classes,
                                        LasDescription* description) {
  if (IsLaz(data)) return ParseLaz(data, classes, description);
  NM_ASSIGN_OR_RETURN(const LasHeader header, ReadHeader(data));
  const absl::string_view records =
      data.substr(header.offset_to_points, header.count * header.record_length);
  if (description != nullptr) {
    *description = DescribeHeader(data, header);
    CountClasses(records, header, description);
    NM_RETURN_IF_ERROR(DescribeStorage(data, description));
  }
  LasPointCollector points(header, classes, header.count);
  points.Take(records);
  return std::move(points).Finish(
      [&](uint64_t k) { return RecordOfKept(records, header, classes, 0, 0, k); });
}

absl::StatusOr<LasDescription> DescribeLas(absl::string_view data) {
  OpenedLas opened;
  NM_RETURN_IF_ERROR(OpenLas(data, &opened));
  LasDescription out = DescribeHeader(opened.head, opened.header);
  NM_RETURN_IF_ERROR(ForEachRecordBlock(opened, [&](absl::string_view records) {
    CountClasses(records, opened.header, &out);
    return absl::OkStatus();
  }));
  NM_RETURN_IF_ERROR(DescribeStorage(data, &out));
  return out;
}

absl::StatusOr<std::unique_ptr<LasRecords>> LasRecords::Create(
    absl::string_view data, const std::optional<LasClasses>& classes) {
  NM_ASSIGN_OR_RETURN(const LasHeader header, ReadHeader(data));
  std::unique_ptr<LasRecords> records(new LasRecords());
  records->data_ = data;
  records->classes_ = classes;
  records->count_ = header.count;
  records->first_ = header.offset_to_points;
  records->length_ = header.record_length;
  records->format_ = header.format;
  records->scale_ = header.scale;
  records->offset_ = header.offset;
  for (int c = 0; c < 3; ++c) {
    records->header_high_[c] = Load<double>(data, kBounds + 16 * c);
    records->header_low_[c] = Load<double>(data, kBounds + 16 * c + 8);
  }
  return records;
}

absl::StatusOr<std::unique_ptr<LasRecords>> LasRecords::Create(
    absl::string_view header, absl::string_view records, const std::optional<LasClasses>& classes) {
  // The header alone, counting no records, so that its checks see records that fit.
  std::string alone(header);
  if (alone.size() >= kLegacyHeaderSize) {
    StoreLittleEndian(uint32_t{0}, kLegacyPointCount, &alone);
    if (static_cast<uint8_t>(alone[kVersionMinor]) >= 4 &&
        Load<uint16_t>(alone, kHeaderSize) >= kHeaderSize14 && alone.size() >= kHeaderSize14) {
      StoreLittleEndian(uint64_t{0}, kPointCount, &alone);
    }
  }
  NM_ASSIGN_OR_RETURN(std::unique_ptr<LasRecords> out, Create(alone, classes));
  out->data_ = records;
  out->first_ = 0;
  out->count_ = records.size() / out->length_;
  return out;
}

std::optional<Point3d> LasRecords::KeptPoint(uint64_t i) const {
  const size_t at = first_ + i * length_;
  if (Usability(data_, at, format_, classes_) != kUsable) return std::nullopt;
  Point3d p;
  for (int c = 0; c < 3; ++c) p[c] = Load<int32_t>(data_, at + 4 * c) * scale_[c] + offset_[c];
  return p;
}

bool LasRecords::has_colors() const { return kFormats[format_].rgb != 0; }

std::optional<std::array<uint16_t, 3>> LasRecords::ColorLevels(uint64_t i) const {
  const size_t rgb = kFormats[format_].rgb;
  if (rgb == 0) return std::nullopt;
  const size_t at = first_ + i * length_ + rgb;
  return std::array<uint16_t, 3>{Load<uint16_t>(data_, at), Load<uint16_t>(data_, at + 2),
                                 Load<uint16_t>(data_, at + 4)};
}

std::optional<Point3d> LasRecords::Resolution() const {
  return Point3d{std::fabs(scale_[0]), std::fabs(scale_[1]), std::fabs(scale_[2])};
}

absl::StatusOr<uint64_t> LasRecordCount(absl::string_view data) {
  NM_ASSIGN_OR_RETURN(const LasHeader header, ReadHeader(data));
  return header.count;
}

absl::StatusOr<std::string> FormatLas(const GeometryView& points) {
  const size_t count = points.positions.size();
  if (count > std::numeric_limits<uint32_t>::max()) {
    return Invalid(absl::StrCat(count, " points are more than LAS 1.2 counts (",
                                std::numeric_limits<uint32_t>::max(), ")"));
  }
  const bool colored = !points.colors.empty();
  const uint8_t format = colored ? 2 : 0;
  const uint16_t record_length = static_cast<uint16_t>(kFormats[format].length);
  Point3d scale;
  for (int c = 0; c < 3; ++c) {
    double farthest = 0;
    for (const Vec3f& p : points.positions) farthest = std::max<double>(farthest, std::fabs(p[c]));
    scale[c] = IntegerScaleKeepingFloats(farthest);
  }

  std::string records;
  records.reserve(count * record_length);
  Point3d low = {INFINITY, INFINITY, INFINITY}, high = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < count; ++i) {
    for (int c = 0; c < 3; ++c) {
      const int32_t stored = static_cast<int32_t>(std::llround(points.positions[i][c] / scale[c]));
      AppendLittleEndian(stored, &records);
      const double coordinate = stored * scale[c] + points.origin[c];
      low[c] = std::min(low[c], coordinate);
      high[c] = std::max(high[c], coordinate);
    }
    AppendLittleEndian(uint16_t{0}, &records);         // Intensity.
    records.push_back(static_cast<char>(1 | 1 << 3));  // Return 1 of 1.
    records.push_back('\0');                           // Class 0: created, never classified.
    records.push_back('\0');                           // Scan angle rank.
    records.push_back('\0');                           // User data.
    AppendLittleEndian(uint16_t{0}, &records);         // Point source.
    if (colored) {
      for (uint8_t level : points.colors[i]) {
        AppendLittleEndian(static_cast<uint16_t>(level * 257), &records);
      }
    }
  }

  std::string out = "LASF";
  AppendLittleEndian(uint16_t{0}, &out);  // File source.
  AppendLittleEndian(uint16_t{0}, &out);  // Global encoding: GPS week time.
  out.append(16, '\0');                   // Project GUID.
  out.push_back(1);
  out.push_back(2);
  AppendText("OTHER", 32, &out);  // System identifier: not a scanner's own file.
  AppendText(GeneratingSoftware(), 32, &out);
  AppendLittleEndian(uint16_t{0}, &out);  // Creation day of year: not recorded.
  AppendLittleEndian(uint16_t{0}, &out);  // Creation year.
  AppendLittleEndian(static_cast<uint16_t>(kLegacyHeaderSize), &out);
  AppendLittleEndian(static_cast<uint32_t>(kLegacyHeaderSize), &out);  // Offset to the points.
  AppendLittleEndian(uint32_t{0}, &out);                               // Variable-length records.
  out.push_back(static_cast<char>(format));
  AppendLittleEndian(record_length, &out);
  AppendLittleEndian(static_cast<uint32_t>(count), &out);
  AppendLittleEndian(static_cast<uint32_t>(count), &out);  // Points by return: all first.
  for (int r = 1; r < 5; ++r) AppendLittleEndian(uint32_t{0}, &out);
  for (int c = 0; c < 3; ++c) AppendLittleEndian(scale[c], &out);
  for (int c = 0; c < 3; ++c) AppendLittleEndian(points.origin[c], &out);
  for (int c = 0; c < 3; ++c) {
    AppendLittleEndian(count > 0 ? high[c] : 0.0, &out);
    AppendLittleEndian(count > 0 ? low[c] : 0.0, &out);
  }
  out += records;
  return out;
}

absl::Status WriteCleanedLasTo(const std::vector<LasSource>& sources,
                               const std::vector<bool>& outliers, LasOutlierRecords records,
                               const std::optional<LasClasses>& classes, LasJoin* joined,
                               LasFileWriter* writer) {
  if (sources.empty()) return Invalid("no file to clean");
  // Constructed in place: a source's views may point into its own decompressed bytes.
  std::vector<OpenedLas> opened(sources.size());
  for (size_t s = 0; s < sources.size(); ++s) {
    const absl::Status status = OpenLas(sources[s].data, &opened[s]);
    if (!status.ok()) return WithPath(status, sources[s].name);
  }
  NM_ASSIGN_OR_RETURN(const JoinLayout join, PlanJoin(sources, opened));
  const LasHeader& first = opened[join.base].header;
  const absl::string_view first_head = opened[join.base].head;
  // Each axis's finest scale among the files, so that no record loses resolution, from the
  // first file's offset.
  Point3d scale = first.scale;
  for (const OpenedLas& source : opened) {
    for (int c = 0; c < 3; ++c) {
      if (std::fabs(source.header.scale[c]) < std::fabs(scale[c]))
        scale[c] = source.header.scale[c];
    }
  }
  const bool as_noise = records == LasOutlierRecords::kClassifiedAsNoise;

  std::string head(first_head);
  head[kPointFormat] = static_cast<char>(join.format);
  if (join.standard_gps_time.has_value()) {  // Of the files' times, whichever file has them.
    const uint16_t encoding = Load<uint16_t>(head, kGlobalEncoding);
    StoreLittleEndian(static_cast<uint16_t>((encoding & ~1u) | *join.standard_gps_time),
                      kGlobalEncoding, &head);
  }
  StoreLittleEndian(static_cast<uint16_t>(join.record_length), kRecordLength, &head);
  NM_RETURN_IF_ERROR(writer->Start(head));

  // The records kept, given to the writer a block of about kBlockBytes at a time.
  constexpr size_t kBlockBytes = size_t{1} << 22;
  std::string block;
  Point3d low = {INFINITY, INFINITY, INFINITY}, high = {-INFINITY, -INFINITY, -INFINITY};
  uint64_t by_return[16] = {};
  uint64_t written = 0;
  size_t usable = 0;  // The points ParseLas reads, over every file.
  for (size_t s = 0; s < sources.size(); ++s) {
    const LasHeader& header = opened[s].header;
    const bool same_grid = header.scale == scale && header.offset == first.offset;
    NM_RETURN_IF_ERROR(ForEachRecordBlock(opened[s], [&](absl::string_view data) {
      for (size_t at = 0; at + header.record_length <= data.size(); at += header.record_length) {
        bool outlier = false;
        if (Usability(data, at, header.format, classes) == kUsable) {
          outlier = usable < outliers.size() && outliers[usable];
          ++usable;
          if (outlier && !as_noise) continue;
        } else if (!as_noise) {
          continue;
        }
        const size_t put = block.size();
        if (header.format == join.format) {
          block.append(data.data() + at, header.record_length);
        } else {
          const absl::string_view record = data.substr(at, header.record_length);
          AppendRecordFields(ReadRecordFields(record, header.format), join.format, &block);
          absl::StrAppend(&block, record.substr(record.size() - join.extra_bytes));
        }
        if (outlier) {
          if (join.format >= 6) {
            block[put + 16] = static_cast<char>(kLowNoiseClass);
          } else {  // The class in the low five bits; the top three are flags.
            block[put + 15] =
                static_cast<char>((static_cast<uint8_t>(block[put + 15]) & 0xE0) | kLowNoiseClass);
          }
        }
        for (int c = 0; c < 3; ++c) {
          double coordinate = header.Coordinate(data, at, c);
          if (!same_grid) {  // Onto the joined file's scale and offset.
            const double stored = std::round((coordinate - first.offset[c]) / scale[c]);
            if (!(stored >= std::numeric_limits<int32_t>::min() &&
                  stored <= std::numeric_limits<int32_t>::max())) {
              return absl::FailedPreconditionError(
                  absl::StrCat("the coordinates of '", sources[s].name,
                               "' do not fit LAS's 32-bit integers at the offset of '",
                               sources[join.base].name, "' and the scale ", scale[c], " of axis ",
                               absl::string_view("xyz").substr(c, 1)));
            }
            StoreLittleEndian(static_cast<int32_t>(stored), put + 4 * c, &block);
            coordinate = stored * scale[c] + first.offset[c];
          }
          low[c] = std::min(low[c], coordinate);
          high[c] = std::max(high[c], coordinate);
        }
        ++by_return[ReturnNumber(block, put, join.format)];
        ++written;
        if (block.size() >= kBlockBytes) {
          NM_RETURN_IF_ERROR(writer->AppendRecords(block));
          block.clear();
        }
      }
      return absl::OkStatus();
    }));
  }
  NM_RETURN_IF_ERROR(writer->AppendRecords(block));
  const auto names = [&sources] {
    return absl::StrJoin(sources, ", ", [](std::string* out, const LasSource& source) {
      absl::StrAppend(out, "'", source.name, "'");
    });
  };
  if (outliers.size() != usable) {
    return Invalid(absl::StrCat(outliers.size(), " flags for the ", usable, " points read from ",
                                names(), " (withheld, noise or other classes left out)"));
  }
  if (written == 0 && !as_noise) {
    return Invalid(absl::StrCat("no point of ", names(), " is kept"));
  }
  const bool extended_counts = first.minor >= 4 && first.header_size >= kHeaderSize14;
  constexpr uint64_t kLegacyMax = std::numeric_limits<uint32_t>::max();
  if (!extended_counts && written > kLegacyMax) {
    return absl::FailedPreconditionError(absl::StrCat(written, " points are more than LAS 1.",
                                                      first.minor, " counts (", kLegacyMax, ")"));
  }

  // LAS 1.3's waveform packets and LAS 1.4's extended records, after the points, move with
  // their end.
  const size_t points_end = head.size() + written * join.record_length;
  const auto move_start = [&](size_t field) {
    const uint64_t start = Load<uint64_t>(first_head, field);
    if (start >= first.points_end()) {
      StoreLittleEndian<uint64_t>(start - first.points_end() + points_end, field, &head);
    }
  };
  if (first.minor >= 3 && first.header_size >= kHeaderSize13) move_start(kWaveformStart);
  if (extended_counts) {
    move_start(kEvlrStart);
    StoreLittleEndian<uint64_t>(written, kPointCount, &head);
    for (int r = 1; r <= 15; ++r) {
      StoreLittleEndian<uint64_t>(by_return[r], kByReturn14 + 8 * (r - 1), &head);
    }
  }
  // The legacy counts stay zero where the file left them so (LAS 1.4 with formats 6-10, or
  // more points than they hold), and become so beyond what they hold or for records joined
  // into formats 6-10.
  if (!extended_counts || Load<uint32_t>(first_head, kLegacyPointCount) != 0) {
    const bool fits = written <= kLegacyMax && join.format < 6;
    StoreLittleEndian(static_cast<uint32_t>(fits ? written : 0), kLegacyPointCount, &head);
    for (int r = 1; r <= 5; ++r) {
      StoreLittleEndian(static_cast<uint32_t>(fits ? by_return[r] : 0),
                        kLegacyByReturn + 4 * (r - 1), &head);
    }
  }
  for (int c = 0; c < 3; ++c) {
    StoreLittleEndian(scale[c], kScale + 8 * c, &head);
    StoreLittleEndian(written > 0 ? high[c] : 0.0, kBounds + 16 * c, &head);
    StoreLittleEndian(written > 0 ? low[c] : 0.0, kBounds + 16 * c + 8, &head);
  }
  SetGeneratingSoftware(&head);
  if (joined != nullptr) {
    *joined = {join.base, first.minor, join.format,
               std::any_of(opened.begin(), opened.end(), [&](const OpenedLas& source) {
                 return source.header.format != join.format;
               })};
  }
  return writer->Finish(head, opened[join.base].tail);
}

absl::StatusOr<std::string> FormatCleanedLas(const std::vector<LasSource>& sources,
                                             const std::vector<bool>& outliers,
                                             LasOutlierRecords records,
                                             const std::optional<LasClasses>& classes,
                                             LasJoin* join) {
  StringSink out;
  PlainLasWriter writer(&out);
  NM_RETURN_IF_ERROR(WriteCleanedLasTo(sources, outliers, records, classes, join, &writer));
  return std::move(out.bytes());
}

}  // namespace neuralmesh::io_internal
