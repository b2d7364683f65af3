// Whole-file reads and writes with messages that name the file: the file readers and writers
// of core/io use them, and so does anything else that stores bytes it already has (the
// client's Draco meshes from the server).
#ifndef NEURALMESH_CORE_IO_FILE_CONTENTS_H_
#define NEURALMESH_CORE_IO_FILE_CONTENTS_H_

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh {

// Reads the whole file at `path`.
// Returns NOT_FOUND ("cannot open 'path': reason") when it cannot be opened or read, and
// INVALID_ARGUMENT when it is empty.
absl::StatusOr<std::string> ReadFileContents(const std::string& path);

// For the programs' flags that name a file (--tls_cert_file=PATH): its contents, or "" when
// `path` is empty. ReadFileContents's errors, their message prefixed with "--FLAG: ".
absl::StatusOr<std::string> ReadFileNamedByFlag(absl::string_view flag, const std::string& path);

// Replaces the file at `path` with `contents`; removes a partly written file on failure.
// Returns the errno-derived status ("cannot write 'path': reason") when opening, writing or
// closing fails: NOT_FOUND for a missing directory, PERMISSION_DENIED, RESOURCE_EXHAUSTED for a
// full disk, and so on.
absl::Status WriteFileContents(const std::string& path, absl::string_view contents);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_FILE_CONTENTS_H_
