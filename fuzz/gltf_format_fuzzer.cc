// The glTF parser and writer (core/io/internal/gltf.h) against the properties of
// fuzz/geometry_parser_properties.h: .glb containers and .gltf JSON, with buffers in the BIN
// chunk or in data URIs (external files are refused: no loader), Draco primitives included.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/io/internal/gltf.h"
#include "fuzz/fuzz_check.h"
#include "fuzz/geometry_parser_properties.h"

namespace {

absl::StatusOr<neuralmesh::io_internal::ParsedGeometry> Parse(
    absl::string_view data, neuralmesh::io_internal::FaceHandling faces,
    neuralmesh::io_internal::PositionPrecision) {
  return neuralmesh::io_internal::ParseGltf(data, faces);
}

// Plain glTF: positions, triangles, colours, normals (made unit length: those the parser gives
// are, or are the file's own when no node turns them) and weights. A file of no vertices is
// written as a document without meshes, which WriteMesh never writes (it refuses empty
// meshes).
std::string Format(const neuralmesh::io_internal::GeometryView& geometry) {
  if (geometry.positions.empty()) return R"({"asset":{"version":"2.0"}})";
  const absl::StatusOr<std::string> written =
      neuralmesh::io_internal::FormatGltf(geometry, neuralmesh::io_internal::GltfWriteOptions{});
  FUZZ_CHECK(written.ok(), "the writer failed: %s", written.status().ToString().c_str());
  return *written;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  neuralmesh::fuzz::CheckGeometryParser({Parse, Format, /*skips_faces=*/true,
                                         /*writes_normals_and_weights=*/true},
                                        data, size);
  return 0;
}
