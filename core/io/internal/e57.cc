#include "core/io/internal/e57.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/e57_pages.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"
#include "core/io/internal/xml.h"
#include "core/rgb.h"
#include "core/status_macros.h"
#include "core/version.h"

namespace neuralmesh::io_internal {
namespace {

constexpr absl::string_view kSignature = "ASTM-E57";
constexpr size_t kFileHeaderSize = 48;
constexpr size_t kSectionHeaderSize = 32;
constexpr uint8_t kCompressedVectorSection = 1;
constexpr uint8_t kIndexPacket = 0, kDataPacket = 1, kEmptyPacket = 2;
constexpr size_t kMaxPacketSize = 65536;  // A packet's length is stored less one in 16 bits.
constexpr size_t kDataPacketHeaderSize = 6;
constexpr absl::string_view kNormalsNamespace = "http://www.libe57.org/E57_EXT_surface_normals.txt";

absl::Status Invalid(absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("E57: ", what));
}

uint64_t Load64(absl::string_view bytes, size_t at) {
  return LoadScalar<uint64_t>(bytes.data() + at, /*big_endian=*/false);
}

// ---- The XML tree --------------------------------------------------------------------------

// The element's text as a number of its E57 type (Integer, ScaledInteger or Float; empty text
// is 0, the standard's default). `what` names it in errors.
absl::StatusOr<double> NumberOf(const XmlElement& element, absl::string_view what) {
  const std::string* type = element.Attribute("type");
  const absl::string_view text = absl::StripAsciiWhitespace(element.text);
  double value = 0;
  if (!text.empty() && (!ParseDouble(text, &value) || !std::isfinite(value))) {
    return Invalid(absl::StrCat(what, " is ", Quoted(text), ", not a finite number"));
  }
  if (type != nullptr && *type == "ScaledInteger") {
    double scale = 1, offset = 0;
    const std::string* s = element.Attribute("scale");
    const std::string* o = element.Attribute("offset");
    if ((s != nullptr && !ParseDouble(*s, &scale)) || (o != nullptr && !ParseDouble(*o, &offset))) {
      return Invalid(absl::StrCat(what, "'s scale or offset is not a number"));
    }
    value = value * scale + offset;
  } else if (type == nullptr || (*type != "Integer" && *type != "Float")) {
    return Invalid(absl::StrCat(what, " is not a number (its type is ",
                                type == nullptr ? "missing" : Quoted(*type), ")"));
  }
  return value;
}

// Child `name` of `parent` as a number, or `fallback` when it is missing.
absl::StatusOr<double> ChildNumber(const XmlElement& parent, absl::string_view name,
                                   double fallback, absl::string_view what) {
  const XmlElement* child = parent.Child(name);
  if (child == nullptr) return fallback;
  return NumberOf(*child, absl::StrCat(what, " ", name));
}

// An unsigned integer attribute that must be present.
absl::StatusOr<uint64_t> CountAttribute(const XmlElement& element, absl::string_view name,
                                        absl::string_view what) {
  const std::string* text = element.Attribute(name);
  uint64_t value = 0;
  if (text == nullptr || !absl::SimpleAtoi(*text, &value)) {
    return Invalid(absl::StrCat(what, " has no ", name, " attribute of a non-negative integer"));
  }
  return value;
}

// ---- Fields of a scan's prototype ----------------------------------------------------------

struct Field {
  enum class Kind { kInteger, kFloat, kOther };
  std::string name;
  Kind kind = Kind::kOther;
  // Integer and ScaledInteger: the stored integer is minimum + the packed one, of `bits` bits;
  // its value is that times `scale` plus `offset`.
  int64_t minimum = std::numeric_limits<int64_t>::min();
  int64_t maximum = std::numeric_limits<int64_t>::max();
  double scale = 1, offset = 0;
  int bits = 0;
  bool single = false;  // Float: 4 bytes each, not 8.

