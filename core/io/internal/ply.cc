#include "core/io/internal/ply.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/ply_header.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"
#include "core/rgb.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

// Face indices are stored as uint32_t; the largest index must fit, with one value to spare.
constexpr uint64_t kMaxVertices = std::numeric_limits<uint32_t>::max();

class BinaryBody {
 public:
  BinaryBody(absl::string_view data, size_t offset, bool big_endian)
      : data_(data), offset_(offset), big_endian_(big_endian) {}

  // Rejects a count that the remaining bytes cannot hold, before anything is allocated.
  absl::Status BeginElement(const PlyElement& element) {
    uint64_t min_size = 0;
    for (const PlyProperty& p : element.properties) {
      min_size += PlyTypeSize(p.is_list ? p.count_type : p.type);
    }
    const uint64_t remaining = data_.size() - offset_;
    if (min_size > 0 && element.count > remaining / min_size) {
      return absl::InvalidArgumentError(
          absl::StrCat("byte ", offset_, ": the header declares ", element.count, " '",
                       element.name, "' elements of at least ", min_size, " bytes each, but only ",
                       remaining, " bytes follow"));
    }
    return absl::OkStatus();
  }
  absl::Status BeginRecord(const PlyElement&, uint64_t) {
    record_start_ = offset_;
    return absl::OkStatus();
  }
  absl::Status EndRecord(const PlyElement&, uint64_t) { return absl::OkStatus(); }
  std::string Where() const { return absl::StrCat("byte ", record_start_); }

  absl::Status Read(PlyType type, const PlyElement& element, uint64_t index,
                    const PlyProperty& property, double* value) {
    const size_t size = PlyTypeSize(type);
    if (data_.size() - offset_ < size) {
      return absl::InvalidArgumentError(absl::StrCat("byte ", offset_, ": the data ends inside ",
                                                     element.name, " ", index, " (property '",
                                                     property.name, "'); the file is truncated"));
    }
    *value = LoadPlyValue(data_.data() + offset_, type, big_endian_);
    offset_ += size;
    return absl::OkStatus();
  }

 private:
  absl::string_view data_;
  size_t offset_;
  size_t record_start_ = 0;
  bool big_endian_;
};

// Reads values from an ASCII body: one element per line, blank lines skipped.
class AsciiBody {
 public:
  AsciiBody(absl::string_view data, size_t offset, int first_line)
      : cursor_(data.substr(offset)), first_line_(first_line) {}

  absl::Status BeginElement(const PlyElement& element) {
    // Each element with properties takes at least one character.
    if (!element.properties.empty() && element.count > cursor_.remaining()) {
      return LineError(Line(),
                       absl::StrCat("the header declares ", element.count, " '", element.name,
                                    "' elements but only ", cursor_.remaining(), " bytes follow"));
    }
    return absl::OkStatus();
  }

  absl::Status BeginRecord(const PlyElement& element, uint64_t index) {
    absl::string_view line;
    do {
      if (!cursor_.Next(&line)) {
        return LineError(
            Line(), absl::StrCat("the file ends after ", index, " of the ", element.count, " '",
                                 element.name, "' elements the header declares"));
      }
      SplitWhitespace(line, &tokens_);
    } while (tokens_.empty());
    next_ = 0;
    return absl::OkStatus();
  }

  absl::Status EndRecord(const PlyElement& element, uint64_t index) {
    if (next_ < tokens_.size()) {
      return LineError(Line(), absl::StrCat(element.name, " ", index, " has ", tokens_.size(),
                                            " values, more than its properties take"));
    }
    return absl::OkStatus();
  }

  std::string Where() const { return absl::StrCat("line ", Line()); }

