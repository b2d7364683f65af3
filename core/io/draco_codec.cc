#include "core/io/draco_codec.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/status_macros.h"
#include "draco/attributes/geometry_attribute.h"
#include "draco/attributes/point_attribute.h"
#include "draco/compression/config/compression_shared.h"
#include "draco/compression/decode.h"
#include "draco/compression/expert_encode.h"
#include "draco/core/decoder_buffer.h"
#include "draco/core/draco_types.h"
#include "draco/core/encoder_buffer.h"
#include "draco/core/options.h"
#include "draco/core/varint_decoding.h"
#include "draco/mesh/mesh.h"
#include "draco/metadata/geometry_metadata.h"
#include "draco/metadata/metadata_decoder.h"
#include "draco/point_cloud/point_cloud.h"

namespace neuralmesh {
namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f must be three packed floats");

absl::Status CheckRange(const char* field, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    return absl::InvalidArgumentError(absl::StrCat("DracoOptions.", field, " is ", value,
                                                   "; it must be in [", lo, ", ", hi, "]"));
  }
  return absl::OkStatus();
}

bool IsFinite(const Vec3f& p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// The grid Draco quantizes a `components`-component attribute against: per component from
// origin[c], cells of range / (2^bits - 1). Without a fixed box Draco takes the values' minima
// and the largest side of their bounding box (1 when they all coincide).
struct DracoGrid {
  float origin[3] = {0, 0, 0};
  float range = 1;
};

DracoGrid GridOfValues(const float* values, size_t count, int components) {
  DracoGrid grid;
  grid.range = 0;
  for (int c = 0; c < components; ++c) {
    float lo = values[c], hi = values[c];
    for (size_t i = 1; i < count; ++i) {
      lo = std::min(lo, values[i * components + c]);
      hi = std::max(hi, values[i * components + c]);
    }
    grid.origin[c] = lo;
    grid.range = std::max(grid.range, hi - lo);
  }
  if (grid.range == 0) grid.range = 1;
  return grid;
}

// The value nearest to x, at or above it when `up`, else at or below, that Draco reads back
// exactly (BoxAsDracoReadsIt). Below 2^23 * 1e-6 floats are finer than six decimals, so the
// candidates are whole millionths; above, floats are coarser and most read back unchanged.
// (Should none of the first candidates qualify, the last is returned: it lies on the asked
// side, and the encoders check boxes as Draco reads them anyway.)
float ValueDracoKeeps(double x, bool up) {
  // Draco reads an origin back as a vector and an edge as a float, through different parsers:
  // a candidate must come back from both.
  auto kept_on_side = [x, up](float candidate) {
    const QuantizationBox read =
        BoxAsDracoReadsIt(QuantizationBox{Vec3f(candidate, candidate, candidate), candidate});
    return (up ? candidate >= x : candidate <= x) && read.origin[0] == candidate &&
           read.range == candidate;
  };
  if (!std::isfinite(x) || kept_on_side(static_cast<float>(x))) return static_cast<float>(x);
  const double direction = up ? 1 : -1;
  const float toward =
      up ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
  double millionths = up ? std::ceil(x * 1e6) : std::floor(x * 1e6);
  float candidate = static_cast<float>(millionths * 1e-6);
  for (int tries = 0; tries < 64; ++tries) {
    if (kept_on_side(candidate)) return candidate;
    millionths += direction;
    const float next_millionth = static_cast<float>(millionths * 1e-6);
    const float next_float = std::nextafter(candidate, toward);
    candidate = up ? std::max(next_millionth, next_float) : std::min(next_millionth, next_float);
  }
  return candidate;
}

// Draco multiplies by the float (2^bits - 1) / range and later decodes q * range / (2^bits - 1)
// + origin, without checks. When the first overflows (a range below about 2^bits / 3.4e38: 6e-36
// at 11 bits) its encoder crashes or quantizes everything to garbage, and when the second does
// (a grid reaching to the largest float) the data decodes to infinities. Returns what is
// wrong with `grid`, or "" when Draco can quantize against it.
std::string GridProblem(const DracoGrid& grid, int components, int bits) {
  const float max_index = static_cast<float>(std::ldexp(1.0, bits) - 1.0);
  if (!std::isfinite(grid.range)) return "more than a float can hold";
  if (!(grid.range > 0) || !std::isfinite(max_index / grid.range)) {
    return absl::StrCat(grid.range, ", too little for ", bits, "-bit quantization (at least ",
                        max_index / std::numeric_limits<float>::max(), ")");
  }
  // q * range / (2^bits - 1) and the far corner, with room for rounding in float.
  const double far_margin = 1 + 1e-5;
  const double largest = std::numeric_limits<float>::max();
  for (int c = 0; c < components; ++c) {
    if (double{grid.range} * far_margin > largest ||
        double{grid.origin[c]} + double{grid.range} * far_margin > largest) {
      return absl::StrCat(grid.range, " from ", grid.origin[c],
                          ", reaching past the largest float");
    }
  }
  return "";
}

// GridProblem of a quantization box (as Draco reads it).
std::string BoxProblem(const QuantizationBox& box, int bits) {
  DracoGrid grid;
  for (int c = 0; c < 3; ++c) grid.origin[c] = box.origin[c];
  grid.range = box.range;
  return GridProblem(grid, 3, bits);
}

// Checks that every position is finite, that Draco can quantize them (GridProblem) and, with a
// fixed box, that each quantizes to a grid index inside [0, 2^bits - 1] of the box as Draco
// reads it. A quarter step of slack lets callers use a box computed in float arithmetic whose
// far corner rounded just below the farthest point.
absl::Status CheckPositions(const std::vector<Vec3f>& positions, const DracoOptions& options) {
  for (size_t i = 0; i < positions.size(); ++i) {
    if (!IsFinite(positions[i])) {
      return absl::InvalidArgumentError(absl::StrCat("vertex ", i, " has a non-finite coordinate"));
    }
  }
  const int bits = options.position_quantization_bits;
  if (!options.quantization_box.has_value()) {
    const std::string problem =
        GridProblem(GridOfValues(positions.front().data(), positions.size(), 3), 3, bits);
    if (problem.empty()) return absl::OkStatus();
    return absl::InvalidArgumentError(absl::StrCat(
        "cannot quantize the positions with Draco: their bounding box spans ", problem));
  }
  const QuantizationBox& given = *options.quantization_box;
  const QuantizationBox box = BoxAsDracoReadsIt(given);
  const auto describe = [&given, &box] {
    std::string text =
        absl::StrCat("the quantization box with origin (", given.origin[0], ", ", given.origin[1],
                     ", ", given.origin[2], ") and range ", given.range);
    if (box.origin != given.origin || box.range != given.range) {
      absl::StrAppend(&text, ", which Draco reads (with six decimals) as origin (", box.origin[0],
                      ", ", box.origin[1], ", ", box.origin[2], ") and range ", box.range,
                      " (DracoExactBox gives a box it keeps exactly)");
    }
    return text;
  };
  const std::string problem = BoxProblem(box, bits);
  if (!problem.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot quantize against ", describe(), ": its range is ", problem));
  }
  const double max_index = std::ldexp(1.0, bits) - 1.0;
  const double cells_per_unit = max_index / box.range;
  for (size_t i = 0; i < positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double t = (double{positions[i][c]} - double{box.origin[c]}) * cells_per_unit;
      if (t < -0.25 || t > max_index + 0.25) {
        return absl::InvalidArgumentError(absl::StrCat("vertex ", i, " (", positions[i][0], ", ",
                                                       positions[i][1], ", ", positions[i][2],
                                                       ") lies outside ", describe()));
      }
    }
  }
  return absl::OkStatus();
}

