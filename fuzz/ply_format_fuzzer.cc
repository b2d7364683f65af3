// The PLY parser and writer (core/io/internal/ply.h) against the properties of
// fuzz/geometry_parser_properties.h, and the vertices as off-core sampling reads them
// (ply_vertex_records.h) against fuzz/point_records_properties.h.
#include <cstddef>
#include <cstdint>

#include "core/io/internal/ply.h"
#include "core/io/internal/ply_vertex_records.h"
#include "fuzz/geometry_parser_properties.h"
#include "fuzz/point_records_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  neuralmesh::fuzz::CheckGeometryParser(
      {neuralmesh::io_internal::ParsePly, neuralmesh::io_internal::FormatPly}, data, size);
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  const auto records = neuralmesh::io_internal::PlyVertexRecords(bytes);
  if (!records.ok()) return 0;
  const auto parsed =
      neuralmesh::io_internal::ParsePly(bytes, neuralmesh::io_internal::FaceHandling::kSkip);
  neuralmesh::fuzz::CheckRecordsAgreeWithParser(**records, parsed.ok() ? &*parsed : nullptr);
  return 0;
}