  absl::Status Read(PlyType type, const PlyElement& element, uint64_t index,
                    const PlyProperty& property, double* value) {
    if (next_ >= tokens_.size()) {
      return LineError(Line(),
                       absl::StrCat(element.name, " ", index, " has too few values: property '",
                                    property.name, "' is missing"));
    }
    const absl::string_view token = tokens_[next_++];
    if (!ParseDouble(token, value)) {
      return LineError(Line(),
                       absl::StrCat("expected a number for property '", property.name, "' of ",
                                    element.name, " ", index, ", found ", Quoted(token)));
    }
    if (IsIntegralPlyType(type)) {
      const auto [lo, hi] = IntegralPlyRange(type);
      if (!(*value >= lo && *value <= hi) || std::floor(*value) != *value) {
        return LineError(Line(), absl::StrCat("expected an integer in [", lo, ", ", hi,
                                              "] for property '", property.name, "' of ",
                                              element.name, " ", index, ", found ", Quoted(token)));
      }
    }
    return absl::OkStatus();
  }

 private:
  int Line() const { return first_line_ - 1 + std::max(cursor_.line_number(), 1); }

  LineCursor cursor_;
  int first_line_;
  std::vector<absl::string_view> tokens_;
  size_t next_ = 0;
};

// Reads a list length; binary signed types can hold negative values.
template <typename Body>
absl::Status ReadListCount(Body& body, const PlyElement& element, uint64_t index,
                           const PlyProperty& property, uint64_t* count) {
  double value = 0;
  NM_RETURN_IF_ERROR(body.Read(property.count_type, element, index, property, &value));
  if (value < 0) {
    return absl::InvalidArgumentError(absl::StrCat(body.Where(), ": list '", property.name, "' of ",
                                                   element.name, " ", index,
                                                   " has negative length ", value));
  }
  *count = static_cast<uint64_t>(value);
  return absl::OkStatus();
}

template <typename Body>
absl::Status SkipProperty(Body& body, const PlyElement& element, uint64_t index,
                          const PlyProperty& property) {
  double ignored = 0;
  if (!property.is_list) return body.Read(property.type, element, index, property, &ignored);
  uint64_t count = 0;
  NM_RETURN_IF_ERROR(ReadListCount(body, element, index, property, &count));
  // Each read consumes data or fails, so a bogus count stops at the end of the data.
  for (uint64_t k = 0; k < count; ++k) {
    NM_RETURN_IF_ERROR(body.Read(property.type, element, index, property, &ignored));
  }
  return absl::OkStatus();
}

template <typename Body>
absl::Status SkipElement(Body& body, const PlyElement& element) {
  if (element.properties.empty()) return absl::OkStatus();
  for (uint64_t i = 0; i < element.count; ++i) {
    NM_RETURN_IF_ERROR(body.BeginRecord(element, i));
    for (const PlyProperty& property : element.properties) {
      NM_RETURN_IF_ERROR(SkipProperty(body, element, i, property));
    }
    NM_RETURN_IF_ERROR(body.EndRecord(element, i));
  }
  return absl::OkStatus();
}

enum Role { kOther, kX, kY, kZ, kNx, kNy, kNz, kWeight, kRed, kGreen, kBlue, kNumRoles };

// The names colour channels go by: red, green, blue in most files, r, g, b and diffuse_red,
// ... in some.
constexpr const char* kChannelNames[][3] = {
    {"red", "green", "blue"}, {"r", "g", "b"}, {"diffuse_red", "diffuse_green", "diffuse_blue"}};