// Draco codes a normal as a direction (octahedral), normalising it in float: one of length
// 1e38 or more overflowed to infinity there and decoded to NaN (found by
// fuzz/draco_encoder_fuzzer.cc). So the directions are taken here, in double; zero normals
// stay zero.
std::vector<Vec3f> UnitNormals(const std::vector<Vec3f>& normals) {
  std::vector<Vec3f> unit(normals.size());
  for (size_t i = 0; i < normals.size(); ++i) {
    const Vec3 n(normals[i][0], normals[i][1], normals[i][2]);
    const double length = n.norm();
    unit[i] = length > 0 ? Vec3f(n / length) : normals[i];
  }
  return unit;
}

// Adds a per-point float attribute with identity mapping and copies `count` values into it.
int AddFloatAttribute(draco::PointCloud& geometry, draco::GeometryAttribute::Type type,
                      int components, const float* values, size_t count) {
  draco::GeometryAttribute layout;
  layout.Init(type, nullptr, static_cast<uint8_t>(components), draco::DT_FLOAT32,
              /*normalized=*/false, sizeof(float) * components, /*byte_offset=*/0);
  const int id =
      geometry.AddAttribute(layout, /*identity_mapping=*/true, static_cast<uint32_t>(count));
  geometry.attribute(id)->buffer()->Write(0, values, count * components * sizeof(float));
  return id;
}

// How a COLOR attribute stores the sRGB channels of Rgb: as they are, in bytes, or as linear
// light in 16-bit integers (glTF).
enum class ColorStorage { kSrgbBytes, kLinearShorts };

// Adds a per-point COLOR attribute of three normalized integers (Draco codes integers
// losslessly, without quantization).
void AddColorAttribute(draco::PointCloud& geometry, const std::vector<Rgb>& colors,
                       ColorStorage storage = ColorStorage::kSrgbBytes) {
  const bool linear = storage == ColorStorage::kLinearShorts;
  draco::GeometryAttribute layout;
  layout.Init(draco::GeometryAttribute::COLOR, nullptr, 3,
              linear ? draco::DT_UINT16 : draco::DT_UINT8, /*normalized=*/true,
              linear ? 3 * sizeof(uint16_t) : sizeof(Rgb), /*byte_offset=*/0);
  const int id = geometry.AddAttribute(layout, /*identity_mapping=*/true,
                                       static_cast<uint32_t>(colors.size()));
  if (!linear) {
    geometry.attribute(id)->buffer()->Write(0, colors.data(), colors.size() * sizeof(Rgb));
    return;
  }
  std::vector<std::array<uint16_t, 3>> shorts(colors.size());
  for (size_t i = 0; i < colors.size(); ++i) {
    for (int c = 0; c < 3; ++c) shorts[i][c] = LinearShortFromSrgb(colors[i][c]);
  }
  geometry.attribute(id)->buffer()->Write(0, shorts.data(), shorts.size() * sizeof(shorts[0]));
}

absl::Status CheckColorCount(size_t colors, size_t points, const char* what) {
  if (colors == 0 || colors == points) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("there are ", colors, " colours for ", points, " ", what));
}

