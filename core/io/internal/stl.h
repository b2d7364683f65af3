// The STL format: binary and ASCII triangle soups.
#ifndef NEURALMESH_CORE_IO_INTERNAL_STL_H_
#define NEURALMESH_CORE_IO_INTERNAL_STL_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"

namespace neuralmesh::io_internal {

// Parses a binary or ASCII STL file and merges vertices with identical positions (0 and -0
// count as equal), so that triangles share vertices. A file whose size is exactly
// 84 + 50 * (its triangle count) is binary; otherwise one starting with "solid" is ASCII.
// Returns INVALID_ARGUMENT with the byte offset (binary) or line (ASCII) for a size that does
// not match the triangle count, a malformed facet, or a non-finite coordinate.
absl::StatusOr<ParsedGeometry> ParseStl(absl::string_view data);

// Formats the positions and faces of `geometry` as binary STL, with unit facet normals (zero
// for degenerate triangles). STL holds floats: positions stay relative to geometry.origin.
std::string FormatStl(const GeometryView& geometry);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_STL_H_
