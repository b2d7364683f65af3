// A LAZ file mapped into memory and read a chunk at a time, never decompressed whole: LASzip
// codes the records in chunks (50,000 records by default) that each decode on their own. What
// the upload of a LAZ file from where it lies reads (client/point_upload.h, LazFileUpload).
#ifndef NEURALMESH_CORE_IO_MAPPED_LAZ_FILE_H_
#define NEURALMESH_CORE_IO_MAPPED_LAZ_FILE_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "core/bounding_box.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "core/io/mapped_file.h"
#include "core/io/point_selection.h"
#include "core/origin.h"
#include "core/rgb.h"

namespace neuralmesh {

// Whether the file at `path` is LAZ (a LAS header whose point format carries LASzip's
// compression bits), by its first bytes; false when it cannot be read.
bool IsLazFile(const std::string& path);

class MappedLazFile {
 public:
  // The chunks decoded at open, spread over the file (SpreadOrder), to see where the points lie
  // and what share of the records are points.
  static constexpr size_t kProbeChunks = 8;

  // Maps the LAZ file at `path`; `classes` as ParseLas's. Returns MappedFile's errors
  // (NOT_FOUND for a missing file); INVALID_ARGUMENT, naming the file and saying why, for
  // DecompressLaz's errors (of the header, the LASzip record, the chunk table, and of the
  // probe's chunks), a file without point records, and one whose probe holds no point.
  static absl::StatusOr<MappedLazFile> Open(
      const std::string& path, const std::optional<LasClasses>& classes = std::nullopt);

  size_t chunks() const { return chunks_.size(); }
  uint64_t records() const { return chunks_.records(); }
  uint64_t records_in(size_t chunk) const { return chunks_.records_in(chunk); }
  // The points of a chunk: positions relative to origin(), and colours when the file has them
  // (one each, scaled as reading the file whole scales them but with the largest level of the
  // probe's records instead of all of them), else none.
  struct ChunkPoints {
    std::vector<Vec3> positions;
    std::vector<Rgb> colors;
  };
  // The points of chunk `chunk` (< chunks()) in their records' order: the records reading the
  // file whole takes (MappedPointFile::Point's rules). INVALID_ARGUMENT, naming the file, for a
  // chunk that cannot be decoded. Safe to call from several threads.
  absl::StatusOr<ChunkPoints> Points(size_t chunk) const;

  // The probe's placement (PlaceProbe: the header's bounds where the probe finds them fresh).
  const BoundingBox& bounds() const { return bounds_; }
  const Origin& origin() const { return origin_; }
  bool has_colors() const { return has_colors_; }
  // The share of the probe's records that are points.
  double kept_share() const { return kept_share_; }
  // MappedFile::CheckSize: whether the chunks decoded so far are the file's.
  absl::Status CheckSize() const { return file_.CheckSize(); }

 private:
  // Chunk `chunk` decoded into `decoded`, as records.
  absl::StatusOr<std::unique_ptr<io_internal::LasRecords>> Records(size_t chunk,
                                                                   std::string* decoded) const;

  MappedLazFile(std::string path, MappedFile file, io_internal::LazChunks chunks)
      : path_(std::move(path)),
        file_(std::move(file)),
        chunks_(std::move(chunks)),
        probed_(std::make_unique<ProbedChunks>()) {}

  // The records of the probe's chunks, decoded at open and kept until Records takes them: the
  // first wave of an upload (LazFileUpload) is the same chunks, and each is decoded once.
  struct ProbedChunks {
    absl::Mutex mutex;
    std::vector<std::pair<size_t, std::string>> decoded ABSL_GUARDED_BY(mutex);
  };
  // Moves chunk `chunk`'s records into `decoded` if the probe holds them.
  bool TakeProbed(size_t chunk, std::string* decoded) const;

  std::string path_;
  MappedFile file_;                // Its mapping stays where it is when this object moves.
  io_internal::LazChunks chunks_;  // A view of file_'s bytes.
  std::optional<LasClasses> classes_;
  Origin origin_ = kNoOrigin;
  BoundingBox bounds_;
  bool has_colors_ = false;
  double kept_share_ = 0;
  double color_scale_ = 255;
  std::unique_ptr<ProbedChunks> probed_;  // Its own address, for the mutex: this object moves.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_MAPPED_LAZ_FILE_H_