void SetPositionQuantization(draco::ExpertEncoder& encoder, int attribute_id,
                             const DracoOptions& options) {
  if (options.quantization_box.has_value()) {
    const QuantizationBox& box = *options.quantization_box;
    const float origin[3] = {box.origin[0], box.origin[1], box.origin[2]};
    encoder.SetAttributeExplicitQuantization(attribute_id, options.position_quantization_bits, 3,
                                             origin, box.range);
  } else {
    encoder.SetAttributeQuantization(attribute_id, options.position_quantization_bits);
  }
}

// The metadata entry that holds where the positions' (0, 0, 0) lies (TriangleMesh::origin,
// PointCloud::origin): three doubles, written only when the origin is not zero.
constexpr char kOriginEntry[] = "origin";

void AddOrigin(draco::PointCloud& geometry, const Origin& origin) {
  if (origin == kNoOrigin) return;
  auto metadata = std::make_unique<draco::GeometryMetadata>();
  metadata->AddEntryDoubleArray(kOriginEntry, {origin[0], origin[1], origin[2]});
  geometry.AddMetadata(std::move(metadata));
}

// The origin a stream's metadata gives, or zero.
absl::StatusOr<Origin> ReadOrigin(const draco::PointCloud& geometry) {
  Origin origin = kNoOrigin;
  const draco::GeometryMetadata* metadata = geometry.GetMetadata();
  std::vector<double> values;
  if (metadata == nullptr || !metadata->GetEntryDoubleArray(kOriginEntry, &values)) {
    return origin;
  }
  if (values.size() != 3 || !std::all_of(values.begin(), values.end(),
                                         [](double v) { return std::isfinite(v); })) {
    return absl::InvalidArgumentError(
        "the Draco metadata's 'origin' is not three finite numbers");
  }
  std::copy(values.begin(), values.end(), origin.begin());
  return origin;
}

absl::StatusOr<std::string> RunEncoder(draco::ExpertEncoder& encoder, const char* what) {
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeToBuffer(&buffer);
  if (!status.ok()) {
    return absl::InternalError(
        absl::StrCat("Draco failed to encode the ", what, ": ", status.error_msg_string()));
  }
  return std::string(buffer.data(), buffer.size());
}

// Draco spends about 70 bytes on a mesh whatever its size: the header, the Edgebreaker and
// attribute headers, the 17-byte quantization box, the entropy coders' tables and the 8 bytes
// of bounds of the prediction transform. Below this many vertices that overhead dominates, and
// which settings give the shortest stream varies from mesh to mesh. Measured on 80 learned
// meshes (tori and spheres, 11 bits, session-style boxes): speed 0 or 10 (another predictor
// and entropy-coder precision) at 10-30 vertices, and the given settings at every mesh from 40
// vertices on. A mesh this small encodes in about 0.1 ms, so every variant is tried and the
// shortest stream kept. Turning position prediction off saved up to 10 more bytes at 10
// vertices, but Draco 1.5.5's encoder crashes without prediction on some meshes with a fixed
// quantization box of small range (a fuzzer found 4 vertices in a box of edge 3e-29; a box of
// 3e-7 still crashes it), so that variant is not tried. Draco's
// sequential connectivity coder is not among them: it was never shorter (28% longer at 10
// vertices, twice as long at 50, 2.7 times at 200), and it would keep what Edgebreaker drops
// (see draco_codec.h).
constexpr size_t kSmallMeshVertices = 64;

// Draco's speed settings for one encoding of a mesh.
struct MeshEncoding {
  int encode_speed;
  int decode_speed;
  bool operator==(const MeshEncoding& o) const {
    return encode_speed == o.encode_speed && decode_speed == o.decode_speed;
  }
};

absl::StatusOr<std::string> EncodeMeshAs(const draco::Mesh& geometry, int position_id,
                                         const DracoOptions& options,
                                         const MeshEncoding& encoding) {
  draco::ExpertEncoder encoder(geometry);
  encoder.SetSpeedOptions(encoding.encode_speed, encoding.decode_speed);
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  SetPositionQuantization(encoder, position_id, options);
  return RunEncoder(encoder, "mesh");
}

// Draco sizes its arrays from the counts at the start of a stream without comparing them with
// the data that follows, so a few corrupt bytes can demand gigabytes (one 120-byte point cloud
// made Draco 1.5.5 fill 8 GB before giving up; a 140-byte Edgebreaker mesh asked for 3.5 GB).
// The counts cannot be bounded tightly either: kd-tree and entropy coding store a million
// identical points in under 200 bytes. So any count up to kAlwaysAllowedElements passes, and
// larger ones need a byte per kMaxElementsPerByte points, vertices or faces.
constexpr uint64_t kAlwaysAllowedElements = uint64_t{1} << 20;
constexpr uint64_t kMaxElementsPerByte = 256;

// Reads one count as mesh streams of the versions CheckStreamStart accepts (2.2 and later)
// store it: a varint.
bool DecodeCount(draco::DecoderBuffer& buffer, uint64_t* count) {
  uint32_t value = 0;
  const bool ok = draco::DecodeVarint(&value, &buffer);
  *count = value;
  return ok;
}

// The fields that open every Draco stream. ReadStreamStart leaves `buffer` after them and after
// the metadata, when there is some, or returns nullopt when the stream ends or is malformed
// before (Draco then reports it itself).
struct StreamStart {
  uint16_t version;
  uint8_t type;
  uint8_t method;
};

