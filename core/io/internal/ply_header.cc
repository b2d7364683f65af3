#include "core/io/internal/ply_header.h"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/text.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

bool ParseType(absl::string_view name, PlyType* type) {
  // The PLY 1.0 names and the sized aliases that many writers use.
  static constexpr struct {
    const char* name;
    const char* alias;
    PlyType type;
  } kTypes[] = {{"char", "int8", PlyType::kInt8},        {"uchar", "uint8", PlyType::kUint8},
                {"short", "int16", PlyType::kInt16},     {"ushort", "uint16", PlyType::kUint16},
                {"int", "int32", PlyType::kInt32},       {"uint", "uint32", PlyType::kUint32},
                {"float", "float32", PlyType::kFloat32}, {"double", "float64", PlyType::kFloat64}};
  for (const auto& entry : kTypes) {
    if (name == entry.name || name == entry.alias) {
      *type = entry.type;
      return true;
    }
  }
  return false;
}

constexpr char kTypeNames[] = "char, uchar, short, ushort, int, uint, float, double";

absl::Status ParseProperty(const std::vector<absl::string_view>& tokens, int line,
                           PlyElement* element) {
  PlyProperty property;
  if (tokens.size() >= 2 && tokens[1] == "list") {
    if (tokens.size() != 5) {
      return LineError(line, "expected 'property list <count type> <item type> <name>'");
    }
    property.is_list = true;
    if (!ParseType(tokens[2], &property.count_type) || !IsIntegralPlyType(property.count_type)) {
      return LineError(
          line, absl::StrCat("expected an integer list count type, found ", Quoted(tokens[2])));
    }
    if (!ParseType(tokens[3], &property.type)) {
      return LineError(line, absl::StrCat("unknown property type ", Quoted(tokens[3]),
                                          "; expected one of ", kTypeNames));
    }
    property.name = std::string(tokens[4]);
  } else {
    if (tokens.size() != 3) return LineError(line, "expected 'property <type> <name>'");
    if (!ParseType(tokens[1], &property.type)) {
      return LineError(line, absl::StrCat("unknown property type ", Quoted(tokens[1]),
                                          "; expected one of ", kTypeNames));
    }
    property.name = std::string(tokens[2]);
  }
  element->properties.push_back(std::move(property));
  return absl::OkStatus();
}

}  // namespace

size_t PlyTypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

double LoadPlyValue(const char* p, PlyType type, bool big_endian) {
  switch (type) {
    case PlyType::kInt8:
      return LoadScalar<int8_t>(p, big_endian);
    case PlyType::kUint8:
      return LoadScalar<uint8_t>(p, big_endian);
    case PlyType::kInt16:
      return LoadScalar<int16_t>(p, big_endian);
    case PlyType::kUint16:
      return LoadScalar<uint16_t>(p, big_endian);
    case PlyType::kInt32:
      return LoadScalar<int32_t>(p, big_endian);
    case PlyType::kUint32:
      return LoadScalar<uint32_t>(p, big_endian);
    case PlyType::kFloat32:
      return LoadScalar<float>(p, big_endian);
    case PlyType::kFloat64:
      return LoadScalar<double>(p, big_endian);
  }
  return 0;
}

bool IsIntegralPlyType(PlyType type) {
  return type != PlyType::kFloat32 && type != PlyType::kFloat64;
}

std::pair<double, double> IntegralPlyRange(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
      return {-128, 127};
    case PlyType::kUint8:
      return {0, 255};
    case PlyType::kInt16:
      return {-32768, 32767};
    case PlyType::kUint16:
      return {0, 65535};
    case PlyType::kInt32:
      return {-2147483648.0, 2147483647.0};
    default:
      return {0, 4294967295.0};
  }
}

absl::StatusOr<PlyHeader> ParsePlyHeader(absl::string_view data) {
  LineCursor cursor(data);
  absl::string_view line;
  std::vector<absl::string_view> tokens;
  if (cursor.Next(&line)) SplitWhitespace(line, &tokens);
  if (tokens.size() != 1 || tokens[0] != "ply") {
    return LineError(
        1, absl::StrCat("not a PLY file: expected 'ply', found ", Quoted(line.substr(0, 16))));
  }
  PlyHeader header;
  bool have_format = false;
  while (cursor.Next(&line)) {
    const int n = cursor.line_number();
    SplitWhitespace(line, &tokens);
    if (tokens.empty()) continue;
    const absl::string_view key = tokens[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (tokens.size() != 3) return LineError(n, "expected 'format <kind> 1.0'");
      if (tokens[1] == "ascii") {
        header.format = PlyFormat::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        header.format = PlyFormat::kBinaryLittleEndian;
      } else if (tokens[1] == "binary_big_endian") {
        header.format = PlyFormat::kBinaryBigEndian;
      } else {
        return LineError(n, absl::StrCat("unknown PLY format ", Quoted(tokens[1]),
                                         "; expected ascii, binary_little_endian or "
                                         "binary_big_endian"));
      }
      if (tokens[2] != "1.0") {
        return LineError(
            n, absl::StrCat("unsupported PLY version ", Quoted(tokens[2]), "; expected 1.0"));
      }
      have_format = true;
    } else if (key == "element") {
      int64_t count = -1;
      if (tokens.size() != 3 || !ParseInt64(tokens[2], &count) || count < 0) {
        return LineError(n, "expected 'element <name> <non-negative count>'");
      }
      header.elements.push_back({std::string(tokens[1]), static_cast<uint64_t>(count), {}, n});
    } else if (key == "property") {
      if (header.elements.empty()) return LineError(n, "'property' before any 'element'");
      NM_RETURN_IF_ERROR(ParseProperty(tokens, n, &header.elements.back()));
    } else if (key == "end_header") {
      if (!have_format) return LineError(n, "the header has no 'format' line");
      header.body_offset = cursor.offset();
      header.body_line = n + 1;
      return header;
    } else {
      return LineError(n, absl::StrCat("unexpected header keyword ", Quoted(key),
                                       "; expected format, element, property, comment or "
                                       "end_header"));
    }
  }
  return LineError(cursor.line_number(), "the header has no 'end_header' line");
}

// Reads values from a binary body. Every read is bounds-checked against the data.
}  // namespace neuralmesh::io_internal
