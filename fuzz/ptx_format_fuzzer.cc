// The PTX parser and writer (core/io/internal/ptx.h) against the properties of
// fuzz/geometry_parser_properties.h: a parsed file written again (one scan, the points in
// their registered frame) reads back to the same points and colours.
#include <cstddef>
#include <cstdint>

#include "core/io/internal/ptx.h"
#include "fuzz/geometry_parser_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const neuralmesh::fuzz::GeometryFormat ptx{
      [](absl::string_view text, neuralmesh::io_internal::FaceHandling,
         neuralmesh::io_internal::PositionPrecision precision) {
        return neuralmesh::io_internal::ParsePtx(text, precision);
      },
      neuralmesh::io_internal::FormatPtx, /*skips_faces=*/false,
      /*writes_normals_and_weights=*/false};
  neuralmesh::fuzz::CheckGeometryParser(ptx, data, size);
  return 0;
}