std::optional<StreamStart> ReadStreamStart(std::string_view bytes, draco::DecoderBuffer& buffer) {
  buffer.Init(bytes.data(), bytes.size());
  char magic[5];
  uint8_t major = 0, minor = 0;
  StreamStart start{};
  uint16_t flags = 0;
  if (!buffer.Decode(magic, sizeof(magic)) || !buffer.Decode(&major) || !buffer.Decode(&minor) ||
      !buffer.Decode(&start.type) || !buffer.Decode(&start.method) || !buffer.Decode(&flags)) {
    return std::nullopt;
  }
  start.version = DRACO_BITSTREAM_VERSION(major, minor);
  buffer.set_bitstream_version(start.version);
  if (start.version >= DRACO_BITSTREAM_VERSION(1, 3) && (flags & METADATA_FLAG_MASK) != 0) {
    draco::GeometryMetadata metadata;
    draco::MetadataDecoder metadata_decoder;
    if (!metadata_decoder.DecodeGeometryMetadata(&buffer, &metadata)) return std::nullopt;
  }
  return start;
}

// The point count of a point cloud stream, or the vertex and face counts of a mesh stream,
// where Draco reads them (its decoders' DecodeConnectivity); `buffer` as ReadStreamStart left
// it, for a stream of a version CheckStreamStart accepts.
std::vector<std::pair<const char*, uint64_t>> DeclaredCounts(const StreamStart& start,
                                                             draco::DecoderBuffer& buffer) {
  if (start.type == draco::POINT_CLOUD) {
    int32_t stored = 0;
    if (!buffer.Decode(&stored)) return {};
    return {{"points", static_cast<uint32_t>(stored)}};  // Read as unsigned by the decoders.
  }
  if (start.type != draco::TRIANGULAR_MESH) return {};
  uint64_t vertices = 0, faces = 0;
  if (start.method == draco::MESH_SEQUENTIAL_ENCODING) {
    if (!DecodeCount(buffer, &faces) || !DecodeCount(buffer, &vertices)) return {};
  } else if (start.method == draco::MESH_EDGEBREAKER_ENCODING) {
    uint8_t traversal = 0;
    if (!buffer.Decode(&traversal)) return {};
    if (!DecodeCount(buffer, &vertices) || !DecodeCount(buffer, &faces)) return {};
  } else {
    return {};
  }
  return {{"vertices", vertices}, {"faces", faces}};
}

// Rejects what Draco would decode without bounds: streams older than the bitstream versions
// current encoders write (2.2 for meshes, 2.3 for point clouds; Draco 1.5 decodes the older
// ones through legacy paths with counts of their own that it never checks: a 102-byte kd-tree
// point cloud of version 2.1 made it fill 21 GB), and counts far beyond what the stream's size
// can hold; then, with RESOURCE_EXHAUSTED, points or vertices beyond `max_points` and faces
// beyond twice that.
absl::Status CheckStreamStart(std::string_view bytes, uint64_t max_points) {
  draco::DecoderBuffer buffer;
  const std::optional<StreamStart> start = ReadStreamStart(bytes, buffer);
  if (!start.has_value()) return absl::OkStatus();
  const uint16_t oldest = start->type == draco::POINT_CLOUD
                              ? draco::kDracoPointCloudBitstreamVersion
                              : draco::kDracoMeshBitstreamVersion;
  if (start->version < oldest) {
    return absl::InvalidArgumentError(absl::StrCat(
        "Draco bitstream version ", start->version >> 8, ".", start->version & 0xff,
        " is not supported (at least ", oldest >> 8, ".", oldest & 0xff,
        ", what current Draco encoders write): encode the data again with a current Draco"));
  }
  const uint64_t limit =
      std::max<uint64_t>(kAlwaysAllowedElements, kMaxElementsPerByte * bytes.size());
  for (const auto& [what, count] : DeclaredCounts(*start, buffer)) {
    // The caller's limit first: data it refuses need not be judged corrupt.
    constexpr uint64_t kUnlimited = std::numeric_limits<uint64_t>::max();
    const bool faces = std::string_view(what) == "faces";
    const uint64_t allowed =
        faces ? (max_points > kUnlimited / 2 ? kUnlimited : 2 * max_points) : max_points;
    if (count > allowed) {
      return absl::ResourceExhaustedError(absl::StrCat("the Draco data declares ", count, " ", what,
                                                       "; at most ", allowed, " are allowed"));
    }
    if (count > limit) {
      return absl::InvalidArgumentError(absl::StrCat("corrupt Draco data: it declares ", count, " ",
                                                     what, " in only ", bytes.size(), " bytes"));
    }
  }
  return absl::OkStatus();
}

// Decodes `bytes` as the given geometry type. Draco sizes its arrays from counts in the
// stream; a corrupt count can make an allocation throw, which must not escape this module.
template <typename Geometry>
absl::StatusOr<std::unique_ptr<Geometry>> DecodeDraco(
    std::string_view bytes, uint64_t max_points = std::numeric_limits<uint64_t>::max()) {
  if (bytes.empty()) return absl::InvalidArgumentError("no Draco data: the buffer is empty");
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  const auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("not valid Draco data: ", type.status().error_msg_string()));
  }
  constexpr bool kWantMesh = std::is_same_v<Geometry, draco::Mesh>;
  if (kWantMesh && type.value() != draco::TRIANGULAR_MESH) {
    return absl::InvalidArgumentError("the Draco data holds a point cloud, not a triangle mesh");
  }
  NM_RETURN_IF_ERROR(CheckStreamStart(bytes, max_points));
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  try {
    if constexpr (kWantMesh) {
      auto result = decoder.DecodeMeshFromBuffer(&buffer);
      if (!result.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("corrupt or truncated Draco mesh: ", result.status().error_msg_string()));
      }
      return std::move(result).value();
    } else {
      auto result = decoder.DecodePointCloudFromBuffer(&buffer);
      if (!result.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("corrupt or truncated Draco data: ", result.status().error_msg_string()));
      }
      return std::move(result).value();
    }
  } catch (const std::bad_alloc&) {
    return absl::InvalidArgumentError(
        "corrupt Draco data: it declares more elements than can be allocated");
  } catch (const std::length_error&) {
    return absl::InvalidArgumentError(
        "corrupt Draco data: it declares more elements than can be allocated");
  }
}

