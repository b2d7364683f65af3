// The E57 parser and writer (core/io/internal/e57.h) against the properties of
// fuzz/geometry_parser_properties.h, and the writer's own: a parsed file written again reads
// back to the same number of points, each within half the written scale (and a float's
// rounding) of where it was, with the same colours and normals. The generic round trip, bit for
// bit, does not apply: E57 stores the coordinates as scaled integers.
// Every page of a file ends in a checksum, so nearly every mutation would stop at the first
// check: each input is parsed as it is and, when it is a whole number of pages, once more with
// its checksums recomputed, so that mutations reach the XML, the sections and the packets.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/io/internal/e57.h"
#include "core/io/internal/e57_pages.h"
#include "core/io/internal/position_collector.h"
#include "fuzz/fuzz_check.h"
#include "fuzz/geometry_parser_properties.h"

namespace {

using neuralmesh::io_internal::GeometryView;
using neuralmesh::io_internal::ParsedGeometry;

void CheckWrittenAgain(const ParsedGeometry& parsed) {
  const GeometryView view{parsed.positions, parsed.normals, {}, {}, parsed.colors, parsed.origin};
  const std::string written = neuralmesh::io_internal::FormatE57(view);
  const absl::StatusOr<ParsedGeometry> reread = neuralmesh::io_internal::ParseE57(written);
  FUZZ_CHECK(reread.ok(), "the writer's output does not parse: %s",
             reread.status().ToString().c_str());
  std::array<double, 3> scale;
  for (int c = 0; c < 3; ++c) {
    double farthest = 0;
    for (const auto& p : parsed.positions) farthest = std::max<double>(farthest, std::fabs(p[c]));
    scale[c] = neuralmesh::io_internal::IntegerScaleKeepingFloats(farthest);
  }
  neuralmesh::fuzz::CheckPositionsWithinScale(parsed, *reread, scale);
  FUZZ_CHECK(reread->colors == parsed.colors, "colours change when written and read back");
  FUZZ_CHECK(reread->normals == parsed.normals, "normals change when written and read back");
}

void CheckFile(absl::string_view bytes) {
  const neuralmesh::fuzz::GeometryFormat e57{
      [](absl::string_view file, neuralmesh::io_internal::FaceHandling,
         neuralmesh::io_internal::PositionPrecision precision) {
        return neuralmesh::io_internal::ParseE57(file, precision);
      },
      nullptr, /*skips_faces=*/false};
  neuralmesh::fuzz::CheckGeometryParser(e57, reinterpret_cast<const uint8_t*>(bytes.data()),
                                        bytes.size());
  const absl::StatusOr<ParsedGeometry> parsed = neuralmesh::io_internal::ParseE57(bytes);
  if (parsed.ok()) CheckWrittenAgain(*parsed);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  CheckFile(bytes);
  using neuralmesh::io_internal::kE57PageDataSize;
  using neuralmesh::io_internal::kE57PageSize;
  if (size > 0 && size % kE57PageSize == 0) {
    std::string logical;
    for (size_t page = 0; page < size / kE57PageSize; ++page) {
      logical.append(bytes.data() + page * kE57PageSize, kE57PageDataSize);
    }
    CheckFile(neuralmesh::io_internal::E57Pages(logical));
  }
  return 0;
}
