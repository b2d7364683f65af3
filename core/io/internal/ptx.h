// Leica's PTX format (.ptx), the export of terrestrial laser scanners (Cyclone, Register 360,
// CloudCompare): one or more scans, each a text header (columns, rows, the scanner's position
// and axes, a 4x4 transformation) followed by its grid of points, one a line.
#ifndef NEURALMESH_CORE_IO_INTERNAL_PTX_H_
#define NEURALMESH_CORE_IO_INTERNAL_PTX_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/position_collector.h"

namespace neuralmesh::io_internal {

// Parses a PTX file: every scan's points ("x y z intensity" or "x y z intensity r g b"; "x y z"
// too), moved by the scan's transformation (its four lines are the columns of the matrix: the
// last one the translation) into the registered frame, relative to an origin where that frame
// is georeferenced (position_collector.h); colours when every point of the file has them.
// Intensity is not read. The grid's empty cells (x, y and z all zero) are left out and counted
// in ParsedGeometry::left_out.invalid.
// Returns INVALID_ARGUMENT naming the line and what was expected for a malformed header (the
// columns and rows, three numbers on each of the next four lines, four on the four after),
// a non-finite transformation, a point line of another number of values or with a value that
// is not a number, a scan that ends before its columns x rows points, or a file whose points
// are all empty cells.
// Positions are kept as `precision` says until the origin is known (position_collector.h).
absl::StatusOr<ParsedGeometry> ParsePtx(absl::string_view data,
                                        PositionPrecision precision = PositionPrecision::kExact);

// Formats points as a PTX file of one scan: as many columns as points, of one row each,
// "x y z intensity" per point, or "x y z intensity r g b" with colours (0-255 levels). The
// coordinates are written as AppendCoordinate writes them (text.h), the origin put back. The
// intensity, which the points do not carry, is 0.5 throughout. The scanner stands at the
// registered frame's origin with its axes, and the transformation is the identity. A point at
// (0, 0, 0), which PTX reserves for an empty cell of the grid, goes instead to a scan of its
// own (with those next to it), translated by 1 in x, in which it lies at (-1, 0, 0); so the
// points read back in their order. Normals and weights have no place in PTX and are not
// written.
std::string FormatPtx(const GeometryView& points);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_PTX_H_