// Draco's streams may declare an attribute of any data type, booleans included, and reading a
// stored byte other than 0 or 1 as a bool is undefined (a fuzzer found a position attribute of
// booleans holding 42). Positions, normals and weights must be numbers.
absl::Status CheckNumeric(const draco::PointAttribute& attribute, const char* what) {
  const draco::DataType type = attribute.data_type();
  if (type >= draco::DT_INT8 && type <= draco::DT_FLOAT64) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat("the Draco ", what, " attribute has data type ",
                                                 static_cast<int>(type), ", not a number type"));
}

absl::StatusOr<const draco::PointAttribute*> PositionAttribute(const draco::PointCloud& geometry) {
  const draco::PointAttribute* positions =
      geometry.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (positions == nullptr) {
    return absl::InvalidArgumentError("the Draco data has no position attribute");
  }
  if (positions->num_components() < 1 || positions->num_components() > 4) {
    return absl::InvalidArgumentError(absl::StrCat("the Draco position attribute has ",
                                                   int{positions->num_components()},
                                                   " components; expected 3"));
  }
  NM_RETURN_IF_ERROR(CheckNumeric(*positions, "position"));
  return positions;
}

absl::StatusOr<Vec3f> ReadVec3(const draco::PointAttribute& attribute,
                               draco::AttributeValueIndex index, const char* what) {
  Vec3f value;
  if (!attribute.ConvertValue<float, 3>(index, value.data())) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot read Draco ", what, " value ", index.value()));
  }
  if (!IsFinite(value)) {
    return absl::InvalidArgumentError(
        absl::StrCat("Draco ", what, " value ", index.value(), " is not finite"));
  }
  return value;
}

// The COLOR attribute of `geometry` when it has one with at least three components (a fourth,
// alpha, is dropped); nullptr otherwise.
absl::StatusOr<const draco::PointAttribute*> ColorAttribute(const draco::PointCloud& geometry) {
  const draco::PointAttribute* colors =
      geometry.GetNamedAttribute(draco::GeometryAttribute::COLOR);
  if (colors == nullptr || colors->num_components() < 3) return nullptr;
  NM_RETURN_IF_ERROR(CheckNumeric(*colors, "colour"));
  return colors;
}

// The largest level of an integer Draco type (colour channels of that type are levels from 0).
double LargestLevel(draco::DataType type) {
  const bool is_signed = type == draco::DT_INT8 || type == draco::DT_INT16 ||
                         type == draco::DT_INT32 || type == draco::DT_INT64;
  return std::ldexp(1.0, 8 * draco::DataTypeLength(type) - (is_signed ? 1 : 0)) - 1.0;
}

// One colour: bytes as they are, other integers as levels of their type (fractions when the
// attribute is normalized, which Draco's conversion has already applied), floats as fractions.
// With ColorStorage::kLinearShorts every channel is linear light, converted to sRGB.
absl::StatusOr<Rgb> ReadColor(const draco::PointAttribute& attribute,
                              draco::AttributeValueIndex index,
                              ColorStorage storage = ColorStorage::kSrgbBytes) {
  Rgb color;
  const bool linear = storage == ColorStorage::kLinearShorts;
  if (attribute.data_type() == draco::DT_UINT8 && !linear) {
    if (!attribute.ConvertValue<uint8_t, 3>(index, color.data())) {
      return absl::InvalidArgumentError(
          absl::StrCat("cannot read Draco colour value ", index.value()));
    }
    return color;
  }
  float channels[3];
  if (!attribute.ConvertValue<float, 3>(index, channels)) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot read Draco colour value ", index.value()));
  }
  const bool levels = attribute.data_type() < draco::DT_FLOAT32 && !attribute.normalized();
  const double max = levels ? LargestLevel(attribute.data_type()) : 1.0;
  for (int c = 0; c < 3; ++c) {
    color[c] = linear ? SrgbFromLinear(channels[c] / max) : ChannelFromLevel(channels[c], max);
  }
  return color;
}

}  // namespace

// Draco's encoder passes the box's origin and edge to its quantizer as text, with
// std::to_string's six decimals (draco::Options).
QuantizationBox BoxAsDracoReadsIt(const QuantizationBox& box) {
  draco::Options text;
  text.SetVector("origin", box.origin.data(), 3);
  text.SetFloat("range", box.range);
  QuantizationBox read;
  text.GetVector("origin", 3, read.origin.data());
  read.range = text.GetFloat("range");
  return read;
}

QuantizationBox DracoExactBox(const QuantizationBox& box) {
  QuantizationBox exact;
  double range = 0;
  for (int c = 0; c < 3; ++c) {
    exact.origin[c] = ValueDracoKeeps(box.origin[c], /*up=*/false);
    range = std::max(range, double{box.origin[c]} + double{box.range} - exact.origin[c]);
  }
  exact.range = ValueDracoKeeps(range, /*up=*/true);
  return exact;
}

