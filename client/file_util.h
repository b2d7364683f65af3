// File checks and writes shared by the subcommands, with messages that name the file.
#ifndef NEURALMESH_CLIENT_FILE_UTIL_H_
#define NEURALMESH_CLIENT_FILE_UTIL_H_

#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::client {

// Checks that `path` names a non-empty regular file. `role` names it in the message
// ("INPUT", "--reference"). NOT_FOUND when it does not exist; INVALID_ARGUMENT when it is a
// directory or empty.
absl::Status CheckInputFile(const std::string& path, absl::string_view role);

// Writes `bytes` to `path`, replacing it. PERMISSION_DENIED (or the errno's code) naming the
// file when it cannot be written.
absl::Status WriteFileBytes(const std::string& path, absl::string_view bytes);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_FILE_UTIL_H_
