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
// the neighbours its edges have in earlier batches. The seen points include the outliers,
// as FindStatisticalOutliers counts every point of the cloud: left out, a random gap in the
// data would stay sparse while the rest fills in, and ever more points falling into it would
// be dropped (on 20,000 sphere points sent one at a time, 1.8% instead of 0.3%). While the
// seen points and the batch together number at most k, nothing is an outlier (there is
// nothing to compare with); on a whole cloud sent as one batch the two filters agree exactly.
//
// An outlier is held, not dropped at once: a point at the leading edge of a scan sent region
// by region has its neighbours on one side only until the next region arrives (a million
// sphere points swept along x in batches of 1,000 lost 0.93% that way, 0.30% filtered whole).
// A held point is judged again each time k/4 points have come closer to it than its k-th
// neighbour was when last judged, which is all that changes its mean distance: accepted as
// soon as it passes, dropped for good when it fails for the 4th time, its neighbourhood
// renewed by about k points. These judgements use the reference's limit alone: with the
// batch's own spread in it, a stray judged at every batch passed once some batch held enough
// strays to widen the limit. Points still held when the stream ends keep their last verdict
// and are dropped (DropHeld). A held point costs at most 4 more searches among the points
// seen, and at each batch a box test, and a search among the batch's points when the batch's
// box comes within its k-th neighbour's distance (a stray's is far, so nearly every batch
// does): with 1% strays, 100,000 sphere points streamed in batches of 1 to 1,000 took 1.1-1.4
// times as long as judged on arrival only.
//
// The seen points are indexed by a logarithmic forest of static k-d trees (Bentley and Saxe):
// trees over consecutive ranges of the seen points whose sizes at least double from the
// newest to the oldest, so adding n points in any batches costs O(n log^2 n) in all and a
// query O(log^2 n). The trees hold the points (PointKdTree): about 18 bytes per point seen, 16
// more per point of the trees being merged while a batch is added, and 28 per point held.
#ifndef NEURALMESH_CORE_ANALYSIS_STREAMING_OUTLIER_FILTER_H_
#define NEURALMESH_CORE_ANALYSIS_STREAMING_OUTLIER_FILTER_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/types/span.h"
#include "core/analysis/point_kd_tree.h"
#include "core/analysis/statistical_outliers.h"
#include "core/mesh.h"

namespace neuralmesh {

// What the filter decides when a batch arrives. Points are named by their arrival index: their
// position among every point the filter has seen, batch after batch, outliers included.
struct OutlierJudgement {
  // One flag per point of the batch: true for an outlier, held back.
  std::vector<bool> held;
  // Points held back by earlier batches that pass now and are to be accepted; ascending.
  std::vector<uint32_t> released;
  // Points held back by earlier batches that are outliers for good; ascending.
  std::vector<uint32_t> dropped;

 private:
  friend class StreamingOutlierFilter;
  // A point held back: its arrival index and position, the squared distance to its k-th
  // nearest neighbour when last judged, how many points have come closer than that since (up
  // to k/4), and how many judgements after its arrival it has failed.
  struct HeldPoint {
    uint32_t index;
    Vec3f position;
    float radius_squared;
    uint32_t arrivals;
    uint32_t failures;
  };
  std::vector<HeldPoint> still_held_;  // The held points once the batch is added.
};

class StreamingOutlierFilter {
 public:
  // Batches smaller than this are judged with the reference of points seen before.
  static constexpr size_t kReferencePoints = 1024;

  // `options` must pass OutlierOptions::Validate; its `threads` is not used (one thread).
  explicit StreamingOutlierFilter(const OutlierOptions& options);

  // Judges `batch` against the points seen so far, and again the held points whose
  // neighbourhoods the batch renews. Changes nothing: Add(batch, judgement) does, unless the
  // batch is refused. Every coordinate of `batch` must be finite. Costs k-nearest searches for
  // the batch's points and for the held points the batch comes near, O(1) for the others.
  OutlierJudgement Judge(absl::Span<const Vec3f> batch) const;

  // Adds every point of `batch`, outliers included, to the points seen, and keeps the held
  // points as `judgement`, which Judge(batch) returned with no other Add in between, says
  // (moved in, its held points are taken over, not copied). O(m log^2 n) amortised for m
  // points, n seen.
  void Add(absl::Span<const Vec3f> batch, OutlierJudgement judgement);

  // Ends the stream: returns the points still held (ascending), which are outliers for good,
  // and holds none any more.
  std::vector<uint32_t> DropHeld();

  // Points seen so far, and those of them held back now.
  size_t size() const { return size_; }
  size_t held() const { return held_.size(); }

 private:
  // Offers the k nearest of the points seen to `query` (skipping seen point `skip`, or none
  // for UINT32_MAX) to `heap`.
  void SearchSeen(const Vec3f& query, uint32_t skip, NeighbourHeap* heap) const;

  // Measures the reference again: the mean neighbour distances of up to kReferencePoints
  // points seen, evenly spread over their arrival order.
  void MeasureReference();

  OutlierOptions options_;
  size_t size_ = 0;  // Points seen.
  // Over consecutive ranges of the points seen, in arrival order, oldest first: the only copy
  // of the points.
  std::vector<PointKdTree> trees_;
  std::vector<double> reference_;     // Mean neighbour distances of points seen.
  size_t reference_measured_at_ = 0;  // size_ when reference_ was measured.
  std::vector<OutlierJudgement::HeldPoint> held_;  // By arrival index.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_STREAMING_OUTLIER_FILTER_H_
