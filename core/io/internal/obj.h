// The Wavefront OBJ format: 'v' and 'f' lines.
#ifndef NEURALMESH_CORE_IO_INTERNAL_OBJ_H_
#define NEURALMESH_CORE_IO_INTERNAL_OBJ_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/position_collector.h"

namespace neuralmesh::io_internal {

// Parses the 'v x y z [w | r g b]' lines of an OBJ file (colours, kept when every vertex has
// one, are fractions when no channel in the file exceeds 1, else 0-255 levels), and with
// FaceHandling::kRead the 'f' lines (references v, v/vt, v/vt/vn or v//vn; 1-based, or
// negative to count back from the last vertex so far), fan-triangulating polygons. 'vn',
// 'vt', groups, materials and other statements are ignored, as is anything after '#'.
// Returns INVALID_ARGUMENT "line N: ..." for a malformed 'v' or 'f' line, a non-finite
// coordinate, or a face index that is 0 or out of range.
// Positions are kept as `precision` says until the origin is known (position_collector.h).
absl::StatusOr<ParsedGeometry> ParseObj(absl::string_view data, FaceHandling faces,
                                        PositionPrecision precision = PositionPrecision::kExact);

// Formats the positions (with geometry.origin added: AppendCoordinate), colours (as fractions,
// 'v x y z r g b') and faces of `geometry` as OBJ text.
std::string FormatObj(const GeometryView& geometry);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_OBJ_H_