  // The bits a value takes in the field's bytestream; 0 for a constant, and for a field that is
  // not read (a String).
  int Width() const {
    if (kind == Kind::kFloat) return single ? 32 : 64;
    return kind == Kind::kInteger ? bits : 0;
  }
};

// The number of bits that hold every integer from `minimum` to `maximum`.
int BitsNeeded(int64_t minimum, int64_t maximum) {
  const uint64_t range = static_cast<uint64_t>(maximum) - static_cast<uint64_t>(minimum);
  int bits = 0;
  while (bits < 64 && (range >> bits) != 0) ++bits;
  return bits;
}

absl::Status ReadIntegerAttribute(const XmlElement& element, const char* name, int64_t* value,
                                  absl::string_view what) {
  const std::string* text = element.Attribute(name);
  if (text != nullptr && !absl::SimpleAtoi(*text, value)) {
    return Invalid(absl::StrCat(what, "'s ", name, " is ", Quoted(*text), ", not an integer"));
  }
  return absl::OkStatus();
}

absl::Status ReadDoubleAttribute(const XmlElement& element, const char* name, double* value,
                                 absl::string_view what) {
  const std::string* text = element.Attribute(name);
  if (text != nullptr && (!ParseDouble(*text, value) || !std::isfinite(*value))) {
    return Invalid(absl::StrCat(what, "'s ", name, " is ", Quoted(*text), ", not a number"));
  }
  return absl::OkStatus();
}

// The prototype's fields in bytestream order: its leaves, depth first.
absl::Status CollectFields(const XmlElement& node, absl::string_view scan,
                           std::vector<Field>* fields) {
  for (const XmlElement& child : node.children) {
    const std::string* type = child.Attribute("type");
    const std::string what = absl::StrCat(scan, "'s field ", child.name);
    if (type == nullptr) return Invalid(absl::StrCat(what, " has no type"));
    if (*type == "Structure" || *type == "Vector") {
      NM_RETURN_IF_ERROR(CollectFields(child, scan, fields));
      continue;
    }
    Field field;
    field.name = child.name;
    if (*type == "Integer" || *type == "ScaledInteger") {
      field.kind = Field::Kind::kInteger;
      NM_RETURN_IF_ERROR(ReadIntegerAttribute(child, "minimum", &field.minimum, what));
      NM_RETURN_IF_ERROR(ReadIntegerAttribute(child, "maximum", &field.maximum, what));
      if (field.maximum < field.minimum) {
        return Invalid(absl::StrCat(what, "'s maximum ", field.maximum, " is below its minimum ",
                                    field.minimum));
      }
      field.bits = BitsNeeded(field.minimum, field.maximum);
      if (*type == "ScaledInteger") {
        NM_RETURN_IF_ERROR(ReadDoubleAttribute(child, "scale", &field.scale, what));
        NM_RETURN_IF_ERROR(ReadDoubleAttribute(child, "offset", &field.offset, what));
      }
    } else if (*type == "Float") {
      field.kind = Field::Kind::kFloat;
      const std::string* precision = child.Attribute("precision");
      field.single = precision != nullptr && absl::EqualsIgnoreCase(*precision, "single");
    }
    fields->push_back(std::move(field));
  }
  return absl::OkStatus();
}

// ---- The compressed vector of a scan's points ----------------------------------------------

// The data packets of a scan's compressed vector section, read one after another.
class DataPackets {
 public:
  // The section at physical offset `file_offset`, of a prototype of `fields` fields.
  static absl::StatusOr<DataPackets> Open(const E57LogicalView& file, uint64_t file_offset,
                                          size_t fields, absl::string_view scan) {
    const uint64_t start = E57LogicalOffset(file_offset);
    if (IsE57Checksum(file_offset) || start > file.size() ||
        file.size() - start < kSectionHeaderSize) {
      return Invalid(absl::StrCat(scan, "'s points begin at byte ", file_offset,
                                  ", where the file holds no section"));
    }
    if (file.Load<uint8_t>(start) != kCompressedVectorSection) {
      return Invalid(absl::StrCat(scan, "'s points at byte ", file_offset,
                                  " are not a compressed vector section"));
    }
    const uint64_t length = file.Load<uint64_t>(start + 8);
    const uint64_t data_offset = file.Load<uint64_t>(start + 16);
    if (length > file.size() - start) {
      return Invalid(absl::StrCat(scan, "'s section of ", length, " bytes runs past the file"));
    }
    const uint64_t at = E57LogicalOffset(data_offset);
    if (IsE57Checksum(data_offset) || at < start + kSectionHeaderSize || at > start + length) {
      return Invalid(absl::StrCat(scan, "'s first data packet, at byte ", data_offset,
                                  ", lies outside its section"));
    }
    return DataPackets(file, at, start + length, fields, scan);
  }

  // Reads up to the next data packet (past index and empty ones) and appends its buffer of each
  // field f to *into[f] where that is not null. INVALID_ARGUMENT at the end of the section, for
  // a packet that runs past it, of an unknown type, or whose number of buffers is not the
  // prototype's.
  absl::Status Next(const std::vector<std::string*>& into) {
    while (true) {
      if (end_ - at_ < 4) {
        return Invalid(absl::StrCat(scan_, "'s section ends before all its records (its packets ",
                                    "are missing or short)"));
      }
      const uint64_t type = file_->Load<uint8_t>(at_);
      const uint64_t length = file_->Load<uint16_t>(at_ + 2) + 1;
      if (length > end_ - at_) {
        return Invalid(
            absl::StrCat(scan_, "'s packet at logical byte ", at_, " runs past its section"));
      }
      const uint64_t packet = at_;
      at_ += length;
      if (type == kIndexPacket || type == kEmptyPacket) continue;
      if (type != kDataPacket) {
        return Invalid(absl::StrCat(scan_, "'s section holds a packet of unknown type ", type));
      }
      const uint64_t count =
          length >= kDataPacketHeaderSize ? file_->Load<uint16_t>(packet + 4) : 0;
      if (count != fields_) {
        return Invalid(absl::StrCat(scan_, "'s data packet holds ", count,
                                    " bytestreams where its prototype declares ", fields_,
                                    " fields"));
      }
      uint64_t buffer = packet + kDataPacketHeaderSize + 2 * count;
      if (buffer > packet + length) {
        return Invalid(absl::StrCat(scan_, "'s data packet is shorter than its header"));
      }
      for (size_t f = 0; f < count; ++f) {
        const uint64_t size = file_->Load<uint16_t>(packet + kDataPacketHeaderSize + 2 * f);
        if (size > packet + length - buffer) {
          return Invalid(absl::StrCat(scan_, "'s data packet's buffers run past its end"));
        }
        if (into[f] != nullptr) file_->Append(buffer, size, into[f]);
        buffer += size;
      }
      return absl::OkStatus();
    }
  }

