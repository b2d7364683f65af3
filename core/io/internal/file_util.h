// Whole-file reads and writes, and file-name extensions, for the readers and writers in core/io.
#ifndef NEURALMESH_CORE_IO_INTERNAL_FILE_UTIL_H_
#define NEURALMESH_CORE_IO_INTERNAL_FILE_UTIL_H_

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::io_internal {

// The formats the readers and writers know, chosen by file-name extension.
enum class FileFormat { kUnknown, kPly, kObj, kOff, kStl, kXyz, kDraco };

// Maps a path's extension (case-insensitive) to its format: .ply, .obj, .off, .stl, .drc, and
// .xyz / .txt / .pts (all kXyz). Anything else, or no extension, is kUnknown.
FileFormat FormatFromPath(absl::string_view path);

// The lower-case extension of `path` with its dot (".ply"), or "" when it has none.
std::string LowercaseExtension(absl::string_view path);

// Reads the whole file at `path`.
// Returns NOT_FOUND ("cannot open 'path': reason") when it cannot be opened or read, and
// INVALID_ARGUMENT when it is empty.
absl::StatusOr<std::string> ReadFileContents(const std::string& path);

// Replaces the file at `path` with `contents`; removes a partly written file on failure.
// Returns the errno-derived status ("cannot write 'path': reason") when opening, writing or
// closing fails: NOT_FOUND for a missing directory, PERMISSION_DENIED, RESOURCE_EXHAUSTED for a
// full disk, and so on.
absl::Status WriteFileContents(const std::string& path, absl::string_view contents);

// Returns `status` with "'path': " in front of its message; OK stays OK.
absl::Status WithPath(const absl::Status& status, const std::string& path);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_FILE_UTIL_H_
