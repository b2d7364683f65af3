// A static k-d tree over a contiguous range of a point array, for k-nearest-neighbour queries
// (statistical outlier removal, statistical_outliers.h and streaming_outlier_filter.h). The
// tree keeps indices into the array, not the points: callers pass the array to every call, so
// it may grow (and move) between calls as long as the tree's range stays as it was built.
#ifndef NEURALMESH_CORE_ANALYSIS_POINT_KD_TREE_H_
#define NEURALMESH_CORE_ANALYSIS_POINT_KD_TREE_H_

#include <cstddef>
#include <cstdint>
#include <queue>
#include <utility>
#include <vector>

#include "absl/types/span.h"
#include "core/mesh.h"

namespace neuralmesh {

// The k nearest points found so far, the farthest on top: (squared distance, index).
using NeighbourHeap = std::priority_queue<std::pair<float, uint32_t>>;

// The mean of the distances (not squared) in `heap`, 0 when it is empty. Empties the heap.
double MeanDistance(NeighbourHeap& heap);

class PointKdTree {
 public:
  // Over points[begin, end). Each node splits its range at the median of the axis of largest
  // extent; ranges of at most 8 points are leaves. O(n log n).
  PointKdTree(absl::Span<const Vec3f> points, uint32_t begin, uint32_t end);

  uint32_t begin() const { return begin_; }
  uint32_t end() const { return end_; }
  size_t size() const { return end_ - begin_; }

  // Offers every point of the range that may be among the k nearest to `query` to `heap`
  // (which holds at most k), skipping the point of index `skip` (pass UINT32_MAX to skip
  // none). Heaps may be shared between trees: a query over several trees gives the k nearest
  // of their union. `points` is the array the tree was built over (or that array grown).
  void Search(absl::Span<const Vec3f> points, const Vec3f& query, uint32_t skip, size_t k,
              NeighbourHeap* heap) const;

 private:
  struct Split {
    int axis = 0;
    float value = 0;
  };

  void Build(absl::Span<const Vec3f> points, size_t begin, size_t end);
  void SearchRange(absl::Span<const Vec3f> points, size_t begin, size_t end, const Vec3f& query,
                   uint32_t skip, size_t k, NeighbourHeap* heap) const;

  uint32_t begin_;
  uint32_t end_;
  std::vector<uint32_t> order_;  // The range's indices, ordered by the splits.
  // The split of the range [b, e) of order_ lives at its midpoint's slot (no two ranges of
  // more than a leaf's points share a midpoint).
  std::vector<Split> splits_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_POINT_KD_TREE_H_
