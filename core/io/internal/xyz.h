// Plain-text point lists (.xyz, .txt, .pts): one point per line.
#ifndef NEURALMESH_CORE_IO_INTERNAL_XYZ_H_
#define NEURALMESH_CORE_IO_INTERNAL_XYZ_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"

namespace neuralmesh::io_internal {

// Parses whitespace-separated points, one per line: "x y z", "x y z w", "x y z nx ny nz" or
// "x y z nx ny nz w" (w is the weight), the same layout on every line. '#' starts a comment;
// blank lines are skipped; a first line holding one integer (the point count of .pts files)
// is skipped.
// Returns INVALID_ARGUMENT "line N: ..." for a value that is not a number, a line whose column
// count differs from 3, 4, 6 or 7 or from the first point's, or a non-finite value.
absl::StatusOr<ParsedGeometry> ParseXyz(absl::string_view data);

// Formats `geometry` as "x y z [nx ny nz] [w]" lines.
std::string FormatXyz(const GeometryView& geometry);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_XYZ_H_
