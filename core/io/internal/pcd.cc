#include "core/io/internal/pcd.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/lzf.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

// Bounds that keep a malformed header from asking for absurd work or memory: fields of a
// point, values of one field, bytes of a point record.
constexpr size_t kMaxFields = 1024;
constexpr uint64_t kMaxCount = 1 << 20;
constexpr uint64_t kMaxRecordBytes = 1 << 24;
// LZF turns 3 bytes into at most 264: data claiming more per compressed byte are not LZF.
constexpr uint64_t kMaxLzfExpansion = 100;

template <typename... Args>
absl::Status Invalid(const Args&... args) {
  return absl::InvalidArgumentError(absl::StrCat("PCD: ", args...));
}

enum class DataKind { kAscii, kBinary, kCompressed };

// One field of the point record: `count` values of `size` bytes of `type` (F float, I signed,
// U unsigned integer), at byte `offset` of a binary record.
struct Field {
  std::string name;
  int size = 4;
  char type = 'F';
  uint64_t count = 1;
  uint64_t offset = 0;

  uint64_t bytes() const { return size * count; }
};

struct PcdHeader {
  std::vector<Field> fields;
  uint64_t points = 0;
  uint64_t record_bytes = 0;
  DataKind kind = DataKind::kAscii;
  size_t data_offset = 0;  // Where the points begin.
};

