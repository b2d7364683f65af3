// Statistical outlier removal for point clouds, as PCL's StatisticalOutlierRemoval and
// Open3D's remove_statistical_outlier define it: for every point the mean distance d to its k
// nearest other points; a point whose d exceeds mean(d) + std_ratio * stddev(d), taken over
// all points, is an outlier. Not in the paper, whose learner treats a far outlier as a sample
// like any other and pulls a spike out to it (README, Status): a scan's stray points are
// best removed before learning. One pass, as those libraries make it: a few points very far
// away widen the deviation enough to hide milder outliers (strays at 1,000 radii from a unit
// sphere hide one at 2 radii); a second pass over the kept points finds those
// (RemoveStatisticalOutliers with `passes`).
#ifndef NEURALMESH_CORE_ANALYSIS_STATISTICAL_OUTLIERS_H_
#define NEURALMESH_CORE_ANALYSIS_STATISTICAL_OUTLIERS_H_

#include <cstddef>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/point_cloud.h"

namespace neuralmesh {

struct OutlierOptions {
  int neighbours = 16;     // k, in [1, 256].
  double std_ratio = 3.0;  // > 0: how many standard deviations above the mean is too far.
  int threads = 0;  // Query threads; 0: one per hardware thread. Results do not depend on it.
  // In [1, 16]: the passes of RemoveStatisticalOutliers, each over the points the one before
  // kept. FindStatisticalOutliers makes one.
  int passes = 1;

  // INVALID_ARGUMENT naming the first field out of range.
  absl::Status Validate() const;
};

// One flag per point of `cloud`: true for an outlier. A cloud of at most `neighbours` points
// has none (there is nothing to compare a point with). O(n log n) for a k-d tree, then
// O(k log n) per point on well spread data. INVALID_ARGUMENT for invalid options.
absl::StatusOr<std::vector<bool>> FindStatisticalOutliers(const PointCloud& cloud,
                                                          const OutlierOptions& options);

// The distance above which a point is an outlier: mean + std_ratio * the sample standard
// deviation of `mean_distances` (each point's mean distance to its k nearest neighbours).
// Infinity for fewer than 2 distances.
double OutlierDistanceLimit(absl::Span<const double> mean_distances, double std_ratio);

// One flag per point of `cloud`: true for an outlier found in up to options.passes passes,
// each judging the points the one before kept (stopping at a pass that finds none).
// INVALID_ARGUMENT for invalid options.
absl::StatusOr<std::vector<bool>> FindStatisticalOutliersInPasses(const PointCloud& cloud,
                                                                  const OutlierOptions& options);

// Removes the outliers FindStatisticalOutliersInPasses finds; weights, normals and colours go
// with their points. Returns how many points went; INVALID_ARGUMENT for invalid options.
absl::StatusOr<size_t> RemoveStatisticalOutliers(PointCloud& cloud, const OutlierOptions& options);

// `cloud` without the points flagged in `drop` (one flag per point), weights, normals and
// colours kept with their points.
PointCloud WithoutPoints(const PointCloud& cloud, const std::vector<bool>& drop);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_STATISTICAL_OUTLIERS_H_