// Assigns a role to each vertex property; fails when x, y or z is missing.
absl::StatusOr<std::vector<Role>> VertexRoles(const PlyElement& element, bool* has_normals,
                                              bool* has_weights, bool* has_colors) {
  std::vector<Role> roles(element.properties.size(), kOther);
  auto find = [&](absl::string_view name) -> int {
    for (size_t i = 0; i < element.properties.size(); ++i) {
      const PlyProperty& p = element.properties[i];
      if (!p.is_list && roles[i] == kOther && absl::EqualsIgnoreCase(p.name, name)) {
        return static_cast<int>(i);
      }
    }
    return -1;
  };
  const char* axes[3] = {"x", "y", "z"};
  for (int c = 0; c < 3; ++c) {
    const int i = find(axes[c]);
    if (i < 0) {
      return LineError(element.line,
                       absl::StrCat("element 'vertex' has no scalar property '", axes[c], "'"));
    }
    roles[i] = static_cast<Role>(kX + c);
  }
  const int nx = find("nx"), ny = find("ny"), nz = find("nz");
  *has_normals = nx >= 0 && ny >= 0 && nz >= 0;
  if (*has_normals) {
    roles[nx] = kNx;
    roles[ny] = kNy;
    roles[nz] = kNz;
  }
  *has_weights = false;
  for (const char* name : {"confidence", "weight", "quality", "intensity", "scalar"}) {
    const int i = find(name);
    if (i >= 0) {
      roles[i] = kWeight;
      *has_weights = true;
      break;
    }
  }
  *has_colors = false;
  for (const auto& names : kChannelNames) {
    const int r = find(names[0]), g = find(names[1]), b = find(names[2]);
    if (r >= 0 && g >= 0 && b >= 0) {
      roles[r] = kRed;
      roles[g] = kGreen;
      roles[b] = kBlue;
      *has_colors = true;
      break;
    }
  }
  return roles;
}

// The full scale of a colour channel of `type`: integers are levels of their type (uchar
// 0-255, ushort 0-65535, ...), floating-point values fractions from 0 to 1.
double ChannelScale(PlyType type) {
  return IsIntegralPlyType(type) ? IntegralPlyRange(type).second : 1.0;
}

}  // namespace

absl::StatusOr<PlyVertexLayout> FindPlyVertexLayout(const PlyElement& vertex) {
  bool has_normals = false, has_weights = false, has_colors = false;
  PlyVertexLayout layout;
  NM_ASSIGN_OR_RETURN(const std::vector<Role> roles,
                      VertexRoles(vertex, &has_normals, &has_weights, &has_colors));
  for (size_t i = 0; i < roles.size(); ++i) {
    if (roles[i] >= kX && roles[i] <= kZ) layout.axes[roles[i] - kX] = static_cast<int>(i);
    if (roles[i] >= kRed && roles[i] <= kBlue) {
      layout.channels[roles[i] - kRed] = static_cast<int>(i);
      layout.channel_scales[roles[i] - kRed] = ChannelScale(vertex.properties[i].type);
    }
  }
  return layout;
}

namespace {

template <typename Body>
absl::Status ReadVertices(Body& body, const PlyElement& element, PositionPrecision precision,
                          ParsedGeometry* out) {
  if (element.count > kMaxVertices) {
    return LineError(element.line,
                     absl::StrCat("the header declares ", element.count, " vertices; at most ",
                                  kMaxVertices, " are supported"));
  }
  bool has_normals = false, has_weights = false, has_colors = false;
  NM_ASSIGN_OR_RETURN(std::vector<Role> roles,
                      VertexRoles(element, &has_normals, &has_weights, &has_colors));
  double channel_max[3] = {1, 1, 1};
  for (size_t k = 0; k < roles.size(); ++k) {
    if (roles[k] >= kRed && roles[k] <= kBlue) {
      channel_max[roles[k] - kRed] = ChannelScale(element.properties[k].type);
    }
  }
  // BeginElement has bounded the count by the remaining bytes.
  PositionCollector positions(precision);
  positions.Reserve(element.count);
  if (has_normals) out->normals.reserve(element.count);
  if (has_weights) out->weights.reserve(element.count);
  if (has_colors) out->colors.reserve(element.count);
  double values[kNumRoles] = {};
  for (uint64_t i = 0; i < element.count; ++i) {
    NM_RETURN_IF_ERROR(body.BeginRecord(element, i));
    for (size_t k = 0; k < element.properties.size(); ++k) {
      const PlyProperty& property = element.properties[k];
      if (roles[k] == kOther) {
        NM_RETURN_IF_ERROR(SkipProperty(body, element, i, property));
      } else {
        NM_RETURN_IF_ERROR(body.Read(property.type, element, i, property, &values[roles[k]]));
      }
    }
    NM_RETURN_IF_ERROR(body.EndRecord(element, i));
    const Vec3f p(NarrowToFloat(values[kX]), NarrowToFloat(values[kY]), NarrowToFloat(values[kZ]));
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return absl::InvalidArgumentError(absl::StrCat(body.Where(), ": vertex ", i,
                                                     " has a non-finite coordinate (", values[kX],
                                                     ", ", values[kY], ", ", values[kZ], ")"));
    }
    positions.Add({values[kX], values[kY], values[kZ]});
    if (has_normals) {
      const Vec3f n(NarrowToFloat(values[kNx]), NarrowToFloat(values[kNy]),
                    NarrowToFloat(values[kNz]));
      if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2])) {
        return absl::InvalidArgumentError(
            absl::StrCat(body.Where(), ": vertex ", i, " has a non-finite normal"));
      }
      out->normals.push_back(n);
    }
    if (has_weights) {
      const float w = NarrowToFloat(values[kWeight]);
      if (!std::isfinite(w)) {
        return absl::InvalidArgumentError(
            absl::StrCat(body.Where(), ": vertex ", i, " has a non-finite weight"));
      }
      out->weights.push_back(w);
    }
    if (has_colors) {
      out->colors.push_back({ChannelFromLevel(values[kRed], channel_max[0]),
                             ChannelFromLevel(values[kGreen], channel_max[1]),
                             ChannelFromLevel(values[kBlue], channel_max[2])});
    }
  }
  positions.MoveTo(out);
  return absl::OkStatus();
}