// The index of the field `name`, or -1.
int FieldIndex(const PcdHeader& header, absl::string_view name) {
  for (size_t i = 0; i < header.fields.size(); ++i) {
    if (header.fields[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

absl::StatusOr<uint64_t> Count(absl::string_view token, int line, absl::string_view what) {
  int64_t value = 0;
  if (!ParseInt64(token, &value) || value < 0) {
    return LineError(line,
                     absl::StrCat(what, " must be a non-negative integer, not ", Quoted(token)));
  }
  return static_cast<uint64_t>(value);
}

absl::StatusOr<PcdHeader> ParseHeader(absl::string_view data) {
  PcdHeader header;
  LineCursor cursor(data);
  absl::string_view line;
  std::vector<absl::string_view> tokens;
  std::vector<std::string> names;
  std::vector<uint64_t> sizes, counts;
  std::vector<char> types;
  std::optional<uint64_t> width, height, points;
  bool has_data = false;
  while (!has_data && cursor.Next(&line)) {
    SplitWhitespace(StripHashComment(line), &tokens);
    if (tokens.empty()) continue;
    const int at = cursor.line_number();
    const absl::string_view key = tokens[0];
    const size_t values = tokens.size() - 1;
    if (key == "FIELDS" || key == "COLUMNS") {
      if (values == 0 || values > kMaxFields) {
        return LineError(at,
                         absl::StrCat("FIELDS names 1 to ", kMaxFields, " fields, not ", values));
      }
      names.clear();
      for (size_t i = 1; i < tokens.size(); ++i) names.emplace_back(tokens[i]);
    } else if (key == "SIZE" || key == "COUNT") {
      std::vector<uint64_t>& list = key == "SIZE" ? sizes : counts;
      list.clear();
      for (size_t i = 1; i < tokens.size(); ++i) {
        NM_ASSIGN_OR_RETURN(const uint64_t value, Count(tokens[i], at, key));
        list.push_back(value);
      }
    } else if (key == "TYPE") {
      types.clear();
      for (size_t i = 1; i < tokens.size(); ++i) {
        if (tokens[i] != "F" && tokens[i] != "I" && tokens[i] != "U") {
          return LineError(at, absl::StrCat("TYPE ", Quoted(tokens[i]), " is not F, I or U"));
        }
        types.push_back(tokens[i][0]);
      }
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      if (values != 1) return LineError(at, absl::StrCat(key, " takes one number"));
      NM_ASSIGN_OR_RETURN(const uint64_t value, Count(tokens[1], at, key));
      (key == "WIDTH" ? width : key == "HEIGHT" ? height : points) = value;
    } else if (key == "DATA") {
      if (values != 1)
        return LineError(at, "DATA takes one word: ascii, binary or binary_compressed");
      if (tokens[1] == "ascii") {
        header.kind = DataKind::kAscii;
      } else if (tokens[1] == "binary") {
        header.kind = DataKind::kBinary;
      } else if (tokens[1] == "binary_compressed") {
        header.kind = DataKind::kCompressed;
      } else {
        return LineError(at, absl::StrCat("DATA ", Quoted(tokens[1]),
                                          " is not ascii, binary or binary_compressed"));
      }
      has_data = true;
      header.data_offset = cursor.offset();
    }
    // VERSION, VIEWPOINT (the sensor's pose, which does not move the points) and keys of
    // later versions say nothing this reader needs.
  }
  if (!has_data) {
    return Invalid(names.empty() ? "no FIELDS line: not a PCD file"
                                 : "the header has no DATA line");
  }
  const size_t n = names.size();
  if (n == 0) return Invalid("the header has no FIELDS line");
  if (counts.empty()) counts.assign(n, 1);  // COUNT is optional (before version 0.7, absent).
  if (sizes.size() != n || types.size() != n || counts.size() != n) {
    return Invalid("FIELDS names ", n, " fields but SIZE gives ", sizes.size(), ", TYPE ",
                   types.size(), " and COUNT ", counts.size());
  }
  for (size_t i = 0; i < n; ++i) {
    Field field;
    field.name = names[i];
    field.type = types[i];
    if (sizes[i] != 1 && sizes[i] != 2 && sizes[i] != 4 && sizes[i] != 8) {
      return Invalid("field ", field.name, " has SIZE ", sizes[i], "; sizes are 1, 2, 4 or 8");
    }
    field.size = static_cast<int>(sizes[i]);
    if (field.type == 'F' && field.size < 4) {
      return Invalid("field ", field.name, " is a float of ", field.size, " bytes");
    }
    if (counts[i] == 0 || counts[i] > kMaxCount) {
      return Invalid("field ", field.name, " has COUNT ", counts[i], "; 1 to ", kMaxCount);
    }
    field.count = counts[i];
    field.offset = header.record_bytes;
    header.record_bytes += field.bytes();
    if (header.record_bytes > kMaxRecordBytes) {
      return Invalid("a point takes more than ", kMaxRecordBytes, " bytes");
    }
    header.fields.push_back(std::move(field));
  }
  for (const char* axis : {"x", "y", "z"}) {
    const int i = FieldIndex(header, axis);
    if (i < 0) return Invalid("no field ", axis, " (FIELDS ", absl::StrJoin(names, " "), ")");
    if (header.fields[i].count != 1) return Invalid("field ", axis, " has COUNT above 1");
  }
  if (!width.has_value() && !points.has_value()) return Invalid("the header has no WIDTH");
  const uint64_t h = height.value_or(1);
  if (width.has_value() && h != 0 && *width > UINT64_MAX / h) {
    return Invalid("WIDTH ", *width, " x HEIGHT ", h, " is too large");
  }
  header.points = width.has_value() ? *width * h : *points;
  if (points.has_value() && *points != header.points) {
    return Invalid("POINTS ", *points, " is not WIDTH ", *width, " x HEIGHT ", h);
  }
  return header;
}

// A value of `field` stored at `p`, little-endian.
double ValueAt(const char* p, const Field& field) {
  switch (field.type) {
    case 'F':
      return field.size == 4 ? double{LoadScalar<float>(p, false)} : LoadScalar<double>(p, false);
    case 'I':
      switch (field.size) {
        case 1:
          return LoadScalar<int8_t>(p, false);
        case 2:
          return LoadScalar<int16_t>(p, false);
        case 4:
          return LoadScalar<int32_t>(p, false);
        default:
          return static_cast<double>(LoadScalar<int64_t>(p, false));
      }
    default:
      switch (field.size) {
        case 1:
          return LoadScalar<uint8_t>(p, false);
        case 2:
          return LoadScalar<uint16_t>(p, false);
        case 4:
          return LoadScalar<uint32_t>(p, false);
        default:
          return static_cast<double>(LoadScalar<uint64_t>(p, false));
      }
  }
}

// PCL's packed colour: 0x00RRGGBB (or 0xAARRGGBB), in a float's bits or an unsigned integer
// (RolesOf takes only fields of 4 bytes).
uint32_t PackedColorAt(const char* p) { return LoadScalar<uint32_t>(p, false); }

// The packed colour an ASCII value gives: the integer PCL writes since 1.9, or the bits of the
// float that older files hold (a colour's bits make a tiny, non-integer float).
uint32_t PackedColorOfText(double value) {
  if (value >= 0 && value < 4294967296.0 && value == std::floor(value)) {
    return static_cast<uint32_t>(value);
  }
  const float f = static_cast<float>(value);
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

Rgb Unpacked(uint32_t packed) {
  return {static_cast<uint8_t>(packed >> 16), static_cast<uint8_t>(packed >> 8),
          static_cast<uint8_t>(packed)};
}

// Which fields become what.
struct Roles {
  std::array<int, 3> position = {-1, -1, -1};
  std::array<int, 3> normal = {-1, -1, -1};
  int color = -1;
  int weight = -1;
};

// The first of the fields `names` that holds one value (of `size` bytes, when given), or -1.
int FirstSingleField(const PcdHeader& header, std::initializer_list<const char*> names,
                     int size = 0) {
  for (const char* name : names) {
    const int i = FieldIndex(header, name);
    if (i >= 0 && header.fields[i].count == 1 && (size == 0 || header.fields[i].size == size)) {
      return i;
    }
  }
  return -1;
}

Roles RolesOf(const PcdHeader& header) {
  Roles roles;
  const char* const axes[3] = {"x", "y", "z"};
  const char* const normals[3] = {"normal_x", "normal_y", "normal_z"};
  for (int c = 0; c < 3; ++c) {
    roles.position[c] = FieldIndex(header, axes[c]);
    roles.normal[c] = FieldIndex(header, normals[c]);
  }
  for (int c = 0; c < 3; ++c) {
    if (roles.normal[c] < 0 || header.fields[roles.normal[c]].count != 1) {
      roles.normal = {-1, -1, -1};
      break;
    }
  }
  roles.color = FirstSingleField(header, {"rgb", "rgba"}, /*size=*/4);
  roles.weight = FirstSingleField(header, {"confidence", "weight", "quality"});
  return roles;
}

// The points as they are read, before their origin is chosen.
class PointSink {
 public:
  PointSink(const Roles& roles, PositionPrecision precision, ParsedGeometry* out)
      : roles_(roles), out_(out), positions_(precision) {}

  // A point, from its fields' first values (`value(i)`) and its packed colour; left out
  // without a finite position.
  template <typename ValueOf>
  void Add(const ValueOf& value, uint32_t packed_color) {
    Point3d p;
    for (int c = 0; c < 3; ++c) p[c] = value(roles_.position[c]);
    for (int c = 0; c < 3; ++c) {
      // Text may hold the largest float as a decimal a little beyond it ("3.4028235e+38").
      if (!std::isfinite(NarrowToFloat(p[c]))) {
        ++out_->left_out.invalid;
        return;
      }
    }
    positions_.Add(p);
    if (roles_.normal[0] >= 0) {
      out_->normals.emplace_back(NarrowToFloat(value(roles_.normal[0])),
                                 NarrowToFloat(value(roles_.normal[1])),
                                 NarrowToFloat(value(roles_.normal[2])));
    }
    if (roles_.weight >= 0) out_->weights.push_back(NarrowToFloat(value(roles_.weight)));
    if (roles_.color >= 0) out_->colors.push_back(Unpacked(packed_color));
  }

  void Reserve(size_t points) {
    positions_.Reserve(points);
    if (roles_.normal[0] >= 0) out_->normals.reserve(points);
    if (roles_.weight >= 0) out_->weights.reserve(points);
    if (roles_.color >= 0) out_->colors.reserve(points);
  }

  absl::Status Finish() {
    if (positions_.size() == 0 && out_->left_out.invalid > 0) {
      return Invalid("all ", out_->left_out.invalid,
                     " points lack a position (NaN or infinite x, y or z)");
    }
    positions_.MoveTo(out_);
    return absl::OkStatus();
  }

 private:
  const Roles roles_;
  ParsedGeometry* const out_;
  PositionCollector positions_;
};

absl::Status ReadAscii(absl::string_view body, const PcdHeader& header, const Roles& roles,
                       int first_line, PointSink* sink) {
  uint64_t values = 0;
  std::vector<uint64_t> first_value;  // Of each field, in a line's values.
  for (const Field& field : header.fields) {
    first_value.push_back(values);
    values += field.count;
  }
  LineCursor cursor(body);
  absl::string_view line;
  std::vector<absl::string_view> tokens;
  std::vector<double> parsed(header.fields.size());
  sink->Reserve(std::min<uint64_t>(header.points, body.size() / 2 + 1));
  uint64_t read = 0;
  while (read < header.points && cursor.Next(&line)) {
    SplitWhitespace(line, &tokens);
    if (tokens.empty()) continue;
    const int at = first_line + cursor.line_number();
    if (tokens.size() != values) {
      return LineError(at, absl::StrCat("point ", read, " has ", tokens.size(),
                                        " values; the fields take ", values));
    }
    for (size_t f = 0; f < header.fields.size(); ++f) {
      const absl::string_view token = tokens[first_value[f]];
      if (!ParseDouble(token, &parsed[f])) {
        return LineError(at, absl::StrCat(header.fields[f].name, " of point ", read, " is ",
                                          Quoted(token), ", not a number"));
      }
    }
    const uint32_t packed = roles.color >= 0 ? PackedColorOfText(parsed[roles.color]) : 0;
    sink->Add([&](int f) { return parsed[f]; }, packed);
    ++read;
  }
  if (read < header.points) {
    return Invalid("the data end after ", read, " of ", header.points, " points");
  }
  return absl::OkStatus();
}

// Binary points: `record(i)` gives where point i's field `f` begins.
template <typename Locate>
void ReadBinary(const PcdHeader& header, const Roles& roles, const Locate& locate,
                PointSink* sink) {
  sink->Reserve(header.points);
  for (uint64_t i = 0; i < header.points; ++i) {
    const uint32_t packed = roles.color >= 0 ? PackedColorAt(locate(i, roles.color)) : 0;
    sink->Add([&](int f) { return ValueAt(locate(i, f), header.fields[f]); }, packed);
  }
}

// Whether the binary points fit in `body`, the bytes after the header.
absl::Status CheckBinaryPointsFit(const PcdHeader& header, absl::string_view body) {
  if (header.points > body.size() / header.record_bytes) {
    return Invalid(header.points, " points of ", header.record_bytes, " bytes do not fit in the ",
                   body.size(), " bytes after the header");
  }
  return absl::OkStatus();
}

// Binary points read one at a time (PcdPointRecords).
class BinaryPointRecords final : public PointRecords {
 public:
  BinaryPointRecords(absl::string_view body, PcdHeader header, const Roles& roles)
      : body_(body), header_(std::move(header)), roles_(roles) {}

  uint64_t size() const override { return header_.points; }
  // Kept as ParsePcd keeps a point: with a position.
  std::optional<Point3d> KeptPoint(uint64_t i) const override {
    Point3d p;
    for (int c = 0; c < 3; ++c) {
      const Field& field = header_.fields[roles_.position[c]];
      p[c] = ValueAt(Address(i) + field.offset, field);
      if (!std::isfinite(NarrowToFloat(p[c]))) return std::nullopt;
    }
    return p;
  }
  const char* Address(uint64_t i) const override { return body_.data() + i * header_.record_bytes; }
  bool has_colors() const override { return roles_.color >= 0; }
  std::optional<Rgb> StatedColor(uint64_t i) const override {
    if (roles_.color < 0) return std::nullopt;
    return Unpacked(PackedColorAt(Address(i) + header_.fields[roles_.color].offset));
  }
  std::optional<Point3d> Resolution() const override { return std::nullopt; }
  std::optional<std::pair<Point3d, Point3d>> StatedBounds() const override { return std::nullopt; }

 private:
  absl::string_view body_;
  PcdHeader header_;
  Roles roles_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<PointRecords>> PcdPointRecords(absl::string_view data) {
  NM_ASSIGN_OR_RETURN(PcdHeader header, ParseHeader(data));
  if (header.kind != DataKind::kBinary) {
    return Invalid(header.kind == DataKind::kAscii ? "ascii" : "binary_compressed",
                   " data: no point can be found without reading those before (binary data "
                   "can)");
  }
  const absl::string_view body = data.substr(header.data_offset);
  NM_RETURN_IF_ERROR(CheckBinaryPointsFit(header, body));
  const Roles roles = RolesOf(header);
  return std::unique_ptr<PointRecords>(
      std::make_unique<BinaryPointRecords>(body, std::move(header), roles));
}

absl::StatusOr<ParsedGeometry> ParsePcd(absl::string_view data, PositionPrecision precision) {
  NM_ASSIGN_OR_RETURN(const PcdHeader header, ParseHeader(data));
  const Roles roles = RolesOf(header);
  ParsedGeometry out;
  PointSink sink(roles, precision, &out);
  const absl::string_view body = data.substr(header.data_offset);
  if (header.kind == DataKind::kAscii) {
    const int header_lines =
        static_cast<int>(std::count(data.begin(), data.begin() + header.data_offset, '\n'));
    NM_RETURN_IF_ERROR(ReadAscii(body, header, roles, header_lines, &sink));
  } else if (header.kind == DataKind::kBinary) {
    NM_RETURN_IF_ERROR(CheckBinaryPointsFit(header, body));
    ReadBinary(
        header, roles,
        [&](uint64_t i, int f) {
          return body.data() + i * header.record_bytes + header.fields[f].offset;
        },
        &sink);
  } else {
    if (body.size() < 8) return Invalid("the compressed points lack their sizes");
    const uint64_t compressed = LoadScalar<uint32_t>(body.data(), false);
    const uint64_t size = LoadScalar<uint32_t>(body.data() + 4, false);
    if (compressed > body.size() - 8) {
      return Invalid(compressed, " compressed bytes do not fit in the ", body.size() - 8,
                     " after the header");
    }
    if (size != header.points * header.record_bytes) {
      return Invalid("the compressed points decompress to ", size, " bytes, not ", header.points,
                     " points of ", header.record_bytes);
    }
    if (size > compressed * kMaxLzfExpansion + 64) {
      return Invalid(compressed, " compressed bytes cannot hold ", size);
    }
    std::string columns(size, '\0');
    if (const absl::Status lzf = LzfDecompress(body.substr(8, compressed), &columns); !lzf.ok()) {
      return Invalid(lzf.message());
    }
    // Field by field: all points' values of the first field, then of the second, ...
    ReadBinary(
        header, roles,
        [&](uint64_t i, int f) {
          const Field& field = header.fields[f];
          return columns.data() + header.points * field.offset + i * field.bytes();
        },
        &sink);
  }
  NM_RETURN_IF_ERROR(sink.Finish());
  return out;
}

absl::StatusOr<std::string> FormatPcd(const GeometryView& geometry, PcdData data) {
  const bool doubles = geometry.has_origin();
  const size_t n = geometry.positions.size();
  const bool normals = !geometry.normals.empty();
  const bool colors = !geometry.colors.empty();
  const bool weights = !geometry.weights.empty();
  const bool ascii = data == PcdData::kAscii;
  std::string fields = "x y z", sizes = doubles ? "8 8 8" : "4 4 4", types = "F F F",
              counts = "1 1 1";
  uint64_t record_bytes = doubles ? 24 : 12;
  // Another field of 4 bytes.
  const auto add = [&](absl::string_view name, absl::string_view type) {
    absl::StrAppend(&fields, " ", name);
    absl::StrAppend(&sizes, " 4");
    absl::StrAppend(&types, " ", type);
    absl::StrAppend(&counts, " 1");
    record_bytes += 4;
  };
  if (normals) {
    for (const char* name : {"normal_x", "normal_y", "normal_z"}) add(name, "F");
  }
  if (colors) add("rgb", ascii ? "U" : "F");
  if (weights) add("confidence", "F");
  const char* kind = ascii ? "ascii" : data == PcdData::kBinary ? "binary" : "binary_compressed";
  std::string out =
      absl::StrCat("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS ", fields,
                   "\nSIZE ", sizes, "\nTYPE ", types, "\nCOUNT ", counts, "\nWIDTH ", n,
                   "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS ", n, "\nDATA ", kind, "\n");
  const auto packed_rgb = [&](size_t i) {
    const Rgb& rgb = geometry.colors[i];
    return uint32_t{rgb[0]} << 16 | uint32_t{rgb[1]} << 8 | uint32_t{rgb[2]};
  };
  if (ascii) {
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        if (c > 0) out.push_back(' ');
        AppendCoordinate(geometry.positions[i][c], geometry.origin[c], &out);
      }
      if (normals) {
        for (int c = 0; c < 3; ++c) {
          out.push_back(' ');
          AppendFloat(geometry.normals[i][c], &out);
        }
      }
      if (colors) absl::StrAppend(&out, " ", packed_rgb(i));
      if (weights) {
        out.push_back(' ');
        AppendFloat(geometry.weights[i], &out);
      }
      out.push_back('\n');
    }
    return out;
  }
  // The values of field `f` of every point, appended to `records` (the point's record when
  // called point by point, the column when field by field).
  const auto append_field = [&](int f, size_t i, std::string* records) {
    if (f < 3) {
      AppendPositionCoordinate(geometry, i, f, records);
    } else if (f < 6) {
      AppendLittleEndian(geometry.normals[i][f - 3], records);
    } else if (f == 6) {
      AppendLittleEndian(packed_rgb(i), records);
    } else {
      AppendLittleEndian(geometry.weights[i], records);
    }
  };
  std::vector<int> written = {0, 1, 2};
  if (normals) written.insert(written.end(), {3, 4, 5});
  if (colors) written.push_back(6);
  if (weights) written.push_back(7);
  if (data == PcdData::kBinary) {
    for (size_t i = 0; i < n; ++i) {
      for (int f : written) append_field(f, i, &out);
    }
    return out;
  }
  // The compressed size may exceed the data's by a 32nd.
  const uint64_t largest = uint64_t{n} * record_bytes * 33 / 32 + 1;
  if (largest > std::numeric_limits<uint32_t>::max()) {
    return Invalid(n, " points of ", record_bytes, " bytes are more than binary_compressed data ",
                   "holds (sizes of 32 bits); write them as binary");
  }
  std::string columns;
  columns.reserve(n * record_bytes);
  for (int f : written) {
    for (size_t i = 0; i < n; ++i) append_field(f, i, &columns);
  }
  const std::string compressed = LzfCompress(columns);
  AppendLittleEndian(static_cast<uint32_t>(compressed.size()), &out);
  AppendLittleEndian(static_cast<uint32_t>(columns.size()), &out);
  return out + compressed;
}

}  // namespace neuralmesh::io_internal
