// ASTM E57 files (.e57), the vendor-neutral exchange format of terrestrial laser scanners
// (Leica, FARO, Trimble, Riegl export it; CloudCompare, PDAL and libE57Format read it): paged
// binary data with checksums (e57_pages.h), an XML tree that describes the scans, and each
// scan's points as a compressed vector of bit-packed fields.
#ifndef NEURALMESH_CORE_IO_INTERNAL_E57_H_
#define NEURALMESH_CORE_IO_INTERNAL_E57_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/position_collector.h"

namespace neuralmesh::io_internal {

// Parses an E57 file: the points of every scan (data3D), from cartesian coordinates or, in a
// scan without them, spherical ones (range, azimuth, elevation), moved by the scan's pose
// (rotation quaternion and translation) into the file's common frame, relative to an origin
// where that frame is georeferenced (position_collector.h). Colours are kept when every scan
// has them, scaled from the scan's colour limits (or the fields' own) to 8 bits; normals when
// every scan has the surface-normals extension's normalX, normalY and normalZ, turned by the
// pose. Fields stored as Integer, ScaledInteger or Float are decoded; intensity, time stamps
// and row and column indices are not read. Points whose invalid state is not 0 (no position,
// or a direction only) are left out and counted in ParsedGeometry::left_out.invalid; a point
// whose isColorInvalid is set keeps its position, and the file's colours are all dropped.
// Returns INVALID_ARGUMENT saying what is wrong for a file without the "ASTM-E57" signature, of
// another major version or page size, damaged (a checksum that does not match, offsets or
// lengths beyond the file), with malformed XML or a missing element the standard requires, a
// scan whose packets do not hold its records or the fields its prototype declares, a value
// beyond its field's limits, or points all marked invalid.
// Positions are kept as `precision` says until the origin is known (position_collector.h).
absl::StatusOr<ParsedGeometry> ParseE57(absl::string_view data,
                                        PositionPrecision precision = PositionPrecision::kExact);

// Formats points as an E57 file of one scan, as libE57Format lays one out: the coordinates as
// ScaledInteger fields whose offset is points.origin and whose scale, per axis, is that of
// IntegerScaleKeepingFloats (so the integers keep what the floats hold to half a scale step),
// bit-packed in as few bits as their range needs; colours as 8-bit Integer fields; normals as
// single-precision Float fields of the surface-normals extension ("nor:normalX"). E57 has no
// place for weights; they are not written. The file's GUIDs are derived from its contents, so
// the same points give the same bytes.
std::string FormatE57(const GeometryView& points);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_E57_H_
