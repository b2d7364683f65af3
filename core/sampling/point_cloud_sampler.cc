#include "core/sampling/point_cloud_sampler.h"

#include <utility>

#include "core/huge_page_allocator.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

absl::Status CheckUsable(const std::shared_ptr<const PointCloud>& cloud) {
  if (cloud == nullptr) return absl::InvalidArgumentError("the point cloud is null");
  if (cloud->empty()) return absl::InvalidArgumentError("the point cloud has no points");
  return ValidatePointCloud(*cloud);
}

// Every Basic Step reads one point at random: on a large cloud, with 4 KB pages, a TLB miss as
// well as a cache miss (huge_page_allocator.h).
void UseHugePages(const PointCloud& cloud) {
  AdviseHugePages(cloud.positions.data(), cloud.positions.size() * sizeof(Vec3f));
}

BoundingBox BoundsOf(const PointCloud& cloud) {
  BoundingBox box;
  for (const Vec3f& p : cloud.positions) box.Extend(Vec3(p));
  return box;
}

}  // namespace

absl::StatusOr<std::unique_ptr<Sampler>> UniformPointCloudSampler::Create(
    std::shared_ptr<const PointCloud> cloud) {
  NM_RETURN_IF_ERROR(CheckUsable(cloud));
  const BoundingBox bounds = BoundsOf(*cloud);
  UseHugePages(*cloud);
  return std::unique_ptr<Sampler>(new UniformPointCloudSampler(std::move(cloud), bounds));
}

UniformPointCloudSampler::UniformPointCloudSampler(std::shared_ptr<const PointCloud> cloud,
                                                   const BoundingBox& bounds)
    : cloud_(std::move(cloud)), bounds_(bounds) {}

Vec3 UniformPointCloudSampler::Sample(Random& rng) const {
  return Vec3(cloud_->positions[rng.NextIndex(cloud_->positions.size())]);
}

void UniformPointCloudSampler::PrefetchSample(const Random& rng) const {
  Random peek = rng;
  __builtin_prefetch(&cloud_->positions[peek.NextIndex(cloud_->positions.size())]);
}

absl::StatusOr<std::unique_ptr<Sampler>> WeightedPointCloudSampler::Create(
    std::shared_ptr<const PointCloud> cloud) {
  NM_RETURN_IF_ERROR(CheckUsable(cloud));
  if (cloud->weights.empty()) {
    return absl::InvalidArgumentError("the point cloud has no weights to sample by");
  }
  NM_ASSIGN_OR_RETURN(AliasTable table, AliasTable::Create(cloud->weights));
  const BoundingBox bounds = BoundsOf(*cloud);
  UseHugePages(*cloud);
  return std::unique_ptr<Sampler>(
      new WeightedPointCloudSampler(std::move(cloud), std::move(table), bounds));
}

WeightedPointCloudSampler::WeightedPointCloudSampler(std::shared_ptr<const PointCloud> cloud,
                                                     AliasTable table, const BoundingBox& bounds)
    : cloud_(std::move(cloud)), table_(std::move(table)), bounds_(bounds) {}

Vec3 WeightedPointCloudSampler::Sample(Random& rng) const {
  return Vec3(cloud_->positions[table_.Draw(rng)]);
}

void WeightedPointCloudSampler::PrefetchSample(const Random& rng) const {
  Random peek = rng;
  __builtin_prefetch(&cloud_->positions[table_.Draw(peek)]);
  table_.PrefetchDraw(peek);  // Draw takes a fixed number of draws: peek is the next state.
}

absl::StatusOr<std::unique_ptr<Sampler>> MakePointCloudSampler(
    std::shared_ptr<const PointCloud> cloud) {
  if (cloud != nullptr && !cloud->weights.empty()) {
    return WeightedPointCloudSampler::Create(std::move(cloud));
  }
  return UniformPointCloudSampler::Create(std::move(cloud));
}

}  // namespace neuralmesh