 private:
  DataPackets(const E57LogicalView& file, uint64_t at, uint64_t end, size_t fields,
              absl::string_view scan)
      : file_(&file), at_(at), end_(end), fields_(fields), scan_(scan) {}

  const E57LogicalView* file_;
  uint64_t at_, end_;  // The next packet and the section's end, logical.
  size_t fields_;
  std::string scan_;
};

// The integer packed at bit `bit` of `bytes`, `bits` wide, least significant bit first (E57's
// bitpack codec).
uint64_t Unpack(absl::string_view bytes, uint64_t bit, int bits) {
  const uint64_t byte = bit / 8;
  const int shift = static_cast<int>(bit % 8);
  uint64_t value;
  if (shift + bits <= 64 && byte + 8 <= bytes.size()) {
    value = Load64(bytes, byte) >> shift;
  } else {
    value = static_cast<uint8_t>(bytes[byte]) >> shift;
    int got = 8 - shift;
    for (uint64_t b = byte + 1; got < bits; ++b, got += 8) {
      value |= uint64_t{static_cast<uint8_t>(bytes[b])} << got;
    }
  }
  return bits == 64 ? value : value & ((uint64_t{1} << bits) - 1);
}

// What has arrived of one field's bytestream and is not decoded yet: values from bit
// `first_bit` of `bytes` on.
struct FieldStream {
  std::string bytes;
  uint64_t first_bit = 0;

  // The number of whole values held.
  uint64_t Values(const Field& field) const {
    if (field.Width() == 0) return std::numeric_limits<uint64_t>::max();
    return (bytes.size() * 8 - first_bit) / field.Width();
  }
  // Drops the first `values` values.
  void Consume(const Field& field, uint64_t values) {
    first_bit += values * field.Width();
    bytes.erase(0, first_bit / 8);
    first_bit %= 8;
  }
};

// Reads the values a field's stream holds, by their index among them; `first_record` numbers
// the first for messages.
class FieldValues {
 public:
  FieldValues(const Field& field, const FieldStream& stream, uint64_t first_record)
      : field_(field), stream_(stream), first_record_(first_record) {}

  absl::StatusOr<double> operator[](uint64_t i) const {
    const absl::string_view bytes = stream_.bytes;
    if (field_.kind == Field::Kind::kFloat) {
      const char* at = bytes.data() + stream_.first_bit / 8;
      if (field_.single) return LoadScalar<float>(at + 4 * i, false);
      return LoadScalar<double>(at + 8 * i, false);
    }
    uint64_t packed = 0;
    if (field_.bits > 0) {
      packed = Unpack(bytes, stream_.first_bit + i * field_.bits, field_.bits);
      if (packed > static_cast<uint64_t>(field_.maximum) - static_cast<uint64_t>(field_.minimum)) {
        return Invalid(absl::StrCat("record ", first_record_ + i, " of field ", field_.name,
                                    " is beyond the field's maximum ", field_.maximum));
      }
    }
    const int64_t stored = static_cast<int64_t>(static_cast<uint64_t>(field_.minimum) + packed);
    return static_cast<double>(stored) * field_.scale + field_.offset;
  }

 private:
  const Field& field_;
  const FieldStream& stream_;
  uint64_t first_record_;
};

// ---- One scan ------------------------------------------------------------------------------

// A scan's pose: a rotation (from a unit quaternion) and a translation.
struct Pose {
  std::array<std::array<double, 3>, 3> rotation = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  Point3d translation = {0, 0, 0};

