// Off-core sampling, as the paper learned the David model "from 28 million points in an
// off-core implementation" (Section 4.1): a point file is mapped into memory, not read, and
// each sample reads one record where it lies (MappedPointFile). Learning starts at once
// whatever the file's size, and memory holds the mesh, not the points: a file larger than
// memory can be learned (its records then come from the disk, one read per sample that misses
// the page cache). Files whose records all have one size: uncompressed LAS, binary PLY and
// binary PCD.
#ifndef NEURALMESH_CORE_SAMPLING_OFF_CORE_SAMPLER_H_
#define NEURALMESH_CORE_SAMPLING_OFF_CORE_SAMPLER_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "absl/status/statusor.h"
#include "core/bounding_box.h"
#include "core/io/mapped_point_file.h"
#include "core/io/point_selection.h"
#include "core/origin.h"
#include "core/random.h"
#include "core/sampling/sampler.h"

namespace neuralmesh {

// Draws a file's point records uniformly, and draws again where a record is not a point
// (MappedPointFile::Point), so that every point is equally likely, as when the file is read
// whole and sampled (UniformPointCloudSampler). Samples are the points' coordinates relative to
// origin(), in doubles.
class OffCoreSampler final : public Sampler {
 public:
  explicit OffCoreSampler(MappedPointFile file) : file_(std::move(file)) {}
  // The sampler of MappedPointFile::Open's file, and its errors.
  static absl::StatusOr<std::unique_ptr<OffCoreSampler>> Open(
      const std::string& path, const std::optional<LasClasses>& classes = std::nullopt);

  // O(1) expected: one draw of `rng`, and 1 / (kept share) record reads on average from a
  // generator it seeds.
  Vec3 Sample(Random& rng) const override;
  // Starts loading the first record the next Sample would read.
  void PrefetchSample(const Random& rng) const override;
  bool empty() const override { return false; }
  // MappedPointFile::bounds(): records outside them are sampled all the same.
  BoundingBox Bounds() const override { return file_.bounds(); }
  // MappedPointFile::CheckSize: a file that shrinks while it is sampled gives zeros past its
  // new end, not a crash, and this error.
  absl::Status CheckSource() const override { return file_.CheckSize(); }

  const Origin& origin() const { return file_.origin(); }
  uint64_t records() const { return file_.records(); }
  bool has_colors() const { return file_.has_colors(); }
  double kept_share() const { return file_.kept_share(); }

 private:
  MappedPointFile file_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_OFF_CORE_SAMPLER_H_
