// The Object File Format (OFF) of Geomview, with its COFF, NOFF and STOFF variants.
#ifndef NEURALMESH_CORE_IO_INTERNAL_OFF_H_
#define NEURALMESH_CORE_IO_INTERNAL_OFF_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/position_collector.h"

namespace neuralmesh::io_internal {

// Parses an ASCII OFF file: a keyword ([ST][C][N]OFF), the counts "vertices faces [edges]"
// (on the keyword line or the next), one vertex per line ("x y z", then "nx ny nz" for NOFF,
// then for COFF "r g b [a]", integers 0-255 or fractions 0-1, kept when every vertex has them;
// texture coordinates are ignored), then with FaceHandling::kRead one
// polygon per line ("n i_1 ... i_n [color]", 0-based), fan-triangulated. '#' starts a comment.
// Returns INVALID_ARGUMENT "line N: ..." for a bad keyword or count, a malformed or missing
// vertex or face line, a non-finite coordinate or an out-of-range index.
// Positions are kept as `precision` says until the origin is known (position_collector.h).
absl::StatusOr<ParsedGeometry> ParseOff(absl::string_view data, FaceHandling faces,
                                        PositionPrecision precision = PositionPrecision::kExact);

// Formats the positions (with geometry.origin added: AppendCoordinate) and faces of `geometry`
// as ASCII OFF, or COFF ("x y z r g b 255") when it has colours.
std::string FormatOff(const GeometryView& geometry);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_OFF_H_
