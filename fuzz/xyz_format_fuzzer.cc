// The XYZ point-list parser and writer (core/io/internal/xyz.h) against the properties of
// fuzz/geometry_parser_properties.h.
#include <cstddef>
#include <cstdint>

#include "core/io/internal/xyz.h"
#include "fuzz/geometry_parser_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const neuralmesh::fuzz::GeometryFormat xyz{
      [](absl::string_view text, neuralmesh::io_internal::FaceHandling,
         neuralmesh::io_internal::PositionPrecision precision) {
        return neuralmesh::io_internal::ParseXyz(text, precision);
      },
      neuralmesh::io_internal::FormatXyz, /*skips_faces=*/false};
  neuralmesh::fuzz::CheckGeometryParser(xyz, data, size);
  return 0;
}