absl::Status CheckQuantizationBox(const QuantizationBox& box, int bits) {
  if (!IsFinite(box.origin) || !std::isfinite(box.range) || !(box.range > 0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("the quantization box with origin (", box.origin[0], ", ", box.origin[1], ", ",
                     box.origin[2], ") and range ", box.range, " is not finite and positive"));
  }
  const std::string problem = BoxProblem(BoxAsDracoReadsIt(box), bits);
  if (!problem.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("Draco cannot quantize against a cube of range ", problem));
  }
  return absl::OkStatus();
}

absl::Status DracoOptions::Validate() const {
  NM_RETURN_IF_ERROR(CheckRange("position_quantization_bits", position_quantization_bits, 1,
                                kMaxQuantizationBits));
  NM_RETURN_IF_ERROR(
      CheckRange("normal_quantization_bits", normal_quantization_bits, 2, kMaxQuantizationBits));
  NM_RETURN_IF_ERROR(
      CheckRange("weight_quantization_bits", weight_quantization_bits, 1, kMaxQuantizationBits));
  NM_RETURN_IF_ERROR(CheckRange("encode_speed", encode_speed, 0, kMaxDracoSpeed));
  NM_RETURN_IF_ERROR(CheckRange("decode_speed", decode_speed, 0, kMaxDracoSpeed));
  if (quantization_box.has_value()) {
    const QuantizationBox& box = *quantization_box;
    if (!IsFinite(box.origin)) {
      return absl::InvalidArgumentError(
          "DracoOptions.quantization_box.origin has a non-finite coordinate");
    }
    if (!std::isfinite(box.range) || box.range <= 0) {
      return absl::InvalidArgumentError(absl::StrCat("DracoOptions.quantization_box.range is ",
                                                     box.range,
                                                     "; it must be finite and positive"));
    }
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(box.origin[c] + box.range)) {
        return absl::InvalidArgumentError(
            "DracoOptions.quantization_box.origin + range overflows a float");
      }
    }
  }
  return absl::OkStatus();
}

namespace {

// EncodeMesh, with colours stored as `storage` says.
absl::StatusOr<std::string> EncodeMeshStoring(const TriangleMesh& mesh,
                                              const DracoOptions& options,
                                              ColorStorage storage) {
  NM_RETURN_IF_ERROR(options.Validate());
  if (mesh.positions.empty()) {
    return absl::InvalidArgumentError("cannot encode an empty mesh (no vertices)");
  }
  if (mesh.faces.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the mesh has ", mesh.positions.size(),
                     " vertices but no faces; encode it with EncodePointCloud"));
  }
  NM_RETURN_IF_ERROR(CheckPositions(mesh.positions, options));
  const size_t num_vertices = mesh.positions.size();
  bool any_proper_face = false;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const std::array<uint32_t, 3>& face = mesh.faces[f];
    for (uint32_t v : face) {
      if (v >= num_vertices) {
        return absl::InvalidArgumentError(absl::StrCat(
            "face ", f, " uses vertex ", v, " but the mesh has only ", num_vertices, " vertices"));
      }
    }
    any_proper_face |= face[0] != face[1] && face[1] != face[2] && face[2] != face[0];
  }
  if (!any_proper_face) {
    return absl::InvalidArgumentError(
        "every face repeats a vertex index; Edgebreaker drops such degenerate faces, so nothing "
        "would remain");
  }
  NM_RETURN_IF_ERROR(CheckColorCount(mesh.colors.size(), num_vertices, "vertices"));

  draco::Mesh geometry;
  geometry.set_num_points(static_cast<uint32_t>(num_vertices));
  const int position_id = AddFloatAttribute(geometry, draco::GeometryAttribute::POSITION, 3,
                                            mesh.positions.front().data(), num_vertices);
  if (!mesh.colors.empty()) AddColorAttribute(geometry, mesh.colors, storage);
  AddOrigin(geometry, mesh.origin);
  geometry.SetNumFaces(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    draco::Mesh::Face face;
    for (int k = 0; k < 3; ++k) face[k] = draco::PointIndex(mesh.faces[f][k]);
    geometry.SetFace(draco::FaceIndex(static_cast<uint32_t>(f)), face);
  }

  const MeshEncoding given{options.encode_speed, options.decode_speed};
  NM_ASSIGN_OR_RETURN(std::string best, EncodeMeshAs(geometry, position_id, options, given));
  if (!options.shrink_small_meshes || num_vertices >= kSmallMeshVertices) return best;
  // Draco takes the larger of the two speeds as the one that limits its choices, so both are
  // set. Every variant quantizes against the same grid, so they all decode to the same mesh
  // (up to the order of vertices and faces).
  for (const MeshEncoding& variant : {MeshEncoding{0, 0}, MeshEncoding{10, 10}}) {
    if (variant == given) continue;
    NM_ASSIGN_OR_RETURN(std::string bytes, EncodeMeshAs(geometry, position_id, options, variant));
    if (bytes.size() < best.size()) best = std::move(bytes);
  }
  return best;
}

}  // namespace

absl::StatusOr<std::string> EncodeMesh(const TriangleMesh& mesh, const DracoOptions& options) {
  return EncodeMeshStoring(mesh, options, ColorStorage::kSrgbBytes);
}