  Point3d Rotate(const Point3d& p) const {
    Point3d out;
    for (int r = 0; r < 3; ++r) {
      out[r] = rotation[r][0] * p[0] + rotation[r][1] * p[1] + rotation[r][2] * p[2];
    }
    return out;
  }
};

absl::StatusOr<Pose> ReadPose(const XmlElement& scan_element, absl::string_view scan) {
  Pose pose;
  const XmlElement* element = scan_element.Child("pose");
  if (element == nullptr) return pose;
  const std::string what = absl::StrCat(scan, "'s pose");
  if (const XmlElement* rotation = element->Child("rotation")) {
    NM_ASSIGN_OR_RETURN(const double w, ChildNumber(*rotation, "w", 1, what));
    NM_ASSIGN_OR_RETURN(const double x, ChildNumber(*rotation, "x", 0, what));
    NM_ASSIGN_OR_RETURN(const double y, ChildNumber(*rotation, "y", 0, what));
    NM_ASSIGN_OR_RETURN(const double z, ChildNumber(*rotation, "z", 0, what));
    const double norm = std::sqrt(w * w + x * x + y * y + z * z);
    if (!(norm > 0) || !std::isfinite(norm)) {
      return Invalid(absl::StrCat(what, "'s rotation is not a quaternion of non-zero length"));
    }
    const double a = w / norm, b = x / norm, c = y / norm, d = z / norm;
    pose.rotation = {{{1 - 2 * (c * c + d * d), 2 * (b * c - a * d), 2 * (b * d + a * c)},
                      {2 * (b * c + a * d), 1 - 2 * (b * b + d * d), 2 * (c * d - a * b)},
                      {2 * (b * d - a * c), 2 * (c * d + a * b), 1 - 2 * (b * b + c * c)}}};
  }
  if (const XmlElement* translation = element->Child("translation")) {
    for (int c = 0; c < 3; ++c) {
      const char name[2] = {static_cast<char>('x' + c), '\0'};
      NM_ASSIGN_OR_RETURN(pose.translation[c], ChildNumber(*translation, name, 0, what));
    }
  }
  return pose;
}

// The index of the field named `name`, or of one whose name ends in ":" `name` when
// `any_prefix`; -1 when the prototype has none.
int FieldIndex(const std::vector<Field>& fields, absl::string_view name, bool any_prefix = false) {
  for (size_t f = 0; f < fields.size(); ++f) {
    const absl::string_view field = fields[f].name;
    if (field == name || (any_prefix && absl::EndsWith(field, name) && field.size() > name.size() &&
                          field[field.size() - name.size() - 1] == ':')) {
      return static_cast<int>(f);
    }
  }
  return -1;
}

// Three fields that go together (x, y and z), all present or none.
absl::StatusOr<std::optional<std::array<int, 3>>> FieldTriple(
    const std::vector<Field>& fields, const std::array<const char*, 3>& names,
    absl::string_view scan, bool any_prefix = false) {
  std::array<int, 3> found;
  int present = 0;
  for (int c = 0; c < 3; ++c) {
    found[c] = FieldIndex(fields, names[c], any_prefix);
    present += found[c] >= 0;
  }
  if (present == 0) return std::nullopt;
  const int any = found[0] >= 0 ? 0 : found[1] >= 0 ? 1 : 2;
  for (int c = 0; c < 3; ++c) {
    if (found[c] < 0) {
      return Invalid(absl::StrCat(scan, " has a ", names[any], " field but no ", names[c]));
    }
    if (fields[found[c]].kind == Field::Kind::kOther) {
      return Invalid(absl::StrCat(scan, "'s field ", names[c], " is not a number"));
    }
  }
  return found;
}

// The colour limits of channel `c`: the scan's colorLimits, else the field's own range (an
// Integer's minimum and maximum, 0 to 1 for a Float).
absl::StatusOr<std::pair<double, double>> ColorLimits(const XmlElement& scan_element,
                                                      const Field& field, int c,
                                                      absl::string_view scan) {
  static constexpr const char* kChannel[] = {"Red", "Green", "Blue"};
  std::pair<double, double> limits = {0, 1};
  if (field.kind == Field::Kind::kInteger) {
    limits = {field.minimum * field.scale + field.offset,
              field.maximum * field.scale + field.offset};
  }
  if (const XmlElement* element = scan_element.Child("colorLimits")) {
    const std::string what = absl::StrCat(scan, "'s colour limits");
    NM_ASSIGN_OR_RETURN(
        limits.first,
        ChildNumber(*element, absl::StrCat("color", kChannel[c], "Minimum"), limits.first, what));
    NM_ASSIGN_OR_RETURN(
        limits.second,
        ChildNumber(*element, absl::StrCat("color", kChannel[c], "Maximum"), limits.second, what));
  }
  return limits;
}

// What the scans give, gathered before the origin is chosen.
struct Gathered {
  explicit Gathered(PositionPrecision precision) : positions(precision) {}

