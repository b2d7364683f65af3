// A file mapped into memory read-only: its bytes are read from the page cache (or the disk)
// when touched, not copied, so a file larger than memory can be read where it lies (off-core
// sampling: core/sampling/off_core_sampler.h). A file that shrinks while it is mapped does not
// crash its reader: what lies past its new end reads as zeros (internal/shrink_guard.h), and
// CheckSize says so.
#ifndef NEURALMESH_CORE_IO_MAPPED_FILE_H_
#define NEURALMESH_CORE_IO_MAPPED_FILE_H_

#include <cstddef>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh {

class MappedFile {
 public:
  // How the file's bytes will be read: at random, or once from the first to the last.
  enum class Access { kRandom, kInOrder };

  // Maps the whole file at `path` for reading. At random, a file of at most half the memory
  // available is read into the page cache in the background, in order (read_ahead()), a larger
  // one page by page where it is touched; in order, each page is read ahead of the reads
  // (the kernel's sequential read-ahead). Returns NOT_FOUND ("cannot open 'path': reason") when
  // it cannot be opened, mapped or is not a regular file, and INVALID_ARGUMENT when it is empty
  // (ReadFileContents's messages).
  static absl::StatusOr<MappedFile> Open(const std::string& path, Access access = Access::kRandom);

  MappedFile(MappedFile&& other) noexcept;
  MappedFile& operator=(MappedFile&& other) noexcept;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile();

  // The file's bytes, valid while this object lives.
  absl::string_view data() const { return absl::string_view(data_, size_); }
  // Whether the whole file is being read ahead into the page cache.
  bool read_ahead() const { return read_ahead_; }
  // OK while the file is as large as when it was mapped. DATA_LOSS ("'path' shrank from 1000 to
  // 10 bytes while it was read; ...") once it is smaller, or once a read past its new end read
  // zeros instead of its bytes: what was read since it shrank is not the file's. Reads done
  // before a call that returns OK read the file's bytes. One fstat.
  absl::Status CheckSize() const;

 private:
  MappedFile(std::string path, int fd, const char* data, size_t size, bool read_ahead);
  void Close();

  std::string path_;
  int fd_ = -1;  // Kept open to see the file's size.
  const char* data_ = nullptr;
  size_t size_ = 0;
  bool read_ahead_ = false;
  int guard_slot_ = -1;  // io_internal::GuardRange's.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_MAPPED_FILE_H_