// `num_vertices` is 0 when the vertex element has not been read yet (it is checked later).
template <typename Body>
absl::Status ReadFaces(Body& body, const PlyElement& element, size_t num_vertices,
                       ParsedGeometry* out) {
  int indices = -1;
  for (size_t k = 0; k < element.properties.size(); ++k) {
    const PlyProperty& p = element.properties[k];
    if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
      indices = static_cast<int>(k);
      break;
    }
  }
  if (indices < 0) {
    return LineError(element.line,
                     "element 'face' has no 'vertex_indices' (or 'vertex_index') list property");
  }
  out->faces.reserve(element.count);
  std::vector<uint32_t> polygon;
  for (uint64_t i = 0; i < element.count; ++i) {
    NM_RETURN_IF_ERROR(body.BeginRecord(element, i));
    for (size_t k = 0; k < element.properties.size(); ++k) {
      const PlyProperty& property = element.properties[k];
      if (static_cast<int>(k) != indices) {
        NM_RETURN_IF_ERROR(SkipProperty(body, element, i, property));
        continue;
      }
      uint64_t count = 0;
      NM_RETURN_IF_ERROR(ReadListCount(body, element, i, property, &count));
      if (count < 3) {
        return absl::InvalidArgumentError(absl::StrCat(body.Where(), ": face ", i, " has ", count,
                                                       " vertices; a face needs at least 3"));
      }
      polygon.clear();
      for (uint64_t c = 0; c < count; ++c) {
        double value = 0;
        NM_RETURN_IF_ERROR(body.Read(property.type, element, i, property, &value));
        if (!(value >= 0) || std::floor(value) != value ||
            (num_vertices > 0 && value >= static_cast<double>(num_vertices)) ||
            value >= static_cast<double>(kMaxVertices)) {
          return absl::InvalidArgumentError(absl::StrCat(
              body.Where(), ": face ", i, " uses vertex index ", value,
              num_vertices > 0 ? absl::StrCat("; the file has ", num_vertices, " vertices")
                               : std::string(" which is not a valid index")));
        }
        polygon.push_back(static_cast<uint32_t>(value));
      }
      for (size_t c = 1; c + 1 < polygon.size(); ++c) {
        out->faces.push_back({polygon[0], polygon[c], polygon[c + 1]});
      }
    }
    NM_RETURN_IF_ERROR(body.EndRecord(element, i));
  }
  return absl::OkStatus();
}

