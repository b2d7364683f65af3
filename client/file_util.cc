#include "client/file_util.h"

#include <filesystem>
#include <system_error>

#include "absl/strings/str_cat.h"

namespace neuralmesh::client {

absl::Status CheckInputFile(const std::string& path, absl::string_view role) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status)) {
    return absl::NotFoundError(absl::StrCat(role, " file '", path, "' does not exist"));
  }
  if (std::filesystem::is_directory(status)) {
    return absl::InvalidArgumentError(absl::StrCat(role, " '", path, "' is a directory"));
  }
  if (std::filesystem::is_regular_file(status) && std::filesystem::file_size(path, error) == 0) {
    return absl::InvalidArgumentError(absl::StrCat(role, " file '", path, "' is empty"));
  }
  return absl::OkStatus();
}

}  // namespace neuralmesh::client
