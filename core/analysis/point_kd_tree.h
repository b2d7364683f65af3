// A static k-d tree over a contiguous range of a point array, for k-nearest-neighbour queries
// (statistical outlier removal, statistical_outliers.h and streaming_outlier_filter.h; the
// colours of points, color_source.h; the error against points, geometric_error.h). The tree
// holds a copy of the range's points, in the order of its leaves, with their indices in the
// array: the array may change or go once the tree is built, and a search reads each leaf's
// points from one place rather than from all over the array.
#ifndef NEURALMESH_CORE_ANALYSIS_POINT_KD_TREE_H_
#define NEURALMESH_CORE_ANALYSIS_POINT_KD_TREE_H_

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "absl/types/span.h"
#include "core/mesh.h"

namespace neuralmesh {

// The k nearest points found so far, the farthest on top: (squared distance, index) pairs,
// popped in descending order of the pairs (as a std::priority_queue of them pops). Kept sorted
// in a small array: k is at most a few hundred, and most points offered are refused by one
// comparison with the top.
class NeighbourHeap {
 public:
  using Entry = std::pair<float, uint32_t>;

  bool empty() const { return entries_.empty(); }
  size_t size() const { return entries_.size(); }
  const Entry& top() const { return entries_.back(); }
  void pop() { entries_.pop_back(); }

  // Offers a point to a heap of at most k: taken while the heap holds fewer, else in place of
  // the top when it is nearer than the top (by distance alone).
  void Offer(float squared_distance, uint32_t index, size_t k) {
    if (entries_.size() < k) {
      Insert({squared_distance, index});
    } else if (squared_distance < entries_.back().first) {
      entries_.pop_back();
      Insert({squared_distance, index});
    }
  }

 private:
  void Insert(const Entry& entry) {
    size_t i = entries_.size();
    entries_.push_back(entry);
    for (; i > 0 && entry < entries_[i - 1]; --i) entries_[i] = entries_[i - 1];
    entries_[i] = entry;
  }

  std::vector<Entry> entries_;  // Ascending.
};

// The mean of the distances (not squared) in `heap`, 0 when it is empty. Empties the heap.
double MeanDistance(NeighbourHeap& heap);

class PointKdTree {
 public:
  // A point of the range, with its index in the array the tree was built over.
  struct LeafPoint {
    Vec3f position;
    uint32_t index;
  };

  // Over points[begin, end), which the tree copies: each node splits its range at the median of
  // the axis of largest extent; ranges of at most 8 points are leaves. O(n log n), on `threads`
  // threads (0: one per hardware thread); the tree does not depend on them. 16 bytes a point,
  // and at most 2 more for the splits.
  PointKdTree(absl::Span<const Vec3f> points, uint32_t begin, uint32_t end, int threads = 1);

  // The tree over `points`, whose indices are consecutive and in order (points[i].index ==
  // points[0].index + i): over the points of other trees (their leaf_order(), put back in the
  // order of their indices) without the array they came from. The same tree as the one over
  // that array.
  static PointKdTree FromLeafPoints(std::vector<LeafPoint> points, int threads = 1);
  // The tree over the points of `trees` and `appended` (the points of indices appended_begin
  // on), whose ranges together are one range of the array: for rebuilding trees as points
  // arrive without keeping the array. The trees' points are put back by index (FromLeafPoints),
  // each tree freed once its points are out, so that at most one more copy of the points is held
  // meanwhile. The same tree as the one over the array.
  static PointKdTree Merged(std::vector<PointKdTree> trees, uint32_t appended_begin,
                            absl::Span<const Vec3f> appended, int threads = 1);

  uint32_t begin() const { return begin_; }
  uint32_t end() const { return end_; }
  size_t size() const { return end_ - begin_; }
  // The range's points in the order of the tree's leaves: points near one another in it are
  // near in space, so queries made in this order find their nodes and points in cache.
  absl::Span<const LeafPoint> leaf_order() const { return leaves_; }

  // Offers every point of the range that may be among the k nearest to `query` to `heap`
  // (which holds at most k), skipping the point of index `skip` (pass UINT32_MAX to skip
  // none). Heaps may be shared between trees: a query over several trees gives the k nearest
  // of their union.
  void Search(const Vec3f& query, uint32_t skip, size_t k, NeighbourHeap* heap) const;

 private:
  struct Split {
    int axis = 0;
    float value = 0;
  };

  // What a search carries down the tree: the query, and per axis how far the query lies outside
  // the current range's cell along it (0 inside).
  struct Query {
    Vec3f position;
    uint32_t skip;
    size_t k;
    Vec3f outside{0, 0, 0};

    // A lower bound of the squared distance to every point of the cell, as the points' are
    // computed: each of the point's offsets is at least the cell's, and the sum of their
    // squares rounds monotonically; one part in a million below it, in case the compiler
    // rounds the two sums differently (a fused multiply-add in one of them).
    float CellSquaredDistance() const { return outside.sqrnorm() * (1.0f - 1e-6f); }
  };

  // Over `leaves`, the points of indices [begin, begin + leaves.size()) in that order.
  PointKdTree(uint32_t begin, std::vector<LeafPoint> leaves, int threads);

  // Node `node` splits leaves_[begin, end); its children are nodes 2 node + 1 (the lower half)
  // and 2 node + 2.
  void Build(size_t node, size_t begin, size_t end, int threads);
  void SearchRange(size_t node, size_t begin, size_t end, Query& query, NeighbourHeap* heap) const;

  uint32_t begin_;
  uint32_t end_;
  std::vector<LeafPoint> leaves_;  // The range's points, ordered by the splits.
  std::vector<Split> splits_;      // By node.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_POINT_KD_TREE_H_
