// The header of a PLY file (Turk 1994): format, elements, and their typed properties.
#ifndef NEURALMESH_CORE_IO_INTERNAL_PLY_HEADER_H_
#define NEURALMESH_CORE_IO_INTERNAL_PLY_HEADER_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::io_internal {

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // The item type of a list.
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
  int line = 0;  // Where the header declares it.
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;  // First byte after the end_header line.
  int body_line = 0;       // Number of the first line after end_header.
};

// Size in bytes of one value of `type` in a binary body.
size_t PlyTypeSize(PlyType type);

// One value of `type` stored at `p` in a binary body, in that byte order, as a double.
double LoadPlyValue(const char* p, PlyType type, bool big_endian);

// True for the integer types.
bool IsIntegralPlyType(PlyType type);

// The smallest and largest value of an integer type.
std::pair<double, double> IntegralPlyRange(PlyType type);

// Parses the header at the start of `data`, from "ply" to "end_header".
// Returns INVALID_ARGUMENT "line N: ..." for a missing magic word, an unknown format, version,
// keyword or type, a malformed element or property line, or a missing format or end_header.
absl::StatusOr<PlyHeader> ParsePlyHeader(absl::string_view data);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_PLY_HEADER_H_
