// The PLY format (Turk 1994): ASCII, binary little-endian and binary big-endian bodies.
#ifndef NEURALMESH_CORE_IO_INTERNAL_PLY_H_
#define NEURALMESH_CORE_IO_INTERNAL_PLY_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/ply_header.h"
#include "core/io/internal/position_collector.h"

namespace neuralmesh::io_internal {

// Parses a PLY file held in `data`. Reads the 'vertex' element's x, y, z (any scalar type),
// nx, ny, nz when all three are present, and as weights the first scalar property named
// confidence, weight, quality, intensity or scalar (case-insensitive), and colours from red,
// green, blue (or r, g, b, or diffuse_red, ...): integer types as levels of their range
// (uchar 0-255, ushort 0-65535), floating ones as fractions from 0 to 1. With FaceHandling::kRead
// the 'face' element's 'vertex_indices' (or 'vertex_index') lists are fan-triangulated.
// Every other element and property, lists included, is skipped.
// Returns INVALID_ARGUMENT naming the line (header, ASCII body) or byte offset (binary body) and
// what was expected, for a malformed header, a count larger than the remaining data could
// hold, missing or malformed values, non-finite coordinates or out-of-range face indices.
// Positions are kept as `precision` says until the origin is known (position_collector.h).
absl::StatusOr<ParsedGeometry> ParsePly(absl::string_view data, FaceHandling faces,
                                        PositionPrecision precision = PositionPrecision::kExact);

// Which properties of the 'vertex' element ParsePly reads as x, y and z, and as red, green and
// blue (their indices; the channels -1 when it reads no colours), with each channel's full
// scale as ParsePly takes it (an integer type's largest value, 1 for floating point).
// INVALID_ARGUMENT "line N: ..." when x, y or z is missing.
struct PlyVertexLayout {
  int axes[3] = {-1, -1, -1};
  int channels[3] = {-1, -1, -1};
  double channel_scales[3] = {1, 1, 1};
  bool has_colors() const { return channels[0] >= 0; }
};
absl::StatusOr<PlyVertexLayout> FindPlyVertexLayout(const PlyElement& vertex);

// Formats `geometry` as binary little-endian PLY: float x, y, z (double, with geometry.origin
// added, when the origin is not zero), then float nx, ny, nz, a float
// 'confidence' and uchar red, green, blue when present, and a 'face' element (uchar count,
// uint indices) when there are faces.
std::string FormatPly(const GeometryView& geometry);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_PLY_H_
