#include "core/io/internal/gltf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/analysis/json_reader.h"
#include "core/analysis/json_writer.h"
#include "core/io/file_contents.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/vertex_merger.h"
#include "core/status_macros.h"
#include "core/version.h"

namespace neuralmesh::io_internal {
namespace {

constexpr uint32_t kGlbMagic = 0x46546C67;       // "glTF"
constexpr uint32_t kJsonChunkType = 0x4E4F534A;  // "JSON"
constexpr uint32_t kBinChunkType = 0x004E4942;   // "BIN\0"
constexpr size_t kGlbHeaderBytes = 12;
constexpr size_t kChunkHeaderBytes = 8;
constexpr char kDracoExtension[] = "KHR_draco_mesh_compression";
// The attribute of per-point weights (glTF: application-specific semantics begin with "_").
constexpr char kWeightAttribute[] = "_WEIGHT";

// glTF's accessor component types and primitive modes, and the buffer-view targets.
enum ComponentType : int {
  kByte = 5120,
  kUnsignedByte = 5121,
  kShort = 5122,
  kUnsignedShort = 5123,
  kUnsignedInt = 5125,
  kFloat = 5126,
};
enum PrimitiveMode : int {
  kPoints = 0,
  kLines = 1,
  kLineLoop = 2,
  kLineStrip = 3,
  kTriangles = 4,
  kTriangleStrip = 5,
  kTriangleFan = 6,
};
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;

// Vertices and faces read, instances of meshes included: a small file can draw one large mesh
// many times, and memory must stay bounded.
constexpr uint64_t kMaxVertices = uint64_t{1} << 26;
constexpr uint64_t kMaxFaces = uint64_t{1} << 27;

// Integers in JSON are doubles; glTF's indices and sizes stay below 2^53.
constexpr double kLargestExactInteger = 9007199254740992.0;

template <typename... Args>
absl::Status Invalid(const Args&... args) {
  return absl::InvalidArgumentError(absl::StrCat("glTF: ", args...));
}

size_t ComponentBytes(int type) {
  switch (type) {
    case kByte:
    case kUnsignedByte:
      return 1;
    case kShort:
    case kUnsignedShort:
      return 2;
    case kUnsignedInt:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

int ComponentsOf(absl::string_view type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4" || type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

// One component at `p`, little-endian; normalized integers map to [0, 1] or [-1, 1] as glTF
// says.
double ComponentValue(const char* p, int type, bool normalized) {
  switch (type) {
    case kByte: {
      const double v = LoadScalar<int8_t>(p, false);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case kUnsignedByte: {
      const double v = LoadScalar<uint8_t>(p, false);
      return normalized ? v / 255.0 : v;
    }
    case kShort: {
      const double v = LoadScalar<int16_t>(p, false);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case kUnsignedShort: {
      const double v = LoadScalar<uint16_t>(p, false);
      return normalized ? v / 65535.0 : v;
    }
    case kUnsignedInt:
      return LoadScalar<uint32_t>(p, false);
    default:
      return LoadScalar<float>(p, false);
  }
}

// A non-negative integer `value`, named `what` in errors.
absl::StatusOr<uint64_t> IntegerOf(const JsonValue& value, absl::string_view what) {
  if (!value.is_number() || value.number < 0 || value.number != std::floor(value.number) ||
      value.number > kLargestExactInteger) {
    return Invalid(what, " must be a non-negative integer");
  }
  return static_cast<uint64_t>(value.number);
}

// The integer member `key` of `object`, or `fallback` when it is absent.
absl::StatusOr<uint64_t> IntegerMember(const JsonValue& object, absl::string_view key,
                                       std::optional<uint64_t> fallback, absl::string_view where) {
  const JsonValue* value = object.Find(key);
  if (value == nullptr) {
    if (fallback.has_value()) return *fallback;
    return Invalid(where, " has no ", key);
  }
  return IntegerOf(*value, absl::StrCat(where, ".", key));
}

// `%XX` escapes of a URI decoded.
std::string PercentDecoded(absl::string_view uri) {
  const auto hex = [](char h) { return absl::ascii_isdigit(h) ? h - '0' : (h | 0x20) - 'a' + 10; };
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() &&
        absl::ascii_isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        absl::ascii_isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out.push_back(static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2])));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

// A column-major 4x4 matrix, as glTF writes them.
using Matrix = std::array<double, 16>;

constexpr Matrix kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

Matrix Multiply(const Matrix& a, const Matrix& b) {
  Matrix m{};
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += a[k * 4 + row] * b[col * 4 + k];
      m[col * 4 + row] = sum;
    }
  }
  return m;
}

double LinearPartDeterminant(const Matrix& m) {
  return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
         m[8] * (m[1] * m[6] - m[5] * m[2]);
}

// The transform of normals under `m`: its linear part's cofactor matrix (the inverse transpose
// times the determinant), signed so that it keeps a normal's side under a mirroring transform.
Matrix NormalMatrix(const Matrix& m) {
  const auto at = [&](int row, int col) { return m[col * 4 + row]; };
  Matrix n = kIdentity;
  const double sign = LinearPartDeterminant(m) < 0 ? -1.0 : 1.0;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      const int r1 = (row + 1) % 3, r2 = (row + 2) % 3, c1 = (col + 1) % 3, c2 = (col + 2) % 3;
      n[col * 4 + row] = sign * (at(r1, c1) * at(r2, c2) - at(r1, c2) * at(r2, c1));
    }
  }
  return n;
}

// `normal` as glTF wants NORMAL, unit length: as it is when it nearly is, so that unit normals
// come back bitwise; a zero normal stays zero.
Vec3f UnitNormal(const Vec3f& normal) {
  const double squared = static_cast<double>(normal[0]) * normal[0] +
                         static_cast<double>(normal[1]) * normal[1] +
                         static_cast<double>(normal[2]) * normal[2];
  if (std::abs(squared - 1) < 1e-6 || !(squared > 0)) return normal;
  const double length = std::sqrt(squared);
  return Vec3f(static_cast<float>(normal[0] / length), static_cast<float>(normal[1] / length),
               static_cast<float>(normal[2] / length));
}

// `normal` turned by `normal_matrix` and made unit length (UnitNormal; a zero normal stays zero).
Vec3f Transformed(const Matrix& normal_matrix, const Vec3f& normal) {
  if (normal_matrix == kIdentity) return UnitNormal(normal);
  double turned[3];
  double length = 0;
  for (int row = 0; row < 3; ++row) {
    turned[row] = normal_matrix[row] * normal[0] + normal_matrix[4 + row] * normal[1] +
                  normal_matrix[8 + row] * normal[2];
    length += turned[row] * turned[row];
  }
  length = std::sqrt(length);
  if (!(length > 0) || !std::isfinite(length)) return Vec3f(0, 0, 0);
  return Vec3f(static_cast<float>(turned[0] / length), static_cast<float>(turned[1] / length),
               static_cast<float>(turned[2] / length));
}

// `count` numbers of member `key` of `node`, or nullopt when it is absent.
absl::StatusOr<std::optional<std::vector<double>>> Numbers(const JsonValue& node,
                                                           absl::string_view key, size_t count,
                                                           absl::string_view where) {
  const JsonValue* value = node.Find(key);
  if (value == nullptr) return std::nullopt;
  if (!value->is_array() || value->items.size() != count) {
    return Invalid(where, ".", key, " must be an array of ", count, " numbers");
  }
  std::vector<double> numbers;
  for (const JsonValue& item : value->items) {
    if (!item.is_number()) {
      return Invalid(where, ".", key, " must be an array of ", count, " numbers");
    }
    numbers.push_back(item.number);
  }
  return numbers;
}

// A node's own transform: its matrix, or translation * rotation * scale.
absl::StatusOr<Matrix> LocalTransform(const JsonValue& node, absl::string_view where) {
  NM_ASSIGN_OR_RETURN(std::optional<std::vector<double>> matrix,
                      Numbers(node, "matrix", 16, where));
  if (matrix.has_value()) {
    Matrix m;
    std::copy(matrix->begin(), matrix->end(), m.begin());
    return m;
  }
  NM_ASSIGN_OR_RETURN(std::optional<std::vector<double>> t, Numbers(node, "translation", 3, where));
  NM_ASSIGN_OR_RETURN(std::optional<std::vector<double>> r, Numbers(node, "rotation", 4, where));
  NM_ASSIGN_OR_RETURN(std::optional<std::vector<double>> s, Numbers(node, "scale", 3, where));
  double x = 0, y = 0, z = 0, w = 1;
  if (r.has_value()) {
    const double norm =
        std::sqrt((*r)[0] * (*r)[0] + (*r)[1] * (*r)[1] + (*r)[2] * (*r)[2] + (*r)[3] * (*r)[3]);
    if (!(norm > 0)) return Invalid(where, ".rotation is not a unit quaternion");
    x = (*r)[0] / norm, y = (*r)[1] / norm, z = (*r)[2] / norm, w = (*r)[3] / norm;
  }
  // The rotation matrix of the unit quaternion (x, y, z, w), column by column.
  const double rotation[9] = {
      1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
      2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
      2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  Matrix m = kIdentity;
  for (int col = 0; col < 3; ++col) {
    const double scale = s.has_value() ? (*s)[col] : 1.0;
    for (int row = 0; row < 3; ++row) m[col * 4 + row] = rotation[col * 3 + row] * scale;
  }
  if (t.has_value()) {
    for (int row = 0; row < 3; ++row) m[12 + row] = (*t)[row];
  }
  return m;
}

// Whether a required extension leaves the geometry that this reader takes as it is.
bool CanIgnoreOrRead(absl::string_view extension) {
  return extension == kDracoExtension || extension == "KHR_mesh_quantization" ||
         extension == "KHR_lights_punctual" || extension == "EXT_lights_image_based" ||
         absl::StartsWith(extension, "KHR_materials_") ||
         absl::StartsWith(extension, "KHR_texture_") || absl::StartsWith(extension, "EXT_texture_");
}

// The values of an accessor, `components` per element, as doubles.
struct AccessorData {
  std::vector<double> values;
  uint64_t count = 0;
  int components = 0;
  int component_type = 0;
  bool normalized = false;  // Integers already mapped to [0, 1] or [-1, 1].
};

class GltfReader {
 public:
  GltfReader(JsonValue doc, std::optional<absl::string_view> bin, const GltfBufferLoader& loader,
             FaceHandling faces)
      : doc_(std::move(doc)), bin_(bin), loader_(loader), faces_(faces), merger_(&placed_) {}

  absl::StatusOr<ParsedGeometry> Read() {
    NM_RETURN_IF_ERROR(CheckAssetAndExtensions());
    const JsonValue* scenes = doc_.Find("scenes");
    if (scenes != nullptr && scenes->is_array() && !scenes->items.empty()) {
      NM_ASSIGN_OR_RETURN(const uint64_t scene, IntegerMember(doc_, "scene", 0, "the document"));
      NM_ASSIGN_OR_RETURN(const JsonValue* chosen, Element("scenes", scene));
      const JsonValue* roots = chosen->Find("nodes");
      if (roots != nullptr) {
        if (!roots->is_array()) return Invalid("scenes[", scene, "].nodes must be an array");
        const JsonValue* nodes = doc_.Find("nodes");
        visited_.assign(nodes != nullptr && nodes->is_array() ? nodes->items.size() : 0, false);
        for (const JsonValue& root : roots->items) {
          NM_ASSIGN_OR_RETURN(const uint64_t node,
                              IntegerOf(root, absl::StrCat("scenes[", scene, "].nodes[]")));
          NM_RETURN_IF_ERROR(AddNode(node, kIdentity));
        }
      }
    } else if (const JsonValue* meshes = doc_.Find("meshes"); meshes != nullptr) {
      if (!meshes->is_array()) return Invalid("meshes must be an array");
      for (uint64_t mesh = 0; mesh < meshes->items.size(); ++mesh) {
        NM_RETURN_IF_ERROR(AddMesh(mesh, kIdentity));
      }
    }
    NarrowAndMerge();
    return std::move(out_);
  }

 private:
  absl::Status CheckAssetAndExtensions() {
    if (!doc_.is_object()) return Invalid("the JSON document is not an object");
    const JsonValue* asset = doc_.Find("asset");
    const JsonValue* version = asset != nullptr ? asset->Find("version") : nullptr;
    if (version == nullptr || !version->is_string()) {
      return Invalid("asset.version is missing; not a glTF file");
    }
    if (!absl::StartsWith(version->text, "2.")) {
      return Invalid("asset.version is '", version->text, "'; only glTF 2 is supported");
    }
    const JsonValue* required = doc_.Find("extensionsRequired");
    if (required == nullptr) return absl::OkStatus();
    if (!required->is_array()) return Invalid("extensionsRequired must be an array");
    for (const JsonValue& extension : required->items) {
      if (!extension.is_string()) return Invalid("extensionsRequired must list strings");
      if (!CanIgnoreOrRead(extension.text)) {
        return Invalid("the file requires the extension ", extension.text,
                       ", which changes geometry and is not supported");
      }
    }
    return absl::OkStatus();
  }

  // Element `index` of the top-level array `array`, which must be an object.
  absl::StatusOr<const JsonValue*> Element(absl::string_view array, uint64_t index) const {
    const JsonValue* items = doc_.Find(array);
    const size_t size = items != nullptr && items->is_array() ? items->items.size() : 0;
    if (index >= size) {
      return Invalid(array, "[", index, "] does not exist (there are ", size, ")");
    }
    if (!items->items[index].is_object()) return Invalid(array, "[", index, "] is not an object");
    return &items->items[index];
  }

  absl::Status AddNode(uint64_t index, const Matrix& parent) {
    NM_ASSIGN_OR_RETURN(const JsonValue* node, Element("nodes", index));
    if (visited_[index]) {
      return Invalid("nodes[", index, "] is reached twice (glTF's nodes form trees)");
    }
    visited_[index] = true;
    const std::string where = absl::StrCat("nodes[", index, "]");
    NM_ASSIGN_OR_RETURN(const Matrix local, LocalTransform(*node, where));
    const Matrix world = Multiply(parent, local);
    if (node->Find("mesh") != nullptr) {
      NM_ASSIGN_OR_RETURN(const uint64_t mesh, IntegerMember(*node, "mesh", std::nullopt, where));
      NM_RETURN_IF_ERROR(AddMesh(mesh, world));
    }
    const JsonValue* children = node->Find("children");
    if (children == nullptr) return absl::OkStatus();
    if (!children->is_array()) return Invalid(where, ".children must be an array");
    for (const JsonValue& child : children->items) {
      NM_ASSIGN_OR_RETURN(const uint64_t c, IntegerOf(child, absl::StrCat(where, ".children[]")));
      NM_RETURN_IF_ERROR(AddNode(c, world));
    }
    return absl::OkStatus();
  }

  absl::Status AddMesh(uint64_t index, const Matrix& world) {
    NM_ASSIGN_OR_RETURN(const JsonValue* mesh, Element("meshes", index));
    const JsonValue* primitives = mesh->Find("primitives");
    if (primitives == nullptr || !primitives->is_array()) {
      return Invalid("meshes[", index, "].primitives must be an array");
    }
    for (size_t p = 0; p < primitives->items.size(); ++p) {
      const std::string where = absl::StrCat("meshes[", index, "].primitives[", p, "]");
      if (!primitives->items[p].is_object()) return Invalid(where, " is not an object");
      NM_RETURN_IF_ERROR(AddPrimitive(primitives->items[p], where, world));
    }
    return absl::OkStatus();
  }

  absl::StatusOr<absl::string_view> Buffer(uint64_t index) {
    NM_ASSIGN_OR_RETURN(const JsonValue* buffer, Element("buffers", index));
    const std::string where = absl::StrCat("buffers[", index, "]");
    NM_ASSIGN_OR_RETURN(const uint64_t length,
                        IntegerMember(*buffer, "byteLength", std::nullopt, where));
    absl::string_view bytes;
    const JsonValue* uri = buffer->Find("uri");
    if (uri == nullptr) {
      if (index != 0 || !bin_.has_value()) {
        return Invalid(where, " has no uri and is not the BIN chunk of a .glb file");
      }
      bytes = *bin_;
    } else {
      if (!uri->is_string()) return Invalid(where, ".uri must be a string");
      if (loaded_.size() <= index) loaded_.resize(index + 1);
      if (!loaded_[index].has_value()) {
        NM_ASSIGN_OR_RETURN(loaded_[index], Load(uri->text, where));
      }
      bytes = *loaded_[index];
    }
    if (bytes.size() < length) {
      return Invalid(where, " holds ", bytes.size(), " bytes but declares byteLength ", length);
    }
    return bytes.substr(0, length);
  }

  absl::StatusOr<std::string> Load(const std::string& uri, absl::string_view where) {
    if (absl::StartsWith(uri, "data:")) {
      const size_t comma = uri.find(',');
      if (comma == std::string::npos ||
          !absl::EndsWith(absl::string_view(uri).substr(0, comma), ";base64")) {
        return Invalid(where, ".uri is a data URI that is not base64");
      }
      std::string decoded;
      if (!absl::Base64Unescape(absl::string_view(uri).substr(comma + 1), &decoded)) {
        return Invalid(where, ".uri holds malformed base64");
      }
      return decoded;
    }
    if (!loader_) {
      return Invalid(where, " refers to the file '", uri,
                     "'; external buffers are read only beside a .gltf file on disk");
    }
    return loader_(PercentDecoded(uri));
  }

  absl::StatusOr<absl::string_view> BufferView(uint64_t index, uint64_t* stride) {
    NM_ASSIGN_OR_RETURN(const JsonValue* view, Element("bufferViews", index));
    const std::string where = absl::StrCat("bufferViews[", index, "]");
    NM_ASSIGN_OR_RETURN(const uint64_t buffer, IntegerMember(*view, "buffer", std::nullopt, where));
    NM_ASSIGN_OR_RETURN(const uint64_t offset, IntegerMember(*view, "byteOffset", 0, where));
    NM_ASSIGN_OR_RETURN(const uint64_t length,
                        IntegerMember(*view, "byteLength", std::nullopt, where));
    NM_ASSIGN_OR_RETURN(*stride, IntegerMember(*view, "byteStride", 0, where));
    NM_ASSIGN_OR_RETURN(const absl::string_view bytes, Buffer(buffer));
    if (offset > bytes.size() || length > bytes.size() - offset) {
      return Invalid(where, " (bytes ", offset, " to ", offset + length, ") reaches past buffers[",
                     buffer, "], which has ", bytes.size());
    }
    return bytes.substr(offset, length);
  }

  // Accessor `index` for `what`: its type must be one of `types` (component counts) and its
  // component type one of `component_types`.
  absl::StatusOr<AccessorData> ReadAccessor(uint64_t index, absl::string_view what,
                                            std::initializer_list<int> types,
                                            std::initializer_list<int> component_types) {
    NM_ASSIGN_OR_RETURN(const JsonValue* accessor, Element("accessors", index));
    const std::string where = absl::StrCat("accessors[", index, "] (", what, ")");
    if (accessor->Find("sparse") != nullptr)
      return Invalid(where, " is sparse, which is not supported");
    const JsonValue* type = accessor->Find("type");
    AccessorData data;
    data.components = type != nullptr && type->is_string() ? ComponentsOf(type->text) : 0;
    if (std::find(types.begin(), types.end(), data.components) == types.end()) {
      return Invalid(where, " has type ", type != nullptr ? type->text : "(none)",
                     ", which does not fit");
    }
    NM_ASSIGN_OR_RETURN(const uint64_t component_type,
                        IntegerMember(*accessor, "componentType", std::nullopt, where));
    if (std::find(component_types.begin(), component_types.end(),
                  static_cast<int>(component_type)) == component_types.end()) {
      return Invalid(where, " has componentType ", component_type, ", which does not fit");
    }
    data.component_type = static_cast<int>(component_type);
    const JsonValue* normalized = accessor->Find("normalized");
    data.normalized = normalized != nullptr && normalized->boolean;
    NM_ASSIGN_OR_RETURN(data.count, IntegerMember(*accessor, "count", std::nullopt, where));
    NM_ASSIGN_OR_RETURN(const uint64_t offset, IntegerMember(*accessor, "byteOffset", 0, where));
    if (accessor->Find("bufferView") == nullptr) {
      return Invalid(where, " has no bufferView (accessors of zeros are not supported)");
    }
    NM_ASSIGN_OR_RETURN(const uint64_t view_index,
                        IntegerMember(*accessor, "bufferView", std::nullopt, where));
    uint64_t stride = 0;
    NM_ASSIGN_OR_RETURN(const absl::string_view view, BufferView(view_index, &stride));
    const size_t component_bytes = ComponentBytes(data.component_type);
    const uint64_t element = component_bytes * data.components;
    if (stride == 0) stride = element;
    if (stride < element) {
      return Invalid(where, ": bufferViews[", view_index, "].byteStride ", stride,
                     " is shorter than an element (", element, " bytes)");
    }
    if (data.count == 0 || offset > view.size() || view.size() - offset < element ||
        (view.size() - offset - element) / stride < data.count - 1) {
      return Invalid(where, ": ", data.count, " elements of ", element, " bytes from byte ", offset,
                     " do not fit in bufferViews[", view_index, "] (", view.size(), " bytes)");
    }
    data.values.resize(data.count * data.components);
    for (uint64_t i = 0; i < data.count; ++i) {
      const char* p = view.data() + offset + i * stride;
      for (int c = 0; c < data.components; ++c) {
        data.values[i * data.components + c] =
            ComponentValue(p + c * component_bytes, data.component_type, data.normalized);
      }
    }
    return data;
  }

  absl::Status AddPrimitive(const JsonValue& primitive, const std::string& where,
                            const Matrix& world) {
    NM_ASSIGN_OR_RETURN(const uint64_t mode, IntegerMember(primitive, "mode", kTriangles, where));
    if (mode > kTriangleFan) return Invalid(where, ".mode ", mode, " is not a glTF mode");
    const JsonValue* attributes = primitive.Find("attributes");
    if (attributes == nullptr || !attributes->is_object()) {
      return Invalid(where, ".attributes must be an object");
    }
    std::vector<Vec3f> positions;
    std::vector<Rgb> colors;
    std::vector<Vec3f> normals;
    std::vector<float> weights;
    std::vector<uint32_t> indices;  // Empty: the vertices in order.
    bool has_indices = false;
    const JsonValue* extensions = primitive.Find("extensions");
    const JsonValue* draco = extensions != nullptr ? extensions->Find(kDracoExtension) : nullptr;
    if (draco != nullptr) {
      NM_RETURN_IF_ERROR(ReadDracoPrimitive(*draco, where, &positions, &colors, &indices));
      has_indices = true;
    } else {
      NM_RETURN_IF_ERROR(ReadPrimitive(*attributes, primitive, where, &positions, &colors, &indices,
                                       &has_indices));
      NM_RETURN_IF_ERROR(
          ReadPointAttributes(*attributes, where, positions.size(), &normals, &weights));
    }
    if (placed_.size() + positions.size() > kMaxVertices) {
      return Invalid("the scene draws more than ", kMaxVertices, " vertices");
    }
    const bool mirrored = LinearPartDeterminant(world) < 0;
    colored_ = colored_ && !colors.empty();
    with_normals_ = with_normals_ && !normals.empty();
    weighted_ = weighted_ && !weights.empty();
    if (!with_normals_) std::vector<Vec3f>().swap(normals_);  // The file's are left out.
    if (!weighted_) std::vector<float>().swap(weights_);
    const Matrix normal_matrix = NormalMatrix(world);
    std::vector<uint32_t> merged(positions.size());
    for (size_t i = 0; i < positions.size(); ++i) {
      const Vec3f& p = positions[i];
      Point3d q;
      for (int row = 0; row < 3; ++row) {
        q[row] = world[row] * p[0] + world[4 + row] * p[1] + world[8 + row] * p[2] +
                 world[12 + row];
        // Beyond a float's range (or NaN) the position could not be narrowed.
        if (!(std::abs(q[row]) <= std::numeric_limits<float>::max())) {
          return Invalid(where, ": vertex ", i, " is not finite where its node places it");
        }
        // A sum with +0 terms gives +0 where a coordinate was -0, and a tiny negative sum
        // rounds to -0: zeros are +0, so that a file reads the same however it places them.
        if (q[row] == 0.0) q[row] = 0.0;
      }
      merged[i] = merger_.Add(q);
      if (merged[i] == colors_.size()) {
        colors_.push_back(colors.empty() ? Rgb{} : colors[i]);
        if (with_normals_) normals_.push_back(Transformed(normal_matrix, normals[i]));
        if (weighted_) weights_.push_back(weights[i]);
      }
    }
    if (faces_ == FaceHandling::kSkip || mode < kTriangles) return absl::OkStatus();
    const size_t corners = has_indices ? indices.size() : positions.size();
    const auto corner = [&](size_t k) {
      return has_indices ? indices[k] : static_cast<uint32_t>(k);
    };
    for (size_t k = 0; k < corners; ++k) {
      if (corner(k) >= positions.size()) {
        return Invalid(where, ": index ", corner(k), " at ", k, " is past its ", positions.size(),
                       " vertices");
      }
    }
    if (mode == kTriangles && corners % 3 != 0) {
      return Invalid(where, ": ", corners, " indices do not make whole triangles");
    }
    const size_t triangles = mode == kTriangles ? corners / 3 : (corners >= 3 ? corners - 2 : 0);
    if (out_.faces.size() + triangles > kMaxFaces) {
      return Invalid("the scene draws more than ", kMaxFaces, " triangles");
    }
    for (size_t t = 0; t < triangles; ++t) {
      std::array<size_t, 3> c;
      if (mode == kTriangles) {
        c = {3 * t, 3 * t + 1, 3 * t + 2};
      } else if (mode == kTriangleStrip) {
        c = {t, t + 1 + t % 2, t + 2 - t % 2};
      } else {
        c = {t + 1, t + 2, 0};
      }
      std::array<uint32_t, 3> face = {merged[corner(c[0])], merged[corner(c[1])],
                                      merged[corner(c[2])]};
      if (face[0] == face[1] || face[1] == face[2] || face[2] == face[0]) continue;
      if (mirrored) std::swap(face[1], face[2]);
      out_.faces.push_back(face);
    }
    return absl::OkStatus();
  }

  absl::Status ReadPrimitive(const JsonValue& attributes, const JsonValue& primitive,
                             const std::string& where, std::vector<Vec3f>* positions,
                             std::vector<Rgb>* colors, std::vector<uint32_t>* indices,
                             bool* has_indices) {
    NM_ASSIGN_OR_RETURN(const uint64_t position_accessor,
                        IntegerMember(attributes, "POSITION", std::nullopt, where + ".attributes"));
    NM_ASSIGN_OR_RETURN(const AccessorData p,
                        ReadAccessor(position_accessor, "POSITION", {3},
                                     {kByte, kUnsignedByte, kShort, kUnsignedShort, kFloat}));
    positions->resize(p.count);
    for (uint64_t i = 0; i < p.count; ++i) {
      for (int c = 0; c < 3; ++c) (*positions)[i][c] = static_cast<float>(p.values[3 * i + c]);
    }
    if (attributes.Find("COLOR_0") != nullptr) {
      NM_ASSIGN_OR_RETURN(const uint64_t color_accessor,
                          IntegerMember(attributes, "COLOR_0", std::nullopt, where));
      NM_ASSIGN_OR_RETURN(
          const AccessorData color,
          ReadAccessor(color_accessor, "COLOR_0", {3, 4}, {kUnsignedByte, kUnsignedShort, kFloat}));
      if (color.count != p.count) {
        return Invalid(where, ": COLOR_0 has ", color.count, " elements for ", p.count,
                       " positions");
      }
      // Integer colours are normalized in valid files; those that are not count as levels.
      const double max = color.component_type == kFloat || color.normalized ? 1.0
                         : color.component_type == kUnsignedByte         ? 255.0
                                                                         : 65535.0;
      colors->resize(color.count);
      for (uint64_t i = 0; i < color.count; ++i) {
        for (int c = 0; c < 3; ++c) {
          (*colors)[i][c] = SrgbFromLinear(color.values[i * color.components + c] / max);
        }
      }
    }
    if (faces_ == FaceHandling::kSkip || primitive.Find("indices") == nullptr) {
      return absl::OkStatus();
    }
    *has_indices = true;
    NM_ASSIGN_OR_RETURN(const uint64_t index_accessor,
                        IntegerMember(primitive, "indices", std::nullopt, where));
    NM_ASSIGN_OR_RETURN(const AccessorData index,
                        ReadAccessor(index_accessor, "indices", {1},
                                     {kUnsignedByte, kUnsignedShort, kUnsignedInt}));
    indices->resize(index.count);
    for (uint64_t i = 0; i < index.count; ++i) {
      (*indices)[i] = static_cast<uint32_t>(index.values[i]);
    }
    return absl::OkStatus();
  }

  // A primitive's NORMAL and weights (_WEIGHT, or the first of _CONFIDENCE, _QUALITY,
  // _INTENSITY and _SCALAR, as the PLY reader names them): `count` of each, or none when the
  // primitive has none. An application-specific attribute of such a name that is not a
  // SCALAR belongs to another application and is passed over.
  absl::Status ReadPointAttributes(const JsonValue& attributes, const std::string& where,
                                   size_t count, std::vector<Vec3f>* normals,
                                   std::vector<float>* weights) {
    if (attributes.Find("NORMAL") != nullptr) {
      NM_ASSIGN_OR_RETURN(const uint64_t accessor,
                          IntegerMember(attributes, "NORMAL", std::nullopt, where));
      NM_ASSIGN_OR_RETURN(const AccessorData normal,
                          ReadAccessor(accessor, "NORMAL", {3}, {kByte, kShort, kFloat}));
      if (normal.count != count) {
        return Invalid(where, ": NORMAL has ", normal.count, " elements for ", count,
                       " positions");
      }
      normals->resize(count);
      for (size_t i = 0; i < count; ++i) {
        for (int c = 0; c < 3; ++c) {
          (*normals)[i][c] = static_cast<float>(normal.values[3 * i + c]);
        }
      }
    }
    for (const char* name :
         {kWeightAttribute, "_CONFIDENCE", "_QUALITY", "_INTENSITY", "_SCALAR"}) {
      if (attributes.Find(name) == nullptr) continue;
      NM_ASSIGN_OR_RETURN(const uint64_t accessor,
                          IntegerMember(attributes, name, std::nullopt, where));
      NM_ASSIGN_OR_RETURN(const JsonValue* described, Element("accessors", accessor));
      const JsonValue* type = described->Find("type");
      if (type == nullptr || !type->is_string() || type->text != "SCALAR") continue;
      NM_ASSIGN_OR_RETURN(
          const AccessorData weight,
          ReadAccessor(accessor, name, {1},
                       {kByte, kUnsignedByte, kShort, kUnsignedShort, kUnsignedInt, kFloat}));
      if (weight.count != count) {
        return Invalid(where, ": ", name, " has ", weight.count, " elements for ", count,
                       " positions");
      }
      weights->resize(count);
      for (size_t i = 0; i < count; ++i) (*weights)[i] = static_cast<float>(weight.values[i]);
      break;
    }
    return absl::OkStatus();
  }

  absl::Status ReadDracoPrimitive(const JsonValue& draco, const std::string& where,
                                  std::vector<Vec3f>* positions, std::vector<Rgb>* colors,
                                  std::vector<uint32_t>* indices) {
    const std::string here = absl::StrCat(where, ".extensions.", kDracoExtension);
    NM_ASSIGN_OR_RETURN(const uint64_t view_index,
                        IntegerMember(draco, "bufferView", std::nullopt, here));
    const JsonValue* ids = draco.Find("attributes");
    if (ids == nullptr || !ids->is_object()) return Invalid(here, ".attributes must be an object");
    NM_ASSIGN_OR_RETURN(const uint64_t position_id,
                        IntegerMember(*ids, "POSITION", std::nullopt, here + ".attributes"));
    int color_id = -1;
    if (ids->Find("COLOR_0") != nullptr) {
      NM_ASSIGN_OR_RETURN(const uint64_t id,
                          IntegerMember(*ids, "COLOR_0", std::nullopt, here + ".attributes"));
      if (id > static_cast<uint64_t>(std::numeric_limits<int>::max())) {
        return Invalid(here, ".attributes.COLOR_0 is out of range");
      }
      color_id = static_cast<int>(id);
    }
    if (position_id > static_cast<uint64_t>(std::numeric_limits<int>::max())) {
      return Invalid(here, ".attributes.POSITION is out of range");
    }
    uint64_t stride = 0;
    NM_ASSIGN_OR_RETURN(const absl::string_view bytes, BufferView(view_index, &stride));
    absl::StatusOr<TriangleMesh> mesh = DecodeGltfDracoMesh(
        std::string_view(bytes.data(), bytes.size()), static_cast<int>(position_id), color_id);
    if (!mesh.ok()) return Invalid(here, ": ", mesh.status().message());
    *positions = std::move(mesh->positions);
    *colors = std::move(mesh->colors);
    indices->clear();
    indices->reserve(mesh->faces.size() * 3);
    for (const std::array<uint32_t, 3>& face : mesh->faces) {
      indices->insert(indices->end(), face.begin(), face.end());
    }
    return absl::OkStatus();
  }

  // Narrows the placed vertices to floats, relative to an origin where they lie far from 0
  // (position_collector.h), and merges those that became identical.
  void NarrowAndMerge() {
    PositionCollector collector(std::move(placed_));
    ParsedGeometry narrowed;
    collector.MoveTo(&narrowed);
    out_.origin = narrowed.origin;
    VertexMerger merger(&out_.positions);
    std::vector<uint32_t> index(narrowed.positions.size());
    std::vector<Rgb> colors;
    std::vector<Vec3f> normals;
    std::vector<float> weights;
    for (size_t i = 0; i < narrowed.positions.size(); ++i) {
      index[i] = merger.Add(narrowed.positions[i]);
      if (index[i] == colors.size()) {
        colors.push_back(colors_[i]);
        if (with_normals_) normals.push_back(normals_[i]);
        if (weighted_) weights.push_back(weights_[i]);
      }
    }
    std::vector<std::array<uint32_t, 3>> faces;
    faces.reserve(out_.faces.size());
    for (const std::array<uint32_t, 3>& placed : out_.faces) {
      const std::array<uint32_t, 3> face = {index[placed[0]], index[placed[1]], index[placed[2]]};
      if (face[0] != face[1] && face[1] != face[2] && face[2] != face[0]) faces.push_back(face);
    }
    out_.faces = std::move(faces);
    if (colored_) out_.colors = std::move(colors);
    if (with_normals_) out_.normals = std::move(normals);
    if (weighted_) out_.weights = std::move(weights);
  }

  JsonValue doc_;
  std::optional<absl::string_view> bin_;
  const GltfBufferLoader& loader_;
  const FaceHandling faces_;
  std::vector<std::optional<std::string>> loaded_;
  std::vector<bool> visited_;
  ParsedGeometry out_;  // Faces index placed_ until NarrowAndMerge.
  std::vector<Point3d> placed_;  // Where the nodes place the vertices, identical ones merged.
  VertexMergerOf<Point3d> merger_;
  // One per placed vertex; black for vertices without colour.
  std::vector<Rgb> colors_;
  // One per placed vertex while every primitive has them, then none.
  std::vector<Vec3f> normals_;  // Turned by the nodes, unit length.
  std::vector<float> weights_;
  bool colored_ = true;       // Every primitive so far has COLOR_0,
  bool with_normals_ = true;  // NORMAL,
  bool weighted_ = true;      // and weights.
};

// Splits a .glb into its JSON text and its BIN chunk (when it has one).
absl::Status SplitGlb(absl::string_view data, absl::string_view* json,
                      std::optional<absl::string_view>* bin) {
  if (data.size() < kGlbHeaderBytes) return Invalid("the .glb header is truncated");
  const uint32_t version = LoadScalar<uint32_t>(data.data() + 4, false);
  const uint32_t length = LoadScalar<uint32_t>(data.data() + 8, false);
  if (version != 2)
    return Invalid("the .glb container is version ", version, "; only 2 is supported");
  if (length > data.size()) {
    return Invalid("the .glb header gives ", length, " bytes but the file has ", data.size(),
                   " (truncated?)");
  }
  size_t at = kGlbHeaderBytes;
  bool first = true;
  while (at < length) {
    if (length - at < kChunkHeaderBytes) return Invalid("the chunk at byte ", at, " is truncated");
    const uint32_t chunk_length = LoadScalar<uint32_t>(data.data() + at, false);
    const uint32_t chunk_type = LoadScalar<uint32_t>(data.data() + at + 4, false);
    if (chunk_length > length - at - kChunkHeaderBytes) {
      return Invalid("the chunk at byte ", at, " declares ", chunk_length,
                     " bytes, past the end of the file");
    }
    const absl::string_view chunk = data.substr(at + kChunkHeaderBytes, chunk_length);
    if (first && chunk_type != kJsonChunkType) {
      return Invalid("the first chunk of a .glb must be JSON");
    }
    if (first) *json = chunk;
    if (!first && chunk_type == kBinChunkType && !bin->has_value()) *bin = chunk;
    first = false;
    at += kChunkHeaderBytes + chunk_length;
  }
  if (first) return Invalid("the .glb has no JSON chunk");
  return absl::OkStatus();
}

struct Range {
  size_t offset;
  size_t length;
};

// A vertex attribute as the writer lays it out and its accessor describes it.
struct VertexAttribute {
  const char* semantic;
  int component_type;
  bool normalized;
  const char* type;
  size_t stride;  // 0: tightly packed.
};


}  // namespace

GltfBufferLoader GltfBuffersBeside(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const std::string directory = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  return [directory](const std::string& uri) -> absl::StatusOr<std::string> {
    const size_t colon = uri.find(':');
    if (uri.empty() || uri[0] == '/' || (colon != std::string::npos && colon < uri.find('/'))) {
      return Invalid("the buffer URI '", uri, "' is not a relative file name");
    }
    absl::StatusOr<std::string> bytes = ReadFileContents(directory + uri);
    if (!bytes.ok()) {
      return absl::Status(bytes.status().code(),
                          absl::StrCat("glTF: buffer '", uri, "': ", bytes.status().message()));
    }
    return bytes;
  };
}

absl::StatusOr<ParsedGeometry> ParseGltf(absl::string_view data, FaceHandling faces,
                                         const GltfBufferLoader& load_buffer) {
  absl::string_view json = data;
  std::optional<absl::string_view> bin;
  if (data.size() >= 4 && LoadScalar<uint32_t>(data.data(), false) == kGlbMagic) {
    NM_RETURN_IF_ERROR(SplitGlb(data, &json, &bin));
  } else if (absl::StartsWith(json, "\xEF\xBB\xBF")) {
    json.remove_prefix(3);  // A byte-order mark, which glTF forbids but some tools write.
  }
  absl::StatusOr<JsonValue> doc = ParseJson(json);
  if (!doc.ok()) return Invalid(doc.status().message());
  return GltfReader(*std::move(doc), bin, load_buffer, faces).Read();
}

absl::StatusOr<std::string> FormatGltf(const GeometryView& geometry,
                                       const GltfWriteOptions& options) {
  const bool colored = !geometry.colors.empty();
  const bool has_faces = !geometry.faces.empty();
  if (options.draco && !has_faces) {
    return absl::InvalidArgumentError(
        "the mesh has no faces, and glTF's Draco compression stores only triangles");
  }
  // What the accessors describe: the geometry as given, or as a Draco decoder will give it.
  absl::Span<const Vec3f> positions = geometry.positions;
  absl::Span<const std::array<uint32_t, 3>> faces = geometry.faces;
  TriangleMesh decoded;
  std::string bin;
  std::vector<VertexAttribute> attributes;
  std::vector<Range> views;  // The attributes' (without Draco), then the indices'.
  const auto append_view = [&](auto&& append_values) {
    const size_t start = bin.size();
    append_values();
    views.push_back({start, bin.size() - start});
  };
  if (options.draco) {
    TriangleMesh mesh;
    mesh.positions.assign(geometry.positions.begin(), geometry.positions.end());
    mesh.faces.assign(geometry.faces.begin(), geometry.faces.end());
    mesh.colors.assign(geometry.colors.begin(), geometry.colors.end());
    NM_ASSIGN_OR_RETURN(bin, EncodeMeshForGltf(mesh, options.draco_options));
    NM_ASSIGN_OR_RETURN(decoded, DecodeGltfDracoMesh(bin, kGltfDracoPositionId,
                                                     colored ? kGltfDracoColorId : -1));
    positions = decoded.positions;
    faces = decoded.faces;
    views.push_back({0, bin.size()});
    while (bin.size() % 4 != 0) bin.push_back('\0');
    attributes.push_back({"POSITION", kFloat, false, "VEC3", 0});
    if (colored) attributes.push_back({"COLOR_0", kUnsignedShort, true, "VEC3", 8});
  } else {
    attributes.push_back({"POSITION", kFloat, false, "VEC3", 0});
    append_view([&] {
      for (const Vec3f& p : positions) {
        for (float c : p) AppendLittleEndian(c, &bin);
      }
    });
    if (colored) {
      // Three channels and two bytes of padding: vertex attributes are aligned to 4 bytes.
      attributes.push_back({"COLOR_0", kUnsignedShort, true, "VEC3", 8});
      append_view([&] {
        for (const Rgb& color : geometry.colors) {
          for (uint8_t c : color) AppendLittleEndian(LinearShortFromSrgb(c), &bin);
          AppendLittleEndian(uint16_t{0}, &bin);
        }
      });
    }
    if (!geometry.normals.empty()) {
      attributes.push_back({"NORMAL", kFloat, false, "VEC3", 0});
      append_view([&] {
        for (const Vec3f& n : geometry.normals) {
          for (float c : UnitNormal(n)) AppendLittleEndian(c, &bin);
        }
      });
    }
    if (!geometry.weights.empty()) {
      attributes.push_back({kWeightAttribute, kFloat, false, "SCALAR", 0});
      append_view([&] {
        for (float w : geometry.weights) AppendLittleEndian(w, &bin);
      });
    }
  }
  const size_t vertices = positions.size();
  // The largest index of a type is reserved (primitive restart), so 16 bits take 65535 vertices.
  const bool short_indices = vertices <= 65535;
  if (has_faces && !options.draco) {
    append_view([&] {
      for (const std::array<uint32_t, 3>& face : faces) {
        for (uint32_t v : face) {
          if (short_indices) {
            AppendLittleEndian(static_cast<uint16_t>(v), &bin);
          } else {
            AppendLittleEndian(v, &bin);
          }
        }
      }
    });
    while (bin.size() % 4 != 0) bin.push_back('\0');
  }

  std::array<float, 3> low, high;
  low.fill(std::numeric_limits<float>::infinity());
  high.fill(-std::numeric_limits<float>::infinity());
  for (const Vec3f& p : positions) {
    for (int c = 0; c < 3; ++c) {
      low[c] = std::min(low[c], p[c]);
      high[c] = std::max(high[c], p[c]);
    }
  }

  JsonWriter json;
  json.BeginObject();
  json.Key("asset").BeginObject().Key("version").String("2.0");
  json.Key("generator").String(absl::StrCat("neuralmesh ", NeuralmeshVersion())).EndObject();
  if (options.draco) {
    json.Key("extensionsUsed").BeginArray().String(kDracoExtension).EndArray();
    json.Key("extensionsRequired").BeginArray().String(kDracoExtension).EndArray();
  }
  json.Key("scene").Uint(0);
  json.Key("scenes").BeginArray().BeginObject().Key("nodes").BeginArray().Uint(0).EndArray();
  json.EndObject().EndArray();
  json.Key("nodes").BeginArray().BeginObject().Key("mesh").Uint(0);
  if (geometry.has_origin()) {  // Positions relative to an origin: the node puts it back.
    json.Key("translation").BeginArray();
    for (double c : geometry.origin) json.Double(c);
    json.EndArray();
  }
  json.EndObject().EndArray();
  json.Key("materials").BeginArray().BeginObject();
  json.Key("pbrMetallicRoughness").BeginObject().Key("metallicFactor").Double(0);
  json.Key("roughnessFactor").Double(0.8).EndObject();
  json.Key("doubleSided").Bool(true).EndObject().EndArray();

  // Accessor a describes attributes[a] and, without Draco, lies in bufferViews[a]; the indices'
  // accessor and view come last.
  const uint64_t index_accessor = attributes.size();
  json.Key("meshes").BeginArray().BeginObject().Key("primitives").BeginArray().BeginObject();
  json.Key("attributes").BeginObject();
  for (size_t a = 0; a < attributes.size(); ++a) json.Key(attributes[a].semantic).Uint(a);
  json.EndObject();
  if (has_faces) json.Key("indices").Uint(index_accessor);
  json.Key("material").Uint(0);
  json.Key("mode").Uint(has_faces ? kTriangles : kPoints);
  if (options.draco) {
    json.Key("extensions").BeginObject().Key(kDracoExtension).BeginObject();
    json.Key("bufferView").Uint(0).Key("attributes").BeginObject();
    json.Key("POSITION").Uint(kGltfDracoPositionId);
    if (colored) json.Key("COLOR_0").Uint(kGltfDracoColorId);
    json.EndObject().EndObject().EndObject();
  }
  json.EndObject().EndArray().EndObject().EndArray();

  json.Key("accessors").BeginArray();
  for (size_t a = 0; a < attributes.size(); ++a) {
    const VertexAttribute& attribute = attributes[a];
    json.BeginObject();
    if (!options.draco) json.Key("bufferView").Uint(a);
    json.Key("componentType").Uint(attribute.component_type);
    if (attribute.normalized) json.Key("normalized").Bool(true);
    json.Key("count").Uint(vertices).Key("type").String(attribute.type);
    if (a == 0) {  // POSITION needs its bounds.
      json.Key("min").BeginArray();
      for (float c : low) json.Double(c);
      json.EndArray().Key("max").BeginArray();
      for (float c : high) json.Double(c);
      json.EndArray();
    }
    json.EndObject();
  }
  if (has_faces) {
    json.BeginObject();
    if (!options.draco) json.Key("bufferView").Uint(index_accessor);
    json.Key("componentType").Uint(short_indices ? kUnsignedShort : kUnsignedInt);
    json.Key("count").Uint(faces.size() * 3).Key("type").String("SCALAR").EndObject();
  }
  json.EndArray();

  json.Key("bufferViews").BeginArray();
  for (size_t v = 0; v < views.size(); ++v) {
    json.BeginObject().Key("buffer").Uint(0).Key("byteOffset").Uint(views[v].offset);
    json.Key("byteLength").Uint(views[v].length);
    if (!options.draco) {
      const bool is_attribute = v < attributes.size();
      if (is_attribute && attributes[v].stride != 0) {
        json.Key("byteStride").Uint(attributes[v].stride);
      }
      json.Key("target").Uint(is_attribute ? kArrayBuffer : kElementArrayBuffer);
    }
    json.EndObject();
  }
  json.EndArray();

  json.Key("buffers").BeginArray().BeginObject().Key("byteLength").Uint(bin.size());
  if (!options.binary) {
    json.Key("uri").String(
        absl::StrCat("data:application/octet-stream;base64,", absl::Base64Escape(bin)));
  }
  json.EndObject().EndArray();
  json.EndObject();
  NM_ASSIGN_OR_RETURN(std::string text, json.Finish());
  if (!options.binary) return text;

  while (text.size() % 4 != 0) text.push_back(' ');
  const uint64_t total = kGlbHeaderBytes + 2 * kChunkHeaderBytes + text.size() + bin.size();
  if (total > std::numeric_limits<uint32_t>::max()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the mesh takes ", total, " bytes, more than a .glb file can hold (4 GiB)"));
  }
  std::string glb;
  AppendLittleEndian(kGlbMagic, &glb);
  AppendLittleEndian(uint32_t{2}, &glb);
  AppendLittleEndian(static_cast<uint32_t>(total), &glb);
  AppendLittleEndian(static_cast<uint32_t>(text.size()), &glb);
  AppendLittleEndian(kJsonChunkType, &glb);
  glb += text;
  AppendLittleEndian(static_cast<uint32_t>(bin.size()), &glb);
  AppendLittleEndian(kBinChunkType, &glb);
  glb += bin;
  return glb;
}

}  // namespace neuralmesh::io_internal
