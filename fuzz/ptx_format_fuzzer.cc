// The PTX parser (core/io/internal/ptx.h) against the properties of
// fuzz/geometry_parser_properties.h. PTX has no writer here: the project reads scans from it.
#include <cstddef>
#include <cstdint>

#include "core/io/internal/ptx.h"
#include "fuzz/geometry_parser_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const neuralmesh::fuzz::GeometryFormat ptx{
      [](absl::string_view text, neuralmesh::io_internal::FaceHandling) {
        return neuralmesh::io_internal::ParsePtx(text);
      },
      nullptr, /*skips_faces=*/false};
  neuralmesh::fuzz::CheckGeometryParser(ptx, data, size);
  return 0;
}
