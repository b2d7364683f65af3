#include "core/io/internal/geometry_data.h"

#include "core/io/internal/binary.h"

namespace neuralmesh::io_internal {

void AppendPositionCoordinate(const GeometryView& geometry, size_t i, int c, std::string* out) {
  const float local = geometry.positions[i][c];
  if (!geometry.has_origin()) {
    AppendLittleEndian(local, out);
  } else if (geometry.origin[c] == 0) {
    AppendLittleEndian(double{local}, out);  // Keeps -0, which 0 + -0 would not.
  } else {
    AppendLittleEndian(geometry.origin[c] + double{local}, out);
  }
}

void AppendPosition(const GeometryView& geometry, size_t i, std::string* out) {
  for (int c = 0; c < 3; ++c) AppendPositionCoordinate(geometry, i, c, out);
}

}  // namespace neuralmesh::io_internal
