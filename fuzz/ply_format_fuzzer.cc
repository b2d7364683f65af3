// The PLY parser and writer (core/io/internal/ply.h) against the properties of
// fuzz/geometry_parser_properties.h.
#include <cstddef>
#include <cstdint>

#include "core/io/internal/ply.h"
#include "fuzz/geometry_parser_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  neuralmesh::fuzz::CheckGeometryParser(
      {neuralmesh::io_internal::ParsePly, neuralmesh::io_internal::FormatPly}, data, size);
  return 0;
}
