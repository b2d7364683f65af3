// Samplers over a fixed point cloud: the usual target space P of the paper (Section 2.1, the
// discrete uniform distribution) and its non-uniform variant where each point carries a
// confidence weight (Section 4.1, e.g. points from range images).
//
// Ownership: the samplers share the cloud through std::shared_ptr<const PointCloud>, so a
// cloud of tens of millions of points is never copied and whoever else holds it (the session
// that received it, a report) keeps using the same memory. Build one with
// std::make_shared<const PointCloud>(std::move(cloud)).
#ifndef NEURALMESH_CORE_SAMPLING_POINT_CLOUD_SAMPLER_H_
#define NEURALMESH_CORE_SAMPLING_POINT_CLOUD_SAMPLER_H_

#include <memory>

#include "absl/status/statusor.h"
#include "core/bounding_box.h"
#include "core/point_cloud.h"
#include "core/random.h"
#include "core/sampling/alias_table.h"
#include "core/sampling/sampler.h"

namespace neuralmesh {

// Draws every point with the same probability 1/n; weights, if any, are ignored.
class UniformPointCloudSampler final : public Sampler {
 public:
  // Returns INVALID_ARGUMENT when `cloud` is null or empty or fails ValidatePointCloud.
  // O(n) for the validation and the bounding box.
  static absl::StatusOr<std::unique_ptr<Sampler>> Create(std::shared_ptr<const PointCloud> cloud);

  Vec3 Sample(Random& rng) const override;  // O(1): one NextIndex.
  // Peeks at the next index with a copy of `rng`.
  void PrefetchSample(const Random& rng) const override;
  bool empty() const override { return false; }
  BoundingBox Bounds() const override { return bounds_; }
  const PointCloud& cloud() const { return *cloud_; }

 private:
  UniformPointCloudSampler(std::shared_ptr<const PointCloud> cloud, const BoundingBox& bounds);

  std::shared_ptr<const PointCloud> cloud_;
  BoundingBox bounds_;
};

// Draws point i with probability weights[i] / sum(weights) (Section 4.1: per-point
// confidence), through an alias table. Points of weight zero are never drawn; Bounds() still
// covers them.
class WeightedPointCloudSampler final : public Sampler {
 public:
  // Returns INVALID_ARGUMENT when `cloud` is null or empty, has no weights, or fails
  // ValidatePointCloud (which also rejects all-zero weights). O(n) build, 12 bytes per point.
  static absl::StatusOr<std::unique_ptr<Sampler>> Create(std::shared_ptr<const PointCloud> cloud);

  Vec3 Sample(Random& rng) const override;  // O(1): one alias-table draw.
  // A draw reads a table cell, then the point it names, one cache miss after the other: loaded
  // over two calls, one Basic Step apart. Reads the next draw's cell, which the last call
  // started loading, starts loading its point, and the cell of the draw after it.
  void PrefetchSample(const Random& rng) const override;
  bool empty() const override { return false; }
  BoundingBox Bounds() const override { return bounds_; }
  const PointCloud& cloud() const { return *cloud_; }

 private:
  WeightedPointCloudSampler(std::shared_ptr<const PointCloud> cloud, AliasTable table,
                            const BoundingBox& bounds);

  std::shared_ptr<const PointCloud> cloud_;
  AliasTable table_;
  BoundingBox bounds_;
};

// The sampler the cloud asks for: weighted when it carries weights, uniform otherwise.
// Returns INVALID_ARGUMENT as the two Create functions above.
absl::StatusOr<std::unique_ptr<Sampler>> MakePointCloudSampler(
    std::shared_ptr<const PointCloud> cloud);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_POINT_CLOUD_SAMPLER_H_
