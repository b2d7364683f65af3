// Off-core sampling, as the paper learned the David model "from 28 million points in an
// off-core implementation" (Section 4.1): a point file is mapped into memory, not read, and
// each sample reads one record where it lies. Learning starts at once whatever the file's
// size, and memory holds the mesh, not the points: a file larger than memory can be learned
// (its records then come from the disk, one read per sample that misses the page cache).
// Files whose records all have one size: uncompressed LAS, binary PLY and binary PCD.
#ifndef NEURALMESH_CORE_SAMPLING_OFF_CORE_SAMPLER_H_
#define NEURALMESH_CORE_SAMPLING_OFF_CORE_SAMPLER_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/bounding_box.h"
#include "core/io/internal/point_records.h"
#include "core/io/mapped_file.h"
#include "core/io/point_selection.h"
#include "core/origin.h"
#include "core/random.h"
#include "core/sampling/sampler.h"

namespace neuralmesh {

// Draws a file's point records uniformly, and draws again where a record is one that reading
// the file leaves out (LAS: withheld, noise, or of a class not asked for, as
// io_internal::ParseLas; PCD: no position) or refuses the file for (PLY: a non-finite
// coordinate; any: a coordinate, relative to origin(), beyond a float's range), so that every
// kept record is equally likely, as when the file is read whole and sampled
// (UniformPointCloudSampler). Samples are the records' coordinates relative to origin(), in
// doubles.
class OffCoreSampler final : public Sampler {
 public:
  // Records drawn when the file is opened, to see what share of them is kept and where they
  // lie.
  static constexpr int kProbeRecords = 4096;
  // The least share of the probe that must be kept: below it a sample would read more than
  // 100 records.
  static constexpr double kLeastKeptShare = 0.01;

  // Maps the uncompressed LAS, binary PLY or binary PCD file at `path` (by its extension);
  // `classes` as ParseLas's, for LAS. Returns MappedFile's errors (NOT_FOUND for a missing
  // file); INVALID_ARGUMENT, naming the file and saying why, for a LAZ file (its records are
  // compressed in chunks: none can be read alone), another format, the errors of
  // io_internal::LasRecords::Create, PlyVertexRecords and PcdPointRecords, a file without
  // point records, and one where less than kLeastKeptShare of the probe is kept (read such a
  // file whole).
  static absl::StatusOr<std::unique_ptr<OffCoreSampler>> Open(
      const std::string& path, const std::optional<LasClasses>& classes = std::nullopt);

  // O(1) expected: one draw of `rng`, and 1 / (kept share) record reads on average from a
  // generator it seeds.
  Vec3 Sample(Random& rng) const override;
  // Starts loading the first record the next Sample would read.
  void PrefetchSample(const Random& rng) const override;
  bool empty() const override { return false; }
  // The bounds the file states (a LAS header's) where the probe finds them fresh (no record
  // outside them, and no more than twice the probe's box), else the probe's; relative to
  // origin(). Records outside them are sampled all the same.
  BoundingBox Bounds() const override { return bounds_; }

  // Where the samples' (0, 0, 0) lies in the file's coordinates (georeferenced scans), chosen
  // from Bounds() as reading the file whole chooses it from its points: with the file's
  // resolution (a LAS file's scale) or, where it states none, PositionCollector's rule.
  const Origin& origin() const { return origin_; }
  uint64_t records() const { return records_->size(); }
  bool has_colors() const { return records_->has_colors(); }
  // The share of the probe's records that are kept.
  double kept_share() const { return kept_share_; }

 private:
  OffCoreSampler(MappedFile file, std::unique_ptr<io_internal::PointRecords> records)
      : file_(std::move(file)), records_(std::move(records)) {}

  MappedFile file_;
  std::unique_ptr<io_internal::PointRecords> records_;  // A view of file_'s bytes.
  Origin origin_ = kNoOrigin;
  BoundingBox bounds_;
  double kept_share_ = 0;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_OFF_CORE_SAMPLER_H_
