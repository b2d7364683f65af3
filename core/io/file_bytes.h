// A file's bytes for reading once, from the first to the last: a regular file is mapped
// (MappedFile, read ahead in order), not copied into memory, so a scan of gigabytes costs no
// memory of its own; anything else (a named pipe) is read whole (ReadFileContents).
#ifndef NEURALMESH_CORE_IO_FILE_BYTES_H_
#define NEURALMESH_CORE_IO_FILE_BYTES_H_

#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/mapped_file.h"

namespace neuralmesh {

class FileBytes {
 public:
  // The bytes of the file at `path`. ReadFileContents's errors (NOT_FOUND "cannot open
  // 'path': reason", INVALID_ARGUMENT "'path' is empty").
  static absl::StatusOr<FileBytes> Read(const std::string& path);
  // As Read, but read whole into memory when `path` is the file `written` names (through
  // another spelling or a link, too): a file about to be replaced by what is made of it, whose
  // mapping the replacing would cut short.
  static absl::StatusOr<FileBytes> ReadToReplace(const std::string& path,
                                                 const std::string& written);

  // Valid while this object lives.
  absl::string_view data() const { return mapped_.has_value() ? mapped_->data() : contents_; }
  // OK while a mapped file is as large as when it was mapped (MappedFile::CheckSize's DATA_LOSS
  // once it shrank: what was read past its new end was zeros); always OK for a file read whole.
  absl::Status CheckSize() const {
    return mapped_.has_value() ? mapped_->CheckSize() : absl::OkStatus();
  }

 private:
  std::optional<MappedFile> mapped_;
  std::string contents_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_FILE_BYTES_H_
