#include "core/io/internal/geometry_data.h"

#include "core/io/internal/binary.h"

namespace neuralmesh::io_internal {

void AppendPosition(const GeometryView& geometry, size_t i, std::string* out) {
  for (int c = 0; c < 3; ++c) {
    if (geometry.has_origin()) {
      AppendLittleEndian(geometry.origin[c] + double{geometry.positions[i][c]}, out);
    } else {
      AppendLittleEndian(geometry.positions[i][c], out);
    }
  }
}

}  // namespace neuralmesh::io_internal
