#include "core/analysis/point_kd_tree.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <utility>

namespace neuralmesh {
namespace {

constexpr size_t kLeafPoints = 8;
// Ranges smaller than this are built on the thread that split them.
constexpr size_t kMinPointsPerThread = 1 << 16;

std::vector<PointKdTree::LeafPoint> LeafPointsOf(absl::Span<const Vec3f> points, uint32_t begin,
                                                 uint32_t end) {
  std::vector<PointKdTree::LeafPoint> leaves(end - begin);
  for (uint32_t i = begin; i < end; ++i) leaves[i - begin] = {points[i], i};
  return leaves;
}

}  // namespace

double MeanDistance(NeighbourHeap& heap) {
  double sum = 0;
  const size_t found = heap.size();
  for (; !heap.empty(); heap.pop()) sum += std::sqrt(static_cast<double>(heap.top().first));
  return found == 0 ? 0 : sum / static_cast<double>(found);
}

PointKdTree::PointKdTree(absl::Span<const Vec3f> points, uint32_t begin, uint32_t end, int threads)
    : PointKdTree(begin, LeafPointsOf(points, begin, end), threads) {}

PointKdTree PointKdTree::FromLeafPoints(std::vector<LeafPoint> points, int threads) {
  const uint32_t begin = points.empty() ? 0 : points.front().index;
  return PointKdTree(begin, std::move(points), threads);
}

PointKdTree PointKdTree::Merged(std::vector<PointKdTree> trees, uint32_t appended_begin,
                                absl::Span<const Vec3f> appended, int threads) {
  uint32_t first = appended_begin;
  for (const PointKdTree& tree : trees) first = std::min(first, tree.begin());
  const auto end = appended_begin + static_cast<uint32_t>(appended.size());
  std::vector<LeafPoint> points(end - first);
  for (uint32_t i = appended_begin; i < end; ++i) {
    points[i - first] = {appended[i - appended_begin], i};
  }
  for (; !trees.empty(); trees.pop_back()) {
    for (const LeafPoint& point : trees.back().leaf_order()) points[point.index - first] = point;
  }
  return FromLeafPoints(std::move(points), threads);
}

PointKdTree::PointKdTree(uint32_t begin, std::vector<LeafPoint> leaves, int threads)
    : begin_(begin),
      end_(begin + static_cast<uint32_t>(leaves.size())),
      leaves_(std::move(leaves)) {
  // The tree's nodes down to the last level that splits (halves round up).
  size_t levels = 0;
  for (size_t range = leaves_.size(); range > kLeafPoints; range = (range + 1) / 2) ++levels;
  splits_.resize((size_t{1} << levels) - 1);
  Build(
      0, 0, leaves_.size(),
      threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
}

void PointKdTree::Build(size_t node, size_t begin, size_t end, int threads) {
  if (end - begin <= kLeafPoints) return;
  Vec3f low = leaves_[begin].position;
  Vec3f high = low;
  for (size_t i = begin; i < end; ++i) {
    low.minimize(leaves_[i].position);
    high.maximize(leaves_[i].position);
  }
  const Vec3f extent = high - low;
  const int axis = extent[0] >= extent[1] && extent[0] >= extent[2] ? 0
                   : extent[1] >= extent[2]                         ? 1
                                                                    : 2;
  const size_t mid = begin + (end - begin) / 2;
  std::nth_element(leaves_.begin() + begin, leaves_.begin() + mid, leaves_.begin() + end,
                   [axis](const LeafPoint& a, const LeafPoint& b) {
                     return a.position[axis] < b.position[axis];
                   });
  splits_[node] = Split{axis, leaves_[mid].position[axis]};
  // The halves are disjoint: on several threads, one builds the upper half meanwhile.
  if (threads > 1 && end - begin >= kMinPointsPerThread) {
    std::thread upper([&] { Build(2 * node + 2, mid, end, threads - threads / 2); });
    Build(2 * node + 1, begin, mid, threads / 2);
    upper.join();
  } else {
    Build(2 * node + 1, begin, mid, 1);
    Build(2 * node + 2, mid, end, 1);
  }
}

void PointKdTree::Search(const Vec3f& query, uint32_t skip, size_t k, NeighbourHeap* heap) const {
  if (k == 0 || leaves_.empty()) return;
  Query state{query, skip, k};
  SearchRange(0, 0, leaves_.size(), state, heap);
}

void PointKdTree::SearchRange(size_t node, size_t begin, size_t end, Query& query,
                              NeighbourHeap* heap) const {
  if (end - begin <= kLeafPoints) {
    for (size_t i = begin; i < end; ++i) {
      const LeafPoint& leaf = leaves_[i];
      if (leaf.index == query.skip) continue;
      heap->Offer((leaf.position - query.position).sqrnorm(), leaf.index, query.k);
    }
    return;
  }
  const size_t mid = begin + (end - begin) / 2;
  const Split& split = splits_[node];
  const float offset = query.position[split.axis] - split.value;
  // The side holding the query first; the other only if it may hold a nearer point: the
  // query's distance to its cell is below the farthest of the heap's.
  const bool lower_first = offset < 0;
  if (lower_first) {
    SearchRange(2 * node + 1, begin, mid, query, heap);
  } else {
    SearchRange(2 * node + 2, mid, end, query, heap);
  }
  float& outside = query.outside[split.axis];
  const float outside_before = outside;
  outside = std::abs(offset);  // The far side's cell is that of this range cut at the split.
  if (heap->size() < query.k || query.CellSquaredDistance() < heap->top().first) {
    if (lower_first) {
      SearchRange(2 * node + 2, mid, end, query, heap);
    } else {
      SearchRange(2 * node + 1, begin, mid, query, heap);
    }
  }
  outside = outside_before;
}

}  // namespace neuralmesh