  PositionCollector positions;
  std::vector<Rgb> colors;
  std::vector<Vec3f> normals;
  bool colored = true;  // Every point so far has a valid colour.
  bool with_normals = true;
  PointsLeftOut left_out;
};

absl::Status ReadScan(const E57LogicalView& file, const XmlElement& scan_element,
                      absl::string_view scan, Gathered* out) {
  const XmlElement* points = scan_element.Child("points");
  if (points == nullptr) return Invalid(absl::StrCat(scan, " has no points"));
  const std::string* points_type = points->Attribute("type");
  if (points_type == nullptr || *points_type != "CompressedVector") {
    return Invalid(absl::StrCat(scan, "'s points are not a CompressedVector"));
  }
  NM_ASSIGN_OR_RETURN(const uint64_t file_offset,
                      CountAttribute(*points, "fileOffset", absl::StrCat(scan, "'s points")));
  NM_ASSIGN_OR_RETURN(const uint64_t records,
                      CountAttribute(*points, "recordCount", absl::StrCat(scan, "'s points")));
  const XmlElement* prototype = points->Child("prototype");
  if (prototype == nullptr) return Invalid(absl::StrCat(scan, "'s points have no prototype"));
  std::vector<Field> fields;
  NM_RETURN_IF_ERROR(CollectFields(*prototype, scan, &fields));

  NM_ASSIGN_OR_RETURN(const auto cartesian,
                      FieldTriple(fields, {"cartesianX", "cartesianY", "cartesianZ"}, scan));
  NM_ASSIGN_OR_RETURN(
      const auto spherical,
      FieldTriple(fields, {"sphericalRange", "sphericalAzimuth", "sphericalElevation"}, scan));
  NM_ASSIGN_OR_RETURN(const auto colors,
                      FieldTriple(fields, {"colorRed", "colorGreen", "colorBlue"}, scan));
  NM_ASSIGN_OR_RETURN(const auto normals,
                      FieldTriple(fields, {"normalX", "normalY", "normalZ"}, scan, true));
  if (!cartesian && !spherical) {
    return Invalid(absl::StrCat(scan, " has neither cartesian nor spherical coordinates"));
  }
  const std::array<int, 3> coordinates = cartesian ? *cartesian : *spherical;
  // Flags stored as anything but numbers are not read.
  const auto numeric = [&](int f) {
    return f >= 0 && fields[f].kind != Field::Kind::kOther ? f : -1;
  };
  const int invalid_state =
      numeric(FieldIndex(fields, cartesian ? "cartesianInvalidState" : "sphericalInvalidState"));
  const int color_invalid = numeric(FieldIndex(fields, "isColorInvalid"));
  // Every record takes at least one bit of a stream or else its values are all one constant;
  // a count no stream could hold is a damaged header, not a reason to allocate.
  uint64_t bits_per_record = 0;
  for (const Field& field : fields) bits_per_record += field.Width();
  if (bits_per_record == 0 ? records > (uint64_t{1} << 24)
                           : records > file.size() * 8 / bits_per_record) {
    return Invalid(absl::StrCat(scan, " claims ", records, " records, more than the file holds"));
  }
  NM_ASSIGN_OR_RETURN(const Pose pose, ReadPose(scan_element, scan));
  std::array<std::pair<double, double>, 3> color_limits;
  for (int c = 0; colors && c < 3; ++c) {
    NM_ASSIGN_OR_RETURN(color_limits[c], ColorLimits(scan_element, fields[(*colors)[c]], c, scan));
  }
  out->colored = out->colored && colors.has_value();
  out->with_normals = out->with_normals && normals.has_value();

  // The fields read, whose streams are kept as the packets bring them, decoded as soon as all
  // of them hold the next records and dropped then: a scan never sits in memory whole.
  std::vector<int> read(coordinates.begin(), coordinates.end());
  for (int f : {invalid_state, color_invalid}) {
    if (f >= 0) read.push_back(f);
  }
  if (out->colored) read.insert(read.end(), colors->begin(), colors->end());
  if (out->with_normals) read.insert(read.end(), normals->begin(), normals->end());
  std::vector<FieldStream> streams(fields.size());
  std::vector<std::string*> into(fields.size(), nullptr);
  for (int f : read) into[f] = &streams[f].bytes;
  std::optional<DataPackets> packets;
  out->positions.Reserve(out->positions.size() + records);
  for (uint64_t done = 0; done < records;) {
    uint64_t ready = records - done;
    for (int f : read) ready = std::min(ready, streams[f].Values(fields[f]));
    if (ready == 0) {
      if (!packets.has_value()) {
        NM_ASSIGN_OR_RETURN(packets, DataPackets::Open(file, file_offset, fields.size(), scan));
      }
      NM_RETURN_IF_ERROR(packets->Next(into));
      continue;
    }
    const auto values = [&](int f) { return FieldValues(fields[f], streams[f], done); };
    for (uint64_t i = 0; i < ready; ++i) {
      if (invalid_state >= 0) {
        NM_ASSIGN_OR_RETURN(const double state, values(invalid_state)[i]);
        if (state != 0) {
          ++out->left_out.invalid;
          continue;
        }
      }
      Point3d local;
      for (int c = 0; c < 3; ++c) {
        NM_ASSIGN_OR_RETURN(local[c], values(coordinates[c])[i]);
      }
      if (!cartesian) {
        const double range = local[0], azimuth = local[1], elevation = local[2];
        local = {range * std::cos(elevation) * std::cos(azimuth),
                 range * std::cos(elevation) * std::sin(azimuth), range * std::sin(elevation)};
      }
      Point3d p = pose.Rotate(local);
      for (int c = 0; c < 3; ++c) {
        p[c] += pose.translation[c];
        if (!(std::fabs(p[c]) <= std::numeric_limits<float>::max())) {
          return Invalid(absl::StrCat("point ", done + i, " of ", scan,
                                      " is not finite or lies beyond a float's range"));
        }
      }
      out->positions.Add(p);
      if (out->colored) {
        if (color_invalid >= 0) {
          NM_ASSIGN_OR_RETURN(const double flag, values(color_invalid)[i]);
          out->colored = flag == 0;
        }
        Rgb color;
        for (int c = 0; c < 3; ++c) {
          NM_ASSIGN_OR_RETURN(const double level, values((*colors)[c])[i]);
          const auto [low, high] = color_limits[c];
          color[c] = high > low ? ChannelFromLevel(level - low, high - low) : 0;
        }
        out->colors.push_back(color);
      }
      if (out->with_normals) {
        Point3d n;
        for (int c = 0; c < 3; ++c) {
          NM_ASSIGN_OR_RETURN(n[c], values((*normals)[c])[i]);
        }
        n = pose.Rotate(n);
        out->normals.emplace_back(NarrowToFloat(n[0]), NarrowToFloat(n[1]), NarrowToFloat(n[2]));
        out->with_normals = std::isfinite(out->normals.back()[0]) &&
                            std::isfinite(out->normals.back()[1]) &&
                            std::isfinite(out->normals.back()[2]);
      }
    }
    for (int f : read) streams[f].Consume(fields[f], ready);
    done += ready;
  }
  return absl::OkStatus();
}

// ---- Writing -------------------------------------------------------------------------------

// Appends `bits`-wide integers, least significant bit first, as E57's bitpack codec does.
class BitWriter {
 public:
  explicit BitWriter(std::string* out) : out_(out) {}
  void Put(uint64_t value, int bits) {
    for (int done = 0; done < bits;) {
      const int take = std::min(bits - done, 64 - filled_);
      const uint64_t part = take == 64 ? value : (value >> done) & ((uint64_t{1} << take) - 1);
      word_ |= part << filled_;
      filled_ += take;
      done += take;
      if (filled_ == 64) Flush();
    }
  }
  // Writes what remains, padded with zeros to a whole register of `register_bytes`.
  void Finish(size_t register_bytes) {
    if (filled_ > 0) Flush();
    const size_t over = out_->size() % register_bytes;
    if (over != 0) out_->append(register_bytes - over, '\0');
  }

