// Where the bytes of a file being written go, piece by piece: a string, or the file itself, so
// that a writer of gigabytes (LAS decompressed from LAZ, LAZ compressed from LAS) holds a few
// pieces at a time instead of the whole output. Bytes already written can be patched in place,
// for the offsets a format states before what they point at is written (LAZ's chunk table).
#ifndef NEURALMESH_CORE_IO_BYTE_SINK_H_
#define NEURALMESH_CORE_IO_BYTE_SINK_H_

#include <cstddef>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh {

class ByteSink {
 public:
  virtual ~ByteSink() = default;
  // Adds `bytes` at the end.
  virtual absl::Status Append(absl::string_view bytes) = 0;
  // Overwrites bytes already appended, from `at` on (at + bytes.size() <= size()).
  virtual absl::Status Patch(size_t at, absl::string_view bytes) = 0;
  // The bytes appended so far.
  virtual size_t size() const = 0;
};

// Appends to a string it owns.
class StringSink : public ByteSink {
 public:
  absl::Status Append(absl::string_view bytes) override;
  absl::Status Patch(size_t at, absl::string_view bytes) override;
  size_t size() const override { return bytes_.size(); }

  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

// Writes the file at a path, replacing what was there. The file is opened by the first
// Append (or Close), so that a writer that fails before its first byte leaves any file at the
// path as it was. A regular file whose writing failed, or that was not closed by Close (an
// error on the way), is removed, so no partly written file stays behind. Appends are sequential
// writes, so a pipe or a device (/dev/stdout) takes them; a patch needs a file that can be
// written at any offset.
class FileSink : public ByteSink {
 public:
  explicit FileSink(std::string path) : path_(std::move(path)) {}
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;
  ~FileSink() override;

  // The errno-derived status of a failed open or write ("cannot write 'path': reason":
  // NOT_FOUND for a missing directory, PERMISSION_DENIED, RESOURCE_EXHAUSTED for a full disk,
  // and so on), after which the sink takes nothing more.
  absl::Status Append(absl::string_view bytes) override;
  absl::Status Patch(size_t at, absl::string_view bytes) override;
  size_t size() const override { return size_; }

  // Closes the file, keeping it: the status of the close (or of an earlier failed open or
  // write). The sink takes nothing after it.
  absl::Status Close();
  // OK unless opening, writing or closing the file failed: tells the sink's errors from those
  // of what was being written.
  const absl::Status& status() const { return status_; }

 private:
  absl::Status Failed(int error);
  // Opens the file unless it is open.
  absl::Status Open();
  // Writes `bytes` in full, at the end (`at` null) or at *at.
  absl::Status Write(absl::string_view bytes, const size_t* at);
  // Closes the file and removes a regular one.
  void Discard();

  std::string path_;
  int fd_ = -1;
  bool regular_ = false;  // Removed when not written in full.
  size_t size_ = 0;
  absl::Status status_;
  bool closed_ = false;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_BYTE_SINK_H_
