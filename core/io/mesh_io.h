// Reads and writes triangle meshes as PLY, OBJ, OFF, STL, Draco and glTF files, chosen by the
// file-name extension (case-insensitive).
#ifndef NEURALMESH_CORE_IO_MESH_IO_H_
#define NEURALMESH_CORE_IO_MESH_IO_H_

#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/io/draco_codec.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

// The extensions ReadMesh and WriteMesh handle, for messages: ".ply, .obj, .off, .stl, .drc,
// .glb, .gltf".
extern const char kMeshExtensions[];

// True when ReadMesh and WriteMesh handle the extension of `path` (kMeshExtensions).
bool IsSupportedMeshExtension(std::string_view path);

// Reads the mesh at `path`:
//   .ply  ASCII or binary (either byte order); 'vertex' x, y, z and 'face' vertex_indices.
//   .obj  'v' and 'f' lines (v, v/vt, v/vt/vn, v//vn; negative indices count back).
//   .off  OFF, COFF, NOFF, STOFF.
//   Vertex colours are read from PLY, OBJ and COFF as internal/ply.h, obj.h and off.h say.
//   .stl  binary or ASCII; identical vertex positions are merged.
//   .drc  a Draco mesh (see draco_codec.h: positions are quantized, order may change).
//   .glb, .gltf  glTF 2.0, Draco-compressed or not: the triangles of every mesh the default
//         scene draws, placed by their nodes, with COLOR_0 colours; vertices at identical
//         positions merged (internal/gltf.h). A .gltf's external buffers are read relative to
//         it.
// Polygons are fan-triangulated. A file may hold vertices and no faces. Georeferenced
// coordinates, too far from zero for a float to keep their resolution, are read relative to
// TriangleMesh::origin (internal/position_collector.h; Draco: its metadata; STL: never).
// Returns NOT_FOUND when the file cannot be opened or read; INVALID_ARGUMENT for an
// unsupported extension (listing the supported ones), an empty file, a file with no vertices,
// or malformed content (the message gives the line or byte offset and what was expected),
// including non-finite coordinates and out-of-range face indices.
absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path);

struct MeshWriteOptions {
  DracoOptions draco;       // For .drc, and for glTF with gltf_draco.
  bool gltf_draco = false;  // .glb and .gltf: compress with KHR_draco_mesh_compression.
};

// Writes `mesh` to `path`, replacing any file there: binary little-endian .ply, .obj, .off,
// binary .stl, .drc encoded with `options.draco`, or glTF 2.0: binary .glb, or .gltf with the
// buffer embedded (one mesh, one primitive; see internal/gltf.h). Vertex colours go to every
// format but STL (PLY uchar red, green, blue; OBJ 'v x y z r g b' fractions; COFF; a Draco COLOR
// attribute; glTF COLOR_0, as linear light). A non-zero mesh.origin is put back: PLY double
// coordinates, OBJ and OFF text of the exact sums, a glTF node's translation, Draco metadata
// ("origin"); STL keeps the positions as they are.
// Returns INVALID_ARGUMENT for an unsupported extension, an empty mesh, colours that are not one
// per vertex, a non-finite coordinate, a face index out of range, a mesh without faces for .stl,
// .drc or Draco-compressed glTF, or invalid Draco options (including positions outside the
// quantization box);
// otherwise the status of the write ("cannot write 'path': reason", e.g. NOT_FOUND for a
// missing directory, PERMISSION_DENIED).
absl::Status WriteMesh(const TriangleMesh& mesh, const std::string& path,
                       const MeshWriteOptions& options = {});

// The bytes WriteMesh writes to a file named `path` (only its extension counts), and its
// errors but those of the file itself.
absl::StatusOr<std::string> FormatMesh(const TriangleMesh& mesh, const std::string& path,
                                       const MeshWriteOptions& options = {});

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_MESH_IO_H_
