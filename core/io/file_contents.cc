#include "core/io/file_contents.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/io/byte_sink.h"
#include "core/status_macros.h"

namespace neuralmesh {

absl::StatusOr<std::string> ReadFileContents(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    return absl::NotFoundError(absl::StrCat("cannot open '", path, "': ", std::strerror(errno)));
  }
  std::string contents;
  char chunk[1 << 16];
  size_t got = 0;
  while ((got = std::fread(chunk, 1, sizeof(chunk), file)) > 0) contents.append(chunk, got);
  // fread on a directory fails with EISDIR; report it like any other unreadable file.
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  std::fclose(file);
  if (failed) {
    return absl::NotFoundError(absl::StrCat("cannot read '", path, "': ", std::strerror(error)));
  }
  if (contents.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "' is empty"));
  }
  return contents;
}

absl::StatusOr<std::string> ReadFileNamedByFlag(absl::string_view flag, const std::string& path) {
  if (path.empty()) return std::string();
  absl::StatusOr<std::string> contents = ReadFileContents(path);
  if (!contents.ok()) {
    return absl::Status(contents.status().code(),
                        absl::StrCat("--", flag, ": ", contents.status().message()));
  }
  return contents;
}

absl::Status WriteFileContents(const std::string& path, absl::string_view contents) {
  FileSink file(path);
  NM_RETURN_IF_ERROR(file.Append(contents));
  return file.Close();
}

}  // namespace neuralmesh
