// File-name extensions and path-prefixed messages, for the readers and writers in core/io
// (whole-file reads and writes: core/io/file_contents.h).
#ifndef NEURALMESH_CORE_IO_INTERNAL_FILE_UTIL_H_
#define NEURALMESH_CORE_IO_INTERNAL_FILE_UTIL_H_

#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::io_internal {

// The formats the readers and writers know, chosen by file-name extension.
enum class FileFormat {
  kUnknown, kPly, kObj, kOff, kStl, kXyz, kDraco, kGltf, kLas, kPcd, kPtx, kE57
};

// Maps a path's extension (case-insensitive) to its format: .ply, .obj, .off, .stl, .drc,
// .glb / .gltf (both kGltf), .xyz / .txt / .pts (all kXyz), .las, .pcd, .ptx and .e57. Anything
// else, or no extension, is kUnknown.
FileFormat FormatFromPath(absl::string_view path);

// The lower-case extension of `path` with its dot (".ply"), or "" when it has none.
std::string LowercaseExtension(absl::string_view path);

// Returns `status` with "'path': " in front of its message; OK stays OK.
absl::Status WithPath(const absl::Status& status, const std::string& path);

// Returns the error `status` with "cannot write 'path': " in front of its message, for the
// writers.
absl::Status CannotWrite(const std::string& path, const absl::Status& status);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_FILE_UTIL_H_
