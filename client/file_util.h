// File checks shared by the subcommands, with messages that name the file (writes:
// core/io/file_contents.h).
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

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_FILE_UTIL_H_