 private:
  void Flush() {
    for (int b = 0; b < filled_; b += 8) out_->push_back(static_cast<char>(word_ >> b));
    word_ = 0;
    filled_ = 0;
  }
  std::string* out_;
  uint64_t word_ = 0;
  int filled_ = 0;
};

// The register libE57Format packs a field of `bits` bits in, whose size its reader expects the
// stream to be padded to.
size_t RegisterBytes(int bits) { return bits <= 8 ? 1 : bits <= 16 ? 2 : bits <= 32 ? 4 : 8; }

struct WrittenField {
  std::string xml;     // The prototype's element.
  std::string stream;  // The whole bytestream.
  int bits_per_record;
};

// A 64-bit FNV-1a hash, for GUIDs derived from the contents.
uint64_t Fnv1a(absl::string_view data, uint64_t hash) {
  for (char c : data) hash = (hash ^ static_cast<uint8_t>(c)) * 0x100000001b3ull;
  return hash;
}

std::string Guid(absl::string_view data, uint64_t salt) {
  const uint64_t a = Fnv1a(data, 0xcbf29ce484222325ull ^ salt);
  const uint64_t b = Fnv1a(data, 0x84222325cbf29ce4ull ^ salt);
  return absl::StrFormat("{%08X-%04X-%04X-%04X-%012X}", a >> 32, (a >> 16) & 0xFFFF, a & 0xFFFF,
                         b >> 48, b & 0xFFFFFFFFFFFFull);
}

// The data packets of the section: as many records as fit per packet, a multiple of 64 so that
// every stream's share ends on a whole 8-byte register.
std::string FormatDataPackets(const std::vector<WrittenField>& fields, uint64_t records) {
  const size_t header = kDataPacketHeaderSize + 2 * fields.size();
  uint64_t bits_per_record = 0;
  for (const WrittenField& field : fields) bits_per_record += field.bits_per_record;
  const uint64_t per_packet =
      std::max<uint64_t>(
          1, (kMaxPacketSize - header - 3) / (8 * std::max<uint64_t>(1, bits_per_record))) *
      64;
  std::string packets;
  for (uint64_t first = 0; first < records; first += per_packet) {
    const bool last = first + per_packet >= records;
    std::string sizes, buffers;
    for (const WrittenField& field : fields) {
      const uint64_t begin = first * field.bits_per_record / 8;
      const uint64_t end =
          last ? field.stream.size() : (first + per_packet) * field.bits_per_record / 8;
      AppendLittleEndian(static_cast<uint16_t>(end - begin), &sizes);
      buffers.append(field.stream, begin, end - begin);
    }
    const size_t length = (header + buffers.size() + 3) / 4 * 4;
    packets.push_back(static_cast<char>(kDataPacket));
    packets.push_back('\0');  // Flags.
    AppendLittleEndian(static_cast<uint16_t>(length - 1), &packets);
    AppendLittleEndian(static_cast<uint16_t>(fields.size()), &packets);
    packets += sizes;
    packets += buffers;
    packets.append(length - header - buffers.size(), '\0');
  }
  return packets;
}

std::string Number(double value) { return absl::StrFormat("%.17g", value); }

}  // namespace

