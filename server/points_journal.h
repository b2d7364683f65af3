// The append-only file in which a session of neuralmesh-server --state_dir keeps every batch it
// takes (session_store.h), so that its points outlive a restart of the server.
//
// A record is a 12-byte header (the magic "NMPB", the payload's length and the payload's
// CRC-32, each a little-endian uint32) and the payload, a neuralmesh.v1.PointBatch with packed
// arrays. A write that a crash cut short leaves a torn last record: reading stops before it
// and reports it, and the journal reopened for appending cuts it off. The batch it held was
// never acknowledged (a batch is acknowledged only once its record is written).
#ifndef NEURALMESH_SERVER_POINTS_JOURNAL_H_
#define NEURALMESH_SERVER_POINTS_JOURNAL_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/point_cloud.h"

namespace neuralmesh::server {

struct JournalReadResult {
  uint64_t batches = 0;
  uint64_t points = 0;
  // Bytes of whole, intact records from the start of the file.
  uint64_t valid_bytes = 0;
  // Empty when the file ends after its last whole record; otherwise what follows it (a torn
  // or damaged record), for a warning.
  std::string damage;
};

// Calls `visit` with each intact batch of the journal at `path`, in the order they were
// written, and stops at the first torn or damaged record. NOT_FOUND when the file cannot be
// opened; the first error `visit` returns, as is.
absl::StatusOr<JournalReadResult> ReadPointsJournal(
    const std::string& path, const std::function<absl::Status(const PointCloud&)>& visit);

class PointsJournal {
 public:
  // Opens the journal at `path` for appending, creating it when missing, and cuts it to
  // `valid_bytes` (ReadPointsJournal's, or 0 for a new journal). With `sync`, each Append
  // returns only once its record is on the disk (fdatasync); without, once the kernel has it,
  // which a crash of the server survives but a crash of the machine may not.
  static absl::StatusOr<std::unique_ptr<PointsJournal>> Open(const std::string& path,
                                                             uint64_t valid_bytes, bool sync);
  ~PointsJournal();

  PointsJournal(const PointsJournal&) = delete;
  PointsJournal& operator=(const PointsJournal&) = delete;

  // Writes one batch as a record. On error (RESOURCE_EXHAUSTED for a full disk, and so on, the
  // message naming the file) the journal is cut back to what it was: nothing of the batch
  // stays. Not thread-safe; the session calls it under its ingestion lock.
  absl::Status Append(const PointCloud& batch);

  uint64_t size_bytes() const { return size_; }

 private:
  PointsJournal(std::string path, int fd, uint64_t size, bool sync)
      : path_(std::move(path)), fd_(fd), size_(size), sync_(sync) {}

  const std::string path_;
  const int fd_;
  uint64_t size_;
  const bool sync_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_POINTS_JOURNAL_H_
