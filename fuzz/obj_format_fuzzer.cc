// The OBJ parser and writer (core/io/internal/obj.h) against the properties of
// fuzz/geometry_parser_properties.h.
#include <cstddef>
#include <cstdint>

#include "core/io/internal/obj.h"
#include "fuzz/geometry_parser_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The writer keeps positions and faces only.
  neuralmesh::fuzz::CheckGeometryParser(
      {neuralmesh::io_internal::ParseObj, neuralmesh::io_internal::FormatObj, /*skips_faces=*/true,
       /*writes_normals_and_weights=*/false},
      data, size);
  return 0;
}
