#include "core/sampling/las_file_sampler.h"

#include <cmath>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/io/internal/laz.h"
#include "core/io/internal/position_collector.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

using io_internal::Point3d;

// Seeds the probe's draws: the same file gives the same probe.
constexpr uint64_t kProbeSeed = 0x6c61735f70726f62;

Vec3 ToVec3(const Point3d& p) { return Vec3(p[0], p[1], p[2]); }

}  // namespace

absl::StatusOr<std::unique_ptr<LasFileSampler>> LasFileSampler::Open(
    const std::string& path, const std::optional<LasClasses>& classes) {
  NM_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  const auto invalid = [&path](absl::string_view message) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "': ", message));
  };
  if (io_internal::IsLaz(file.data())) {
    return invalid(
        "LAZ: its records are compressed in chunks and cannot be read one at a time; read the "
        "file whole, or sample its decompressed LAS file");
  }
  absl::StatusOr<io_internal::LasRecords> records =
      io_internal::LasRecords::Create(file.data(), classes);
  if (!records.ok()) return invalid(records.status().message());
  if (records->size() == 0) return invalid("LAS: the file has no point records");
  std::unique_ptr<LasFileSampler> sampler(new LasFileSampler(std::move(file), *std::move(records)));
  const io_internal::LasRecords& las = sampler->records_;

  BoundingBox probed;
  int kept = 0;
  Random probe(kProbeSeed);
  for (int i = 0; i < kProbeRecords; ++i) {
    const uint64_t r = probe.NextIndex(las.size());
    if (!las.Kept(r)) continue;
    ++kept;
    probed.Extend(ToVec3(las.Position(r)));
  }
  sampler->kept_share_ = static_cast<double>(kept) / kProbeRecords;
  if (sampler->kept_share_ < kLeastKeptShare) {
    return invalid(absl::StrFormat(
        "LAS: %d of %d records drawn at random are points to read (the others withheld, %s): "
        "sampling the file where it lies would read about %s records per sample; read it whole",
        kept, kProbeRecords, classes.has_value() ? "noise or of other classes" : "or noise",
        kept == 0 ? std::string("countless") : absl::StrCat(kProbeRecords / kept)));
  }
  // The header's bounds, unless the probe finds them stale: records outside them, or a box
  // more than twice the probe's (which covers nearly all of a scan's extent).
  const Point3d resolution = las.Resolution();
  const Vec3 low = ToVec3(las.header_low()), high = ToVec3(las.header_high());
  BoundingBox stated;
  stated.Extend(low - ToVec3(resolution));
  stated.Extend(high + ToVec3(resolution));
  const bool fresh = std::isfinite(stated.diagonal()) && stated.Contains(probed.min) &&
                     stated.Contains(probed.max) &&
                     stated.diagonal() <= 2 * probed.diagonal() + 4 * ToVec3(resolution).norm();
  BoundingBox bounds = probed;
  if (fresh) {
    bounds.Extend(low);
    bounds.Extend(high);
  }
  sampler->origin_ = io_internal::OriginKeepingResolution(
      {bounds.min[0], bounds.min[1], bounds.min[2]}, {bounds.max[0], bounds.max[1], bounds.max[2]},
      resolution);
  const Vec3 origin = ToVec3(sampler->origin_);
  sampler->bounds_.Extend(bounds.min - origin);
  sampler->bounds_.Extend(bounds.max - origin);
  return sampler;
}

Vec3 LasFileSampler::Sample(Random& rng) const {
  Random tries(rng.NextU64());  // One draw of `rng` per sample, however many records it reads.
  while (true) {
    const uint64_t r = tries.NextIndex(records_.size());
    if (records_.Kept(r)) return ToVec3(records_.Position(r)) - ToVec3(origin_);
  }
}

void LasFileSampler::PrefetchSample(const Random& rng) const {
  Random peek = rng;
  Random tries(peek.NextU64());
  __builtin_prefetch(records_.Address(tries.NextIndex(records_.size())));
}

}  // namespace neuralmesh
