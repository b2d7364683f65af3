#include "core/sampling/off_core_sampler.h"

#include <utility>

#include "core/status_macros.h"

namespace neuralmesh {

absl::StatusOr<std::unique_ptr<OffCoreSampler>> OffCoreSampler::Open(
    const std::string& path, const std::optional<LasClasses>& classes) {
  NM_ASSIGN_OR_RETURN(MappedPointFile file, MappedPointFile::Open(path, classes));
  return std::make_unique<OffCoreSampler>(std::move(file));
}

Vec3 OffCoreSampler::Sample(Random& rng) const {
  Random tries(rng.NextU64());  // One draw of `rng` per sample, however many records it reads.
  while (true) {
    const std::optional<Vec3> point = file_.Point(tries.NextIndex(file_.records()));
    if (point.has_value()) return *point;
  }
}

void OffCoreSampler::PrefetchSample(const Random& rng) const {
  Random peek = rng;
  Random tries(peek.NextU64());
  file_.Prefetch(tries.NextIndex(file_.records()));
}

}  // namespace neuralmesh
