// A LAS file written in order without being held whole, for writers of gigabytes (a survey's
// tiles cleaned and joined into one file): its head (the header and variable-length records),
// then its records in pieces, then what follows them (LAS 1.4's extended records). The head's
// counts and bounds are known only once the records are written, so it is given again at the
// end, the same size, and patched in.
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAS_FILE_WRITER_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAS_FILE_WRITER_H_

#include <cstddef>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "core/io/byte_sink.h"

namespace neuralmesh::io_internal {

// Nothing reaches the sink before the first records (or Finish), so that a file refused by
// Start, or by the checks its writer makes before the records, leaves what the sink holds as it
// was (FileSink: the file at the path).
class LasFileWriter {
 public:
  virtual ~LasFileWriter() = default;
  // The header and variable-length records, up to the points' offset (head.size()). Returns
  // INVALID_ARGUMENT for a head that is no LAS header ending where its points start, or a
  // writer's refusal of its point format.
  virtual absl::Status Start(absl::string_view head) = 0;
  // The next whole records; INVALID_ARGUMENT for a piece that is not a whole number of records;
  // the sink's error.
  virtual absl::Status AppendRecords(absl::string_view records) = 0;
  // Ends the file: `head` as Start's, but for its counts, bounds and offsets past the points
  // (the same size, point format and record length), then `tail`, what follows the records.
  virtual absl::Status Finish(absl::string_view head, absl::string_view tail) = 0;

 protected:
  explicit LasFileWriter(ByteSink* out) : out_(out) {}
  // Appends `head` to `out_` the first time it is called, noting where (start_).
  absl::Status WriteHeadOnce(absl::string_view head);

  ByteSink* const out_;
  size_t start_ = 0;  // Where the file starts in `out_`: its offsets count from there.

 private:
  bool head_written_ = false;
};

// Uncompressed (.las), each piece appended to `out` as it comes.
class PlainLasWriter final : public LasFileWriter {
 public:
  explicit PlainLasWriter(ByteSink* out) : LasFileWriter(out) {}

  absl::Status Start(absl::string_view head) override;
  absl::Status AppendRecords(absl::string_view records) override;
  absl::Status Finish(absl::string_view head, absl::string_view tail) override;

 private:
  std::string started_;  // The head Start took.
};

// The checks of Start's and Finish's heads that every writer makes: INVALID_ARGUMENT, saying
// what is wrong, for a head shorter than LAS's legacy header, without the LASF signature, or
// whose points' offset is not its size; for Finish's (`started` the head Start took), one of
// another size, point format or record length.
absl::Status CheckLasHead(absl::string_view head);
absl::Status CheckFinishingLasHead(absl::string_view head, absl::string_view started);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAS_FILE_WRITER_H_
