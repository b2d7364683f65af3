#include "core/io/byte_sink.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <utility>

#include "absl/strings/str_cat.h"

namespace neuralmesh {

absl::Status StringSink::Append(absl::string_view bytes) {
  bytes_.append(bytes.data(), bytes.size());
  return absl::OkStatus();
}

absl::Status StringSink::Patch(size_t at, absl::string_view bytes) {
  bytes_.replace(at, bytes.size(), bytes.data(), bytes.size());
  return absl::OkStatus();
}

FileSink::~FileSink() {
  if (!closed_) Discard();
}

void FileSink::Discard() {
  if (fd_ >= 0) ::close(std::exchange(fd_, -1));
  if (regular_) std::remove(path_.c_str());
  closed_ = true;
}

absl::Status FileSink::Failed(int error) {
  if (status_.ok()) {
    status_ =
        absl::ErrnoToStatus(error != 0 ? error : EIO, absl::StrCat("cannot write '", path_, "'"));
  }
  return status_;
}

absl::Status FileSink::Open() {
  if (!status_.ok()) return status_;
  if (closed_) return absl::FailedPreconditionError(absl::StrCat("'", path_, "' is closed"));
  if (fd_ >= 0) return absl::OkStatus();
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) return Failed(errno);
  struct stat file;
  regular_ = ::fstat(fd_, &file) == 0 && S_ISREG(file.st_mode);
  return absl::OkStatus();
}

absl::Status FileSink::Write(absl::string_view bytes, const size_t* at) {
  if (const absl::Status opened = Open(); !opened.ok()) return opened;
  size_t offset = at != nullptr ? *at : 0;
  while (!bytes.empty()) {
    const ssize_t written =
        at != nullptr ? ::pwrite(fd_, bytes.data(), bytes.size(), static_cast<off_t>(offset))
                      : ::write(fd_, bytes.data(), bytes.size());
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) return Failed(written < 0 ? errno : ENOSPC);
    bytes.remove_prefix(static_cast<size_t>(written));
    offset += static_cast<size_t>(written);
  }
  return absl::OkStatus();
}

absl::Status FileSink::Append(absl::string_view bytes) {
  const absl::Status status = Write(bytes, nullptr);
  if (status.ok()) size_ += bytes.size();
  return status;
}

absl::Status FileSink::Patch(size_t at, absl::string_view bytes) { return Write(bytes, &at); }

absl::Status FileSink::Close() {
  if (closed_) return status_;
  if (Open().ok() && ::close(std::exchange(fd_, -1)) != 0) Failed(errno).IgnoreError();
  if (status_.ok()) {
    closed_ = true;
  } else {
    Discard();
  }
  return status_;
}

}  // namespace neuralmesh