template <typename Body>
absl::StatusOr<ParsedGeometry> ReadBody(const PlyHeader& header, Body& body, FaceHandling faces,
                                        PositionPrecision precision) {
  ParsedGeometry out;
  bool have_vertices = false;
  bool faces_before_vertices = false;
  for (const PlyElement& element : header.elements) {
    NM_RETURN_IF_ERROR(body.BeginElement(element));
    if (element.name == "vertex") {
      if (have_vertices) return LineError(element.line, "a second 'vertex' element");
      NM_RETURN_IF_ERROR(ReadVertices(body, element, precision, &out));
      have_vertices = true;
    } else if (element.name == "face" && faces == FaceHandling::kRead) {
      // Indices read before the vertex count was known are checked at the end, whatever
      // face elements follow.
      faces_before_vertices |= !have_vertices;
      NM_RETURN_IF_ERROR(ReadFaces(body, element, out.positions.size(), &out));
    } else {
      NM_RETURN_IF_ERROR(SkipElement(body, element));
    }
  }
  if (!have_vertices) return absl::InvalidArgumentError("the PLY header has no 'vertex' element");
  if (faces_before_vertices || out.positions.empty()) {
    for (size_t f = 0; f < out.faces.size(); ++f) {
      for (uint32_t v : out.faces[f]) {
        if (v >= out.positions.size()) {
          return absl::InvalidArgumentError(absl::StrCat("triangle ", f, " uses vertex ", v,
                                                         "; the file has ", out.positions.size(),
                                                         " vertices"));
        }
      }
    }
  }
  return out;
}

}  // namespace

absl::StatusOr<ParsedGeometry> ParsePly(absl::string_view data, FaceHandling faces,
                                        PositionPrecision precision) {
  NM_ASSIGN_OR_RETURN(const PlyHeader header, ParsePlyHeader(data));
  if (header.format == PlyFormat::kAscii) {
    AsciiBody body(data, header.body_offset, header.body_line);
    return ReadBody(header, body, faces, precision);
  }
  BinaryBody body(data, header.body_offset, header.format == PlyFormat::kBinaryBigEndian);
  return ReadBody(header, body, faces, precision);
}

std::string FormatPly(const GeometryView& geometry) {
  const bool normals = !geometry.normals.empty();
  const bool weights = !geometry.weights.empty();
  const bool colors = !geometry.colors.empty();
  std::string out = absl::StrCat(
      "ply\nformat binary_little_endian 1.0\ncomment written by neuralmesh\nelement vertex ",
      geometry.positions.size(), "\n");
  // Relative to an origin, the coordinates are written whole, as doubles.
  const bool doubles = geometry.has_origin();
  out += doubles ? "property double x\nproperty double y\nproperty double z\n"
                 : "property float x\nproperty float y\nproperty float z\n";
  if (normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (weights) out += "property float confidence\n";
  if (colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (!geometry.faces.empty()) {
    absl::StrAppend(&out, "element face ", geometry.faces.size(),
                    "\nproperty list uchar uint vertex_indices\n");
  }
  out += "end_header\n";
  const size_t vertex_size =
      (doubles ? 24 : 12) + 4 * ((normals ? 3 : 0) + (weights ? 1 : 0)) + (colors ? 3 : 0);
  out.reserve(out.size() + geometry.positions.size() * vertex_size + geometry.faces.size() * 13);
  for (size_t i = 0; i < geometry.positions.size(); ++i) {
    AppendPosition(geometry, i, &out);
    if (normals) {
      for (int c = 0; c < 3; ++c) AppendLittleEndian(geometry.normals[i][c], &out);
    }
    if (weights) AppendLittleEndian(geometry.weights[i], &out);
    if (colors) out.append(reinterpret_cast<const char*>(geometry.colors[i].data()), 3);
  }
  for (const auto& face : geometry.faces) {
    out.push_back(3);
    for (uint32_t v : face) AppendLittleEndian(v, &out);
  }
  return out;
}

}  // namespace neuralmesh::io_internal
