// The common currency of the format readers and writers: what a reader extracts from a file
// before it becomes a TriangleMesh or a PointCloud, and a non-owning view that writers format.
#ifndef NEURALMESH_CORE_IO_INTERNAL_GEOMETRY_DATA_H_
#define NEURALMESH_CORE_IO_INTERNAL_GEOMETRY_DATA_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/types/span.h"
#include "core/mesh.h"
#include "core/point_cloud.h"
#include "core/rgb.h"

namespace neuralmesh::io_internal {

// Whether a reader parses faces (for a mesh) or skips them (for a point cloud). Skipped faces
// are not validated, so a point cloud can be read from a file with broken faces.
enum class FaceHandling { kSkip, kRead };

struct ParsedGeometry {
  std::vector<Vec3f> positions;                // All finite.
  std::vector<Vec3f> normals;                  // Empty or one per position.
  std::vector<float> weights;                  // Empty or one per position.
  std::vector<Rgb> colors;                     // Empty or one per position.
  std::vector<std::array<uint32_t, 3>> faces;  // Polygons fan-triangulated; indices in range.
  // The positions are relative to this point: readers move georeferenced data there to keep a
  // float's resolution (position_collector.h); zero for most files.
  Origin origin = kNoOrigin;
  // Points the file marks as not to be used, which the reader left out.
  PointsLeftOut left_out;
  // Set, with no positions, by a reader given PositionPrecision::kFloatsNearZero when the
  // floats it kept are not those the origin needs: read the file again with kExact.
  bool read_again_exactly = false;
};

struct GeometryView {
  absl::Span<const Vec3f> positions;
  absl::Span<const Vec3f> normals;  // Empty or one per position.
  absl::Span<const float> weights;  // Empty or one per position.
  absl::Span<const std::array<uint32_t, 3>> faces;
  absl::Span<const Rgb> colors;  // Empty or one per position.
  // The positions are relative to this point; writers put it back where the format can hold
  // it (coordinates in double or as text, a glTF node's translation, Draco metadata).
  Origin origin = kNoOrigin;

  bool has_origin() const { return origin != kNoOrigin; }
};

// Appends position `i` of `geometry` as the binary formats hold it (PLY, PCD), little-endian:
// three floats, or with an origin three doubles with the origin put back.
void AppendPosition(const GeometryView& geometry, size_t i, std::string* out);
// Coordinate `c` of that position.
void AppendPositionCoordinate(const GeometryView& geometry, size_t i, int c, std::string* out);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_GEOMETRY_DATA_H_