absl::StatusOr<std::string> EncodeMeshForGltf(const TriangleMesh& mesh,
                                              const DracoOptions& options) {
  // A new draco::Mesh gives its attributes the unique ids 0, 1, ... in the order they are
  // added: positions first, then colours (GltfIoTest and three.js, in GltfThreeJsTest, read
  // them by these ids).
  static_assert(kGltfDracoPositionId == 0 && kGltfDracoColorId == 1);
  return EncodeMeshStoring(mesh, options, ColorStorage::kLinearShorts);
}

absl::StatusOr<std::string> EncodePointCloud(const PointCloud& cloud, const DracoOptions& options) {
  NM_RETURN_IF_ERROR(options.Validate());
  if (cloud.empty()) return absl::InvalidArgumentError("cannot encode an empty point cloud");
  NM_RETURN_IF_ERROR(ValidatePointCloud(cloud));
  NM_RETURN_IF_ERROR(CheckPositions(cloud.positions, options));
  if (!cloud.weights.empty()) {
    const std::string problem =
        GridProblem(GridOfValues(cloud.weights.data(), cloud.weights.size(), 1), 1,
                    options.weight_quantization_bits);
    if (!problem.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("cannot quantize the weights with Draco: they span ", problem));
    }
  }

  const size_t n = cloud.size();
  draco::PointCloud geometry;
  geometry.set_num_points(static_cast<uint32_t>(n));
  const int position_id = AddFloatAttribute(geometry, draco::GeometryAttribute::POSITION, 3,
                                            cloud.positions.front().data(), n);
  int normal_id = -1;
  if (!cloud.normals.empty()) {
    const std::vector<Vec3f> directions = UnitNormals(cloud.normals);
    normal_id = AddFloatAttribute(geometry, draco::GeometryAttribute::NORMAL, 3,
                                  directions.front().data(), n);
  }
  int weight_id = -1;
  if (!cloud.weights.empty()) {
    weight_id =
        AddFloatAttribute(geometry, draco::GeometryAttribute::GENERIC, 1, cloud.weights.data(), n);
  }
  if (!cloud.colors.empty()) AddColorAttribute(geometry, cloud.colors);
  AddOrigin(geometry, cloud.origin);

  draco::ExpertEncoder encoder(geometry);
  encoder.SetSpeedOptions(options.encode_speed, options.decode_speed);
  // Every attribute is quantized or an integer, so the kd-tree coder always applies below
  // speed 10.
  encoder.SetEncodingMethod(options.encode_speed == 10 ? draco::POINT_CLOUD_SEQUENTIAL_ENCODING
                                                       : draco::POINT_CLOUD_KD_TREE_ENCODING);
  SetPositionQuantization(encoder, position_id, options);
  if (normal_id >= 0) encoder.SetAttributeQuantization(normal_id, options.normal_quantization_bits);
  if (weight_id >= 0) encoder.SetAttributeQuantization(weight_id, options.weight_quantization_bits);
  return RunEncoder(encoder, "point cloud");
}

absl::StatusOr<TriangleMesh> DecodeMesh(std::string_view bytes) {
  NM_ASSIGN_OR_RETURN(std::unique_ptr<draco::Mesh> geometry, DecodeDraco<draco::Mesh>(bytes));
  NM_ASSIGN_OR_RETURN(const draco::PointAttribute* positions, PositionAttribute(*geometry));
  if (positions->size() == 0 || geometry->num_faces() == 0) {
    return absl::InvalidArgumentError("the Draco mesh is empty");
  }
  NM_ASSIGN_OR_RETURN(const draco::PointAttribute* colors, ColorAttribute(*geometry));
  TriangleMesh mesh;
  NM_ASSIGN_OR_RETURN(mesh.origin, ReadOrigin(*geometry));
  mesh.positions.reserve(positions->size());
  for (draco::AttributeValueIndex i(0); i < static_cast<uint32_t>(positions->size()); ++i) {
    NM_ASSIGN_OR_RETURN(Vec3f p, ReadVec3(*positions, i, "position"));
    mesh.positions.push_back(p);
  }
  // A vertex takes the colour of the last point at its position.
  if (colors != nullptr) {
    mesh.colors.resize(mesh.positions.size());
    for (draco::PointIndex i(0); i < geometry->num_points(); ++i) {
      const uint32_t vertex = positions->mapped_index(i).value();
      if (vertex >= mesh.positions.size()) continue;  // Corrupt: the faces' check says so.
      NM_ASSIGN_OR_RETURN(mesh.colors[vertex], ReadColor(*colors, colors->mapped_index(i)));
    }
  }
  // Faces index points; a point may differ from another only in a non-position attribute
  // (e.g. a texture seam), so faces are mapped to position values, which merges such points.
  mesh.faces.reserve(geometry->num_faces());
  for (draco::FaceIndex f(0); f < geometry->num_faces(); ++f) {
    const draco::Mesh::Face& face = geometry->face(f);
    std::array<uint32_t, 3> triangle;
    for (int k = 0; k < 3; ++k) {
      if (face[k].value() >= geometry->num_points()) {
        return absl::InvalidArgumentError(
            absl::StrCat("Draco face ", f.value(), " uses a point out of range"));
      }
      triangle[k] = positions->mapped_index(face[k]).value();
      if (triangle[k] >= mesh.positions.size()) {
        return absl::InvalidArgumentError(
            absl::StrCat("Draco face ", f.value(), " maps to a position out of range"));
      }
    }
    mesh.faces.push_back(triangle);
  }
  return mesh;
}