absl::StatusOr<ParsedGeometry> ParseE57(absl::string_view data, PositionPrecision precision) {
  if (data.size() < kFileHeaderSize || data.substr(0, kSignature.size()) != kSignature) {
    return Invalid("the file does not begin with the signature \"ASTM-E57\"");
  }
  const uint32_t major = LoadScalar<uint32_t>(data.data() + 8, false);
  const uint64_t physical_length = Load64(data, 16);
  const uint64_t xml_offset = Load64(data, 24);
  const uint64_t xml_length = Load64(data, 32);
  const uint64_t page_size = Load64(data, 40);
  if (major != 1) return Invalid(absl::StrCat("version ", major, " is not supported (only 1)"));
  if (page_size != kE57PageSize) {
    return Invalid(
        absl::StrCat("pages of ", page_size, " bytes are not supported (only ", kE57PageSize, ")"));
  }
  if (physical_length != data.size()) {
    return Invalid(absl::StrCat("the header says the file has ", physical_length,
                                " bytes, but it has ", data.size(), " (truncated?)"));
  }
  NM_ASSIGN_OR_RETURN(const E57LogicalView file, E57LogicalView::Open(data));
  const uint64_t xml_start = E57LogicalOffset(xml_offset);
  if (IsE57Checksum(xml_offset) || xml_start > file.size() ||
      xml_length > file.size() - xml_start) {
    return Invalid("the XML section's offset and length lie beyond the file");
  }
  std::string xml;
  file.Append(xml_start, xml_length, &xml);
  absl::StatusOr<XmlElement> parsed = ParseXml(xml);
  if (!parsed.ok()) {
    return Invalid(absl::StrCat("its XML is malformed: ", parsed.status().message()));
  }
  const XmlElement& root = *parsed;
  if (root.name != "e57Root") {
    return Invalid(absl::StrCat("the XML's root element is <", root.name, ">, not <e57Root>"));
  }
  const XmlElement* data3d = root.Child("data3D");
  if (data3d == nullptr) return Invalid("the XML has no data3D element");
  Gathered gathered(precision);
  int scans = 0;
  for (const XmlElement& scan_element : data3d->children) {
    const std::string scan = absl::StrCat("scan ", scans++);
    NM_RETURN_IF_ERROR(ReadScan(file, scan_element, scan, &gathered));
  }
  if (scans == 0) return Invalid("the file holds no 3D scans (data3D is empty)");
  if (gathered.positions.size() == 0 && gathered.left_out.invalid > 0) {
    return Invalid(absl::StrCat("all ", gathered.left_out.invalid,
                                " points are marked invalid (no position)"));
  }
  ParsedGeometry out;
  gathered.positions.MoveTo(&out);
  if (gathered.colored) out.colors = std::move(gathered.colors);
  if (gathered.with_normals) out.normals = std::move(gathered.normals);
  out.left_out = gathered.left_out;
  return out;
}

