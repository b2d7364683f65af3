// Plain-text point lists (.xyz, .txt, .pts): one point per line.
#ifndef NEURALMESH_CORE_IO_INTERNAL_XYZ_H_
#define NEURALMESH_CORE_IO_INTERNAL_XYZ_H_

#include <array>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/position_collector.h"

namespace neuralmesh::io_internal {

// Parses points, one per line, their numbers separated by whitespace, commas or semicolons,
// the same number of columns on every line;
// '#' starts a comment, a line that starts with "//" is one; blank lines are skipped; a first
// line holding one integer (the point count of .pts files) is skipped.
//
// The columns are x, y, z, then what a header says they are: the last comment line before the
// first point whose names (separated by spaces or commas, any case) are as many as the
// columns and begin with x, y, z ("# x y z nx ny nz r g b w", CloudCompare's "//X,Y,Z,R,G,B").
// Names read: nx ny nz (or normal_x ...), r g b (or red green blue), w (or weight,
// confidence); any other column (intensity, a scalar field) is skipped, as is a normal or
// colour of fewer than three channels. Without a header, by their count and values:
//   3  x y z
//   4  x y z w
//   6  x y z nx ny nz, or x y z r g b when the last three are colours and not normals
//   7  x y z nx ny nz w, or x y z i r g b (Leica PTS, Semantic3D: i, the intensity, is
//      skipped) when columns 5-7 are colours and columns 4-6 not normals
//   9  x y z nx ny nz r g b or x y z r g b nx ny nz, told apart by which three are normals
// Three columns are normals when each row's length is within 10% of 1 (or 0), and colours
// when every value is an integer from 0 to 255 or every value is from 0 to 1 (then fractions).
// Colours are 0-255 levels unless every channel of the file is at most 1 (the OBJ rule).
// Returns INVALID_ARGUMENT "line N: ..." for a value that is not a number, a line whose column
// count differs from the first point's, a non-finite value, or a column count that neither a
// header nor the list above explains.
// Positions are kept as `precision` says until the origin is known (position_collector.h).
absl::StatusOr<ParsedGeometry> ParseXyz(absl::string_view data,
                                        PositionPrecision precision = PositionPrecision::kExact);

// Which columns of a line hold each attribute (-1: none).
struct XyzLayout {
  std::array<int, 3> normal = {-1, -1, -1};
  std::array<int, 3> color = {-1, -1, -1};
  int weight = -1;
};

// The layout that a header comment's text `text` (XyzCommentText) gives lines of `columns`
// values, as ParseXyz reads it; nullopt when it is not a header of that many columns beginning
// with x, y, z.
std::optional<XyzLayout> XyzLayoutFromHeader(absl::string_view text, size_t columns);

// The text of a comment line ("# ..." or "// ..."), or nullopt for a line that is not one.
std::optional<absl::string_view> XyzCommentText(absl::string_view line);

// Formats `geometry` as "x y z [nx ny nz] [r g b] [w]" lines (positions with geometry.origin
// added: AppendCoordinate; colours as 0-255 levels, or as
// fractions when no channel is above 1), after a header comment naming the columns when there
// are normals or colours.
std::string FormatXyz(const GeometryView& geometry);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_XYZ_H_
