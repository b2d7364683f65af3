// Statistical outlier removal (statistical_outliers.h) for points that arrive in batches, as
// they do in a service session: each batch is judged against every point seen before it.
//
// A batch's point is an outlier when its mean distance d to its k nearest other points, among
// the points seen so far and the batch's own, exceeds mean + std_ratio * stddev of d over a
// reference population: the batch's points, and when they are fewer than kReferencePoints,
// also kReferencePoints points seen before, evenly spread over their arrival order, whose d
// was measured among the points seen when their number was at most 1/16 below what it is now
// (remeasured as it grows). So a batch of one point is judged by the density the cloud has
// now at the cost of a few searches, and a batch that is one region of a scan is judged with
// the neighbours its edges have in earlier batches. The seen points include the outliers
// dropped before, as FindStatisticalOutliers counts every point of the cloud: left out, a
// random gap in the data would stay sparse while the rest fills in, and ever more points
// falling into it would be dropped (on 20,000 sphere points sent one at a time, 1.8% instead
// of 0.3%). While the seen points and the batch together number at most k, nothing is an
// outlier (there is nothing to compare with); on a whole cloud sent as one batch the two
// filters agree exactly.
//
// The seen points are indexed by a logarithmic forest of static k-d trees (Bentley and Saxe):
// trees over consecutive ranges of the seen points whose sizes at least double from the
// newest to the oldest, so adding n points in any batches costs O(n log^2 n) in all and a
// query O(log^2 n). Memory: about 24 bytes per point seen.
#ifndef NEURALMESH_CORE_ANALYSIS_STREAMING_OUTLIER_FILTER_H_
#define NEURALMESH_CORE_ANALYSIS_STREAMING_OUTLIER_FILTER_H_

#include <cstddef>
#include <vector>

#include "absl/types/span.h"
#include "core/analysis/point_kd_tree.h"
#include "core/analysis/statistical_outliers.h"
#include "core/mesh.h"

namespace neuralmesh {

class StreamingOutlierFilter {
 public:
  // Batches smaller than this are judged with the reference of points seen before.
  static constexpr size_t kReferencePoints = 1024;

  // `options` must pass OutlierOptions::Validate; its `threads` is not used (one thread).
  explicit StreamingOutlierFilter(const OutlierOptions& options);

  // One flag per point of `batch`, true for an outlier, judged against the points seen so far.
  // Changes nothing. Every coordinate of `batch` must be finite.
  std::vector<bool> FindOutliers(absl::Span<const Vec3f> batch) const;

  // Adds every point of `batch`, outliers included, to the points seen. O(m log^2 n) amortised
  // for m points, n seen.
  void Add(absl::Span<const Vec3f> batch);

  // Points seen so far.
  size_t size() const { return points_.size(); }

 private:
  // Offers the k nearest of the points seen to `query` (skipping seen point `skip`, or none
  // for UINT32_MAX) to `heap`.
  void SearchSeen(const Vec3f& query, uint32_t skip, NeighbourHeap* heap) const;

  // Measures the reference again: the mean neighbour distances of up to kReferencePoints
  // points seen, evenly spread over their arrival order.
  void MeasureReference();

  OutlierOptions options_;
  std::vector<Vec3f> points_;         // Seen, in arrival order.
  std::vector<PointKdTree> trees_;    // Over consecutive ranges of points_, oldest first.
  std::vector<double> reference_;     // Mean neighbour distances of points seen.
  size_t reference_measured_at_ = 0;  // points_.size() when reference_ was measured.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_STREAMING_OUTLIER_FILTER_H_
