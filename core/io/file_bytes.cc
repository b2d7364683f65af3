#include "core/io/file_bytes.h"

#include <sys/stat.h>

#include <utility>

#include "core/io/file_contents.h"
#include "core/status_macros.h"

namespace neuralmesh {

absl::StatusOr<FileBytes> FileBytes::Read(const std::string& path) {
  FileBytes bytes;
  // A named pipe is opened once: mapping is tried only where it can work.
  struct stat status;
  if (::stat(path.c_str(), &status) == 0 && S_ISREG(status.st_mode)) {
    if (absl::StatusOr<MappedFile> mapped = MappedFile::Open(path, MappedFile::Access::kInOrder);
        mapped.ok()) {
      bytes.mapped_ = *std::move(mapped);
      return bytes;
    }
  }
  NM_ASSIGN_OR_RETURN(bytes.contents_, ReadFileContents(path));
  return bytes;
}

absl::StatusOr<FileBytes> FileBytes::ReadToReplace(const std::string& path,
                                                   const std::string& written) {
  struct stat read, replaced;
  if (::stat(path.c_str(), &read) != 0 || ::stat(written.c_str(), &replaced) != 0 ||
      read.st_dev != replaced.st_dev || read.st_ino != replaced.st_ino) {
    return Read(path);
  }
  FileBytes bytes;
  NM_ASSIGN_OR_RETURN(bytes.contents_, ReadFileContents(path));
  return bytes;
}

}  // namespace neuralmesh
