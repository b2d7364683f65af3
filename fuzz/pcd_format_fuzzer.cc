// The PCD parser and writer (core/io/internal/pcd.h) against the properties of
// fuzz/geometry_parser_properties.h: ascii, binary and LZF-compressed (binary_compressed)
// data, headers of every field type; what is parsed is written back in each of the three
// kinds of data (LzfCompress included) and must read back bit for bit. Binary points as
// off-core sampling reads them (PcdPointRecords) agree with the parser
// (fuzz/point_records_properties.h).
#include <cstddef>
#include <cstdint>

#include "core/io/internal/pcd.h"
#include "fuzz/geometry_parser_properties.h"
#include "fuzz/point_records_properties.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  for (const neuralmesh::PcdData kind :
       {neuralmesh::PcdData::kBinary, neuralmesh::PcdData::kBinaryCompressed,
        neuralmesh::PcdData::kAscii}) {
    const neuralmesh::fuzz::GeometryFormat pcd{
        [](absl::string_view bytes, neuralmesh::io_internal::FaceHandling,
           neuralmesh::io_internal::PositionPrecision precision) {
          return neuralmesh::io_internal::ParsePcd(bytes, precision);
        },
        [kind](const neuralmesh::io_internal::GeometryView& geometry) {
          return neuralmesh::io_internal::FormatPcd(geometry, kind).value();
        },
        /*skips_faces=*/false};
    neuralmesh::fuzz::CheckGeometryParser(pcd, data, size);
  }
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  const auto records = neuralmesh::io_internal::PcdPointRecords(bytes);
  if (!records.ok()) return 0;
  const auto parsed = neuralmesh::io_internal::ParsePcd(bytes);
  neuralmesh::fuzz::CheckRecordsAgreeWithParser(**records, parsed.ok() ? &*parsed : nullptr);
  return 0;
}
