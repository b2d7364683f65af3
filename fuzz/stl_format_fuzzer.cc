// The STL parser (core/io/internal/stl.h) against the properties of
// fuzz/geometry_parser_properties.h. STL has no writer round trip here: it holds triangles only,
// so the vertices that no face uses are lost by design.
#include <cstddef>
#include <cstdint>

#include "core/io/internal/stl.h"
#include "fuzz/geometry_parser_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const neuralmesh::fuzz::GeometryFormat stl{
      [](absl::string_view text, neuralmesh::io_internal::FaceHandling,
         neuralmesh::io_internal::PositionPrecision) {
        return neuralmesh::io_internal::ParseStl(text);
      },
      nullptr, /*skips_faces=*/false};
  neuralmesh::fuzz::CheckGeometryParser(stl, data, size);
  return 0;
}