std::string FormatE57(const GeometryView& points) {
  const uint64_t count = points.positions.size();
  std::vector<WrittenField> fields;
  std::string prototype;
  std::string bounds;
  for (int c = 0; c < 3; ++c) {
    double farthest = 0;
    for (const Vec3f& p : points.positions) farthest = std::max<double>(farthest, std::fabs(p[c]));
    const double scale = IntegerScaleKeepingFloats(farthest);
    std::vector<int64_t> stored(count);
    int64_t low = 0, high = 0;
    for (uint64_t i = 0; i < count; ++i) {
      stored[i] = std::llround(points.positions[i][c] / scale);
      low = i == 0 ? stored[i] : std::min(low, stored[i]);
      high = i == 0 ? stored[i] : std::max(high, stored[i]);
    }
    WrittenField field;
    field.bits_per_record = BitsNeeded(low, high);
    BitWriter writer(&field.stream);
    for (int64_t s : stored) writer.Put(static_cast<uint64_t>(s - low), field.bits_per_record);
    writer.Finish(RegisterBytes(field.bits_per_record));
    const char axis = static_cast<char>('X' + c);
    field.xml = absl::StrFormat(
        "<cartesian%c type=\"ScaledInteger\" minimum=\"%d\" maximum=\"%d\" scale=\"%s\" "
        "offset=\"%s\"/>",
        axis, low, high, Number(scale), Number(points.origin[c]));
    fields.push_back(std::move(field));
    const char lower = static_cast<char>('x' + c);
    absl::StrAppendFormat(&bounds, "<%cMinimum type=\"Float\">%s</%cMinimum>", lower,
                          Number(low * scale + points.origin[c]), lower);
    absl::StrAppendFormat(&bounds, "<%cMaximum type=\"Float\">%s</%cMaximum>", lower,
                          Number(high * scale + points.origin[c]), lower);
  }
  std::string color_limits;
  if (!points.colors.empty()) {
    static constexpr const char* kChannel[] = {"Red", "Green", "Blue"};
    for (int c = 0; c < 3; ++c) {
      WrittenField field;
      field.bits_per_record = 8;
      for (const Rgb& color : points.colors) field.stream.push_back(static_cast<char>(color[c]));
      field.xml =
          absl::StrCat("<color", kChannel[c], " type=\"Integer\" minimum=\"0\" maximum=\"255\"/>");
      fields.push_back(std::move(field));
      absl::StrAppend(&color_limits, "<color", kChannel[c], "Minimum type=\"Integer\">0</color",
                      kChannel[c], "Minimum><color", kChannel[c],
                      "Maximum type=\"Integer\">255</color", kChannel[c], "Maximum>");
    }
  }
  if (!points.normals.empty()) {
    for (int c = 0; c < 3; ++c) {
      WrittenField field;
      field.bits_per_record = 32;
      for (const Vec3f& n : points.normals) AppendLittleEndian(n[c], &field.stream);
      field.xml = absl::StrFormat("<nor:normal%c type=\"Float\" precision=\"single\"/>",
                                  static_cast<char>('X' + c));
      fields.push_back(std::move(field));
    }
  }
  for (const WrittenField& field : fields) prototype += field.xml;

  // The logical layout: the file header, the points' section, the XML.
  std::string section(kSectionHeaderSize, '\0');
  section[0] = static_cast<char>(kCompressedVectorSection);
  section += FormatDataPackets(fields, count);
  const uint64_t section_start = kFileHeaderSize;
  const uint64_t section_length = section.size();
  std::string lengths;
  AppendLittleEndian(section_length, &lengths);
  AppendLittleEndian(E57PhysicalOffset(section_start + kSectionHeaderSize), &lengths);
  AppendLittleEndian(uint64_t{0}, &lengths);  // No index packets.
  section.replace(8, lengths.size(), lengths);

  const std::string file_guid = Guid(section, 1);
  std::string xml = absl::StrCat(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<e57Root type=\"Structure\" xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\"",
      points.normals.empty() ? "" : absl::StrCat(" xmlns:nor=\"", kNormalsNamespace, "\""), ">\n",
      "<formatName type=\"String\"><![CDATA[ASTM E57 3D Imaging Data File]]></formatName>\n",
      "<guid type=\"String\"><![CDATA[", file_guid, "]]></guid>\n",
      "<versionMajor type=\"Integer\">1</versionMajor>\n",
      "<versionMinor type=\"Integer\">0</versionMinor>\n",
      "<e57LibraryVersion type=\"String\"><![CDATA[neuralmesh ", EscapeXml(NeuralmeshVersion()),
      "]]></e57LibraryVersion>\n", "<data3D type=\"Vector\" allowHeterogeneousChildren=\"1\">\n",
      "<vectorChild type=\"Structure\">\n", "<guid type=\"String\"><![CDATA[", Guid(section, 2),
      "]]></guid>\n", "<name type=\"String\"><![CDATA[points]]></name>\n",
      "<cartesianBounds type=\"Structure\">", bounds, "</cartesianBounds>\n",
      color_limits.empty()
          ? ""
          : absl::StrCat("<colorLimits type=\"Structure\">", color_limits, "</colorLimits>\n"),
      "<points type=\"CompressedVector\" fileOffset=\"", E57PhysicalOffset(section_start),
      "\" recordCount=\"", count, "\">\n", "<prototype type=\"Structure\">", prototype,
      "</prototype>\n", "<codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"></codecs>\n",
      "</points>\n</vectorChild>\n</data3D>\n",
      "<images2D type=\"Vector\" allowHeterogeneousChildren=\"1\"></images2D>\n", "</e57Root>\n");

  const uint64_t xml_start = section_start + section.size();
  const uint64_t pages = (xml_start + xml.size() + kE57PageDataSize - 1) / kE57PageDataSize;
  std::string logical(kSignature);
  AppendLittleEndian(uint32_t{1}, &logical);  // Major version.
  AppendLittleEndian(uint32_t{0}, &logical);  // Minor version.
  AppendLittleEndian(pages * kE57PageSize, &logical);
  AppendLittleEndian(E57PhysicalOffset(xml_start), &logical);
  AppendLittleEndian(static_cast<uint64_t>(xml.size()), &logical);
  AppendLittleEndian(kE57PageSize, &logical);
  logical += section;
  logical += xml;
  return E57Pages(logical);
}

}  // namespace neuralmesh::io_internal