absl::StatusOr<TriangleMesh> DecodeGltfDracoMesh(std::string_view bytes, int position_id,
                                                 int color_id) {
  NM_ASSIGN_OR_RETURN(std::unique_ptr<draco::Mesh> geometry, DecodeDraco<draco::Mesh>(bytes));
  const auto attribute =
      [&](int id, const char* what) -> absl::StatusOr<const draco::PointAttribute*> {
    const draco::PointAttribute* found = geometry->GetAttributeByUniqueId(id);
    if (found == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat("the Draco data has no attribute with unique id ", id, " for ", what));
    }
    if (found->num_components() < 3) {
      return absl::InvalidArgumentError(absl::StrCat("the Draco ", what, " attribute has ",
                                                     int{found->num_components()},
                                                     " components; expected 3 or more"));
    }
    NM_RETURN_IF_ERROR(CheckNumeric(*found, what));
    return found;
  };
  NM_ASSIGN_OR_RETURN(const draco::PointAttribute* positions, attribute(position_id, "POSITION"));
  const draco::PointAttribute* colors = nullptr;
  if (color_id >= 0) {
    NM_ASSIGN_OR_RETURN(colors, attribute(color_id, "COLOR_0"));
  }
  const uint32_t points = geometry->num_points();
  if (points == 0 || geometry->num_faces() == 0) {
    return absl::InvalidArgumentError("the Draco mesh is empty");
  }
  TriangleMesh mesh;
  mesh.positions.reserve(points);
  if (colors != nullptr) mesh.colors.reserve(points);
  for (draco::PointIndex i(0); i < points; ++i) {
    NM_ASSIGN_OR_RETURN(Vec3f p, ReadVec3(*positions, positions->mapped_index(i), "position"));
    mesh.positions.push_back(p);
    if (colors == nullptr) continue;
    NM_ASSIGN_OR_RETURN(Rgb color,
                        ReadColor(*colors, colors->mapped_index(i), ColorStorage::kLinearShorts));
    mesh.colors.push_back(color);
  }
  mesh.faces.reserve(geometry->num_faces());
  for (draco::FaceIndex f(0); f < geometry->num_faces(); ++f) {
    const draco::Mesh::Face& face = geometry->face(f);
    std::array<uint32_t, 3> triangle;
    for (int k = 0; k < 3; ++k) {
      triangle[k] = face[k].value();
      if (triangle[k] >= points) {
        return absl::InvalidArgumentError(
            absl::StrCat("Draco face ", f.value(), " uses a point out of range"));
      }
    }
    mesh.faces.push_back(triangle);
  }
  return mesh;
}

absl::StatusOr<PointCloud> DecodePointCloud(std::string_view bytes, uint64_t max_points) {
  NM_ASSIGN_OR_RETURN(std::unique_ptr<draco::PointCloud> geometry,
                      DecodeDraco<draco::PointCloud>(bytes, max_points));
  NM_ASSIGN_OR_RETURN(const draco::PointAttribute* positions, PositionAttribute(*geometry));
  const uint32_t n = geometry->num_points();
  if (n == 0) return absl::InvalidArgumentError("the Draco point cloud is empty");
  const draco::PointAttribute* normals =
      geometry->GetNamedAttribute(draco::GeometryAttribute::NORMAL);
  const draco::PointAttribute* weights = nullptr;
  for (int i = 0; i < geometry->num_attributes(); ++i) {
    const draco::PointAttribute* attribute = geometry->attribute(i);
    if (attribute->attribute_type() == draco::GeometryAttribute::GENERIC &&
        attribute->num_components() == 1) {
      weights = attribute;
      break;
    }
  }
  if (normals != nullptr) NM_RETURN_IF_ERROR(CheckNumeric(*normals, "normal"));
  if (weights != nullptr) NM_RETURN_IF_ERROR(CheckNumeric(*weights, "weight"));
  NM_ASSIGN_OR_RETURN(const draco::PointAttribute* colors, ColorAttribute(*geometry));

  PointCloud cloud;
  NM_ASSIGN_OR_RETURN(cloud.origin, ReadOrigin(*geometry));
  cloud.positions.reserve(n);
  if (normals != nullptr) cloud.normals.reserve(n);
  if (weights != nullptr) cloud.weights.reserve(n);
  if (colors != nullptr) cloud.colors.reserve(n);
  for (draco::PointIndex i(0); i < n; ++i) {
    NM_ASSIGN_OR_RETURN(Vec3f p, ReadVec3(*positions, positions->mapped_index(i), "position"));
    cloud.positions.push_back(p);
    if (normals != nullptr) {
      NM_ASSIGN_OR_RETURN(Vec3f normal, ReadVec3(*normals, normals->mapped_index(i), "normal"));
      cloud.normals.push_back(normal);
    }
    if (weights != nullptr) {
      float w = 0;
      if (!weights->ConvertValue<float, 1>(weights->mapped_index(i), &w)) {
        return absl::InvalidArgumentError(
            absl::StrCat("cannot read the Draco weight of point ", i.value()));
      }
      cloud.weights.push_back(w);
    }
    if (colors != nullptr) {
      NM_ASSIGN_OR_RETURN(Rgb color, ReadColor(*colors, colors->mapped_index(i)));
      cloud.colors.push_back(color);
    }
  }
  const absl::Status valid = ValidatePointCloud(cloud);
  if (!valid.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the decoded Draco point cloud is invalid: ", valid.message()));
  }
  return cloud;
}

}  // namespace neuralmesh
