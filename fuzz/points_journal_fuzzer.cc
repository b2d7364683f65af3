// The server's reading of a session's points journal (server/points_journal.h) after a
// restart, on any file contents: a journal is the server's own file, but a crash, a full disk
// or a damaged disk can leave anything in it. Properties:
//  - ReadPointsJournal never fails on a file it can open, and never crashes;
//  - every batch it passes on holds at least one point, weights and normals empty or one per
//    point;
//  - the whole records end within the file, and at its end exactly when nothing is reported
//    damaged;
//  - the journal reopened at its whole records (as a restored session reopens it) reads the
//    same batches with nothing damaged, and so does a fresh journal the batches are appended to.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz/fuzz_check.h"
#include "server/points_journal.h"

namespace {

using neuralmesh::PointCloud;
using neuralmesh::server::JournalReadResult;
using neuralmesh::server::PointsJournal;
using neuralmesh::server::ReadPointsJournal;

std::string TempPath(const char* name) {
  return (std::filesystem::temp_directory_path() /
          ("points_journal_fuzzer_" + std::to_string(getpid()) + "_" + name))
      .string();
}

template <typename T>
bool SameBytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool SameBatches(const std::vector<PointCloud>& a, const std::vector<PointCloud>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!SameBytes(a[i].positions, b[i].positions) || !SameBytes(a[i].weights, b[i].weights) ||
        !SameBytes(a[i].normals, b[i].normals)) {
      return false;
    }
  }
  return true;
}

JournalReadResult ReadAll(const std::string& path, std::vector<PointCloud>* batches) {
  absl::StatusOr<JournalReadResult> read = ReadPointsJournal(path, [&](const PointCloud& batch) {
    const size_t n = batch.positions.size();
    FUZZ_CHECK(n >= 1, "a batch without points");
    FUZZ_CHECK(batch.weights.empty() || batch.weights.size() == n, "%zu weights for %zu points",
               batch.weights.size(), n);
    FUZZ_CHECK(batch.normals.empty() || batch.normals.size() == n, "%zu normals for %zu points",
               batch.normals.size(), n);
    batches->push_back(batch);
    return absl::OkStatus();
  });
  FUZZ_CHECK(read.ok(), "reading failed: %s", read.status().ToString().c_str());
  FUZZ_CHECK(read->batches == batches->size(), "%llu batches counted, %zu passed on",
             static_cast<unsigned long long>(read->batches), batches->size());
  return *read;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = TempPath("input");
  std::FILE* file = std::fopen(path.c_str(), "wb");
  FUZZ_CHECK(file != nullptr, "cannot write %s", path.c_str());
  if (size > 0) std::fwrite(data, 1, size, file);
  std::fclose(file);

  std::vector<PointCloud> batches;
  const JournalReadResult read = ReadAll(path, &batches);
  FUZZ_CHECK(read.valid_bytes <= size, "%llu whole bytes in a file of %zu",
             static_cast<unsigned long long>(read.valid_bytes), size);
  FUZZ_CHECK(read.damage.empty() == (read.valid_bytes == size),
             "%llu whole bytes of %zu, damage \"%s\"",
             static_cast<unsigned long long>(read.valid_bytes), size, read.damage.c_str());

  {
    absl::StatusOr<std::unique_ptr<PointsJournal>> reopened =
        PointsJournal::Open(path, read.valid_bytes, /*sync=*/false);
    FUZZ_CHECK(reopened.ok(), "reopening failed: %s", reopened.status().ToString().c_str());
  }
  std::vector<PointCloud> again;
  const JournalReadResult cut = ReadAll(path, &again);
  FUZZ_CHECK(cut.damage.empty(), "damage after the cut: %s", cut.damage.c_str());
  FUZZ_CHECK(SameBatches(batches, again), "the cut journal reads other batches");

  const std::string copy_path = TempPath("copy");
  {
    absl::StatusOr<std::unique_ptr<PointsJournal>> copy =
        PointsJournal::Open(copy_path, 0, /*sync=*/false);
    FUZZ_CHECK(copy.ok(), "creating a journal failed: %s", copy.status().ToString().c_str());
    for (const PointCloud& batch : batches) {
      const absl::Status appended = (*copy)->Append(batch);
      FUZZ_CHECK(appended.ok(), "appending failed: %s", appended.ToString().c_str());
    }
  }
  std::vector<PointCloud> copied;
  const JournalReadResult rewritten = ReadAll(copy_path, &copied);
  FUZZ_CHECK(rewritten.damage.empty(), "damage in a fresh journal: %s", rewritten.damage.c_str());
  FUZZ_CHECK(SameBatches(batches, copied), "a fresh journal reads other batches");
  std::remove(path.c_str());
  std::remove(copy_path.c_str());
  return 0;
}
