// The Point Cloud Data format of the Point Cloud Library (PCL) and Open3D (.pcd, versions 0.5
// to 0.7): a text header naming the fields of each point, then the points as ASCII lines, as
// binary records, or LZF-compressed field by field (binary_compressed).
#ifndef NEURALMESH_CORE_IO_INTERNAL_PCD_H_
#define NEURALMESH_CORE_IO_INTERNAL_PCD_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/point_records.h"
#include "core/io/internal/position_collector.h"
#include "core/io/point_cloud_io.h"

namespace neuralmesh::io_internal {

// Parses a PCD file: x, y, z (any numeric type; double ones keep georeferenced coordinates,
// read relative to an origin as position_collector.h says), normal_x, normal_y, normal_z when
// all three are there, colours from rgb or rgba (PCL's packed 0x00RRGGBB, stored as a float or
// an unsigned integer), and as weights the first of confidence, weight or quality (not
// intensity, which a LiDAR scanner's return strength is, not a confidence). Every other field
// (curvature, intensity, descriptors of COUNT > 1, "_" padding) is skipped. Points without a
// position (NaN or infinite x, y or z: the empty pixels of an organized cloud) are left out
// and counted in ParsedGeometry::left_out.invalid. Data of all three kinds, little-endian.
// Returns INVALID_ARGUMENT naming the header line or the point and what is wrong for a
// malformed or inconsistent header (FIELDS, SIZE, TYPE and COUNT of different lengths, a
// SIZE other than 1, 2, 4 or 8, WIDTH x HEIGHT other than POINTS, no x, y or z), points that
// run past the end of the data, a malformed value, compressed data that do not decompress to
// their stated size, or a file whose points all lack a position.
// Positions are kept as `precision` says until the origin is known (position_collector.h).
absl::StatusOr<ParsedGeometry> ParsePcd(absl::string_view data,
                                        PositionPrecision precision = PositionPrecision::kExact);

// The points of a PCD file with binary data as point records read where they lie
// (point_records.h), for off-core sampling: their x, y and z as ParsePcd reads them, the points
// ParsePcd leaves out (no position: NaN or beyond a float's range) not kept. No resolution or
// bounds are stated. `data` must outlive the result. Returns ParsePcd's errors for a malformed
// header or points that run past the end of the data, and INVALID_ARGUMENT, saying why, for
// ASCII and binary_compressed data (no point can be found without reading those before).
absl::StatusOr<std::unique_ptr<PointRecords>> PcdPointRecords(absl::string_view data);

// Formats points as a PCD 0.7 file that PCL and Open3D read: FIELDS x y z (float, or double
// with geometry.origin added when the origin is not zero, as PLY does: PCD has no offset),
// then normal_x normal_y normal_z, rgb (PCL's packed colour: a float's bits in binary data, the
// integer in ASCII, as PCL 1.9 and later write it) and confidence as present; WIDTH the
// points, HEIGHT 1 (unorganized). `data` is the DATA line: binary records, the same values
// field by field and LZF-compressed (binary_compressed), or ASCII lines with floats in as few
// digits as give them back. Faces are not written.
// Returns INVALID_ARGUMENT for binary_compressed data of 4 GiB or more, whose sizes PCD
// stores in 32 bits.
absl::StatusOr<std::string> FormatPcd(const GeometryView& geometry,
                                      PcdData data = PcdData::kBinary);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_PCD_H_
