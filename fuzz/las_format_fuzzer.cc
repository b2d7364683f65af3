// The LAS parser (core/io/internal/las.h) against the properties of
// fuzz/geometry_parser_properties.h. LAS has no writer here: the project reads scans from it.
#include <cstddef>
#include <cstdint>

#include "core/io/internal/las.h"
#include "fuzz/geometry_parser_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const neuralmesh::fuzz::GeometryFormat las{
      [](absl::string_view bytes, neuralmesh::io_internal::FaceHandling) {
        return neuralmesh::io_internal::ParseLas(bytes);
      },
      nullptr, /*skips_faces=*/false};
  neuralmesh::fuzz::CheckGeometryParser(las, data, size);
  return 0;
}
