// ASPRS LAS 1.0-1.4 point clouds (.las), the exchange format of airborne and terrestrial LiDAR:
// a header, then fixed-size point records of formats 0 to 10.
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAS_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAS_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"

namespace neuralmesh::io_internal {

// Parses a LAS file: the positions of its point records (integer X, Y, Z times the header's
// scale, plus its offset; withheld records and those classified as noise, ASPRS classes 7 and
// 18, left out and counted in ParsedGeometry::left_out) and, for the formats that carry them
// (2, 3, 5, 7, 8, 10), their colours (16-bit channels scaled to 8 bits, or taken as they are
// when no channel of the file exceeds 255, as some writers store 8-bit values). Positions are
// floats, relative to ParsedGeometry::origin where the file's coordinates are too far from 0
// for a float to keep its resolution, the scale (georeferenced data such as UTM:
// OriginKeepingResolution in position_collector.h).
// Returns INVALID_ARGUMENT saying what is wrong for a file without the "LASF" signature, a
// header or records that run past the end of the file, a compressed (LAZ) file, a point
// format above 10, a record shorter than its format, a zero or non-finite scale, or a point
// count that does not fit the file, or points that are all withheld or noise.
absl::StatusOr<ParsedGeometry> ParseLas(absl::string_view data);

// Formats points as a LAS 1.2 file of point format 0, or 2 with their colours (8-bit levels
// times 257 in the 16-bit channels), without variable-length records. The header's offset is
// points.origin; each axis's scale is the power of ten at most 1/2^24 of the farthest
// coordinate from that origin (1e-8 for a unit sphere, 1e-5 for a UTM tile of 1,000 m), so the
// integers keep what the floats hold to half a scale step. Records say return 1 of 1, class 0
// (never classified), intensity 0; the creation date is left zero, so the same points give the
// same bytes. Normals and weights have no place in these formats and are not written.
// Returns INVALID_ARGUMENT for more points than LAS 1.2 counts (2^32 - 1).
absl::StatusOr<std::string> FormatLas(const GeometryView& points);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAS_H_
