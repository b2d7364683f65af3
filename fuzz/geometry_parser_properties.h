// The properties every file-format parser of core/io/internal must have, whatever bytes it is
// given, checked by the format fuzzers (fuzz/*_format_fuzzer.cc):
//  - it returns OK or INVALID_ARGUMENT with a message, and never crashes;
//  - what it returns is what geometry_data.h promises: finite positions, normals and weights
//    empty or one per position, face indices in range;
//  - a file that parses with its faces also parses without them, to the same points (point
//    clouds are read with FaceHandling::kSkip, meshes with kRead);
//  - the format's writer output parses back to the same positions, faces and (where the
//    format holds them) normals and weights, bit for bit (a NaN normal or weight may come back
//    as another NaN: text holds no NaN's payload);
//  - a parsed mesh can be reported on (`neuralmesh stats`), however broken its connectivity;
//  - read in the least memory (ParseInLeastMemory: floats near 0 kept as floats, read again
//    with kExact when the origin needs doubles), it gives what kExact gives, bit for bit.
#ifndef NEURALMESH_FUZZ_GEOMETRY_PARSER_PROPERTIES_H_
#define NEURALMESH_FUZZ_GEOMETRY_PARSER_PROPERTIES_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/position_collector.h"

namespace neuralmesh::fuzz {

using GeometryParser = std::function<absl::StatusOr<io_internal::ParsedGeometry>(
    absl::string_view, io_internal::FaceHandling, io_internal::PositionPrecision)>;
using GeometryFormatter = std::function<std::string(const io_internal::GeometryView&)>;

struct GeometryFormat {
  GeometryParser parse;
  // Null when the format cannot hold all that its parser reads (STL keeps only triangles).
  GeometryFormatter format;
  // False when the parser has no FaceHandling::kSkip mode of its own (XYZ has no faces).
  bool skips_faces = true;
  // False when the writer keeps positions and faces only (OBJ and OFF), so that the round trip
  // compares those alone.
  bool writes_normals_and_weights = true;
};

// Checks every property above on `data`, aborting through FUZZ_CHECK on the first that fails.
void CheckGeometryParser(const GeometryFormat& format, const uint8_t* data, size_t size);

// For the formats of scaled integer coordinates (LAS, E57), whose round trip is not bit for
// bit: checks that `reread`, `parsed` written and read back, holds as many points, each within
// half its axis's `scale` (and a float's rounding) of where it was.
void CheckPositionsWithinScale(const io_internal::ParsedGeometry& parsed,
                               const io_internal::ParsedGeometry& reread,
                               const std::array<double, 3>& scale);

}  // namespace neuralmesh::fuzz

#endif  // NEURALMESH_FUZZ_GEOMETRY_PARSER_PROPERTIES_H_
