// The glTF 2.0 format (Khronos): binary .glb files and JSON .gltf files, with and without Draco
// compression (KHR_draco_mesh_compression).
#ifndef NEURALMESH_CORE_IO_INTERNAL_GLTF_H_
#define NEURALMESH_CORE_IO_INTERNAL_GLTF_H_

#include <functional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/draco_codec.h"
#include "core/io/internal/geometry_data.h"

namespace neuralmesh::io_internal {

// The bytes of an external buffer of a .gltf file: its "uri" (percent-decoded, never a data
// URI), relative to the file's directory.
using GltfBufferLoader = std::function<absl::StatusOr<std::string>(const std::string& uri)>;

// Reads the external buffers of the .gltf file at `path`: a relative URI names a file in its
// directory (or below or beside it); absolute paths and URIs with a scheme are refused.
GltfBufferLoader GltfBuffersBeside(const std::string& path);

// Parses a .glb (recognised by its magic bytes) or a .gltf file: the vertices of every mesh
// primitive the default scene draws (or, without scenes, of every mesh once), placed by their
// nodes' transforms, with the triangles of TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN
// primitives (winding reversed under a mirroring transform) and the COLOR_0 colours (linear
// light, converted to sRGB), the NORMAL vectors (turned by the nodes, unit length) and the
// weights (a SCALAR _WEIGHT, or the first of _CONFIDENCE, _QUALITY, _INTENSITY, _SCALAR), each
// when every primitive has them (not those of Draco-compressed primitives; ReadMesh keeps
// neither). Vertices at identical positions are merged, since glTF splits vertices where
// normals or texture coordinates differ; faces that repeat a vertex are dropped. Where the nodes place vertices far from zero (a
// georeferenced model), positions are relative to an origin (position_collector.h), and
// merged after that. Buffers come from the .glb's BIN chunk, base64 data URIs,
// or `load_buffer` (none: external buffers are refused).
// Returns INVALID_ARGUMENT, saying which element is wrong and how, for a truncated or
// malformed container or JSON, a glTF version other than 2, a reference or range out of
// bounds, an index past its primitive's vertices, a non-finite position, a required
// extension that changes geometry and is not supported (Draco is), a sparse accessor, or a
// node reached twice; the loader's error for an external buffer it cannot read.
absl::StatusOr<ParsedGeometry> ParseGltf(absl::string_view data, FaceHandling faces,
                                         const GltfBufferLoader& load_buffer = nullptr);

struct GltfWriteOptions {
  bool binary = true;          // .glb; false: a .gltf with its buffer in a base64 data URI.
  bool draco = false;          // Compress the mesh with KHR_draco_mesh_compression.
  DracoOptions draco_options;  // Used with `draco`.
};

// Formats one mesh of one primitive: positions, faces (TRIANGLES; POINTS without faces),
// colours as COLOR_0 (linear light, normalized 16-bit), and without `draco` normals as NORMAL
// (made unit length, as glTF requires; zero ones stay zero) and weights as _WEIGHT (floats;
// glTF's application-specific attributes begin with "_"), placed by a node whose translation is
// geometry.origin when that is not zero, with a matte double-sided material
// (glTF's default material is fully metallic, which renders dark without an environment).
// With `draco`, the primitive is a Draco stream (EncodeMeshForGltf) and the file requires
// KHR_draco_mesh_compression. Returns INVALID_ARGUMENT for `draco` without faces, and what
// EncodeMeshForGltf returns.
absl::StatusOr<std::string> FormatGltf(const GeometryView& geometry,
                                       const GltfWriteOptions& options);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_GLTF_H_
