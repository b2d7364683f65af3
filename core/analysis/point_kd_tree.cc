#include "core/analysis/point_kd_tree.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace neuralmesh {
namespace {

constexpr size_t kLeafPoints = 8;

}  // namespace

double MeanDistance(NeighbourHeap& heap) {
  double sum = 0;
  const size_t found = heap.size();
  for (; !heap.empty(); heap.pop()) sum += std::sqrt(static_cast<double>(heap.top().first));
  return found == 0 ? 0 : sum / static_cast<double>(found);
}

PointKdTree::PointKdTree(absl::Span<const Vec3f> points, uint32_t begin, uint32_t end)
    : begin_(begin), end_(end), order_(end - begin), splits_(end - begin) {
  std::iota(order_.begin(), order_.end(), begin);
  Build(points, 0, order_.size());
}

void PointKdTree::Build(absl::Span<const Vec3f> points, size_t begin, size_t end) {
  if (end - begin <= kLeafPoints) return;
  Vec3f low = points[order_[begin]];
  Vec3f high = low;
  for (size_t i = begin; i < end; ++i) {
    low.minimize(points[order_[i]]);
    high.maximize(points[order_[i]]);
  }
  const Vec3f extent = high - low;
  const int axis = extent[0] >= extent[1] && extent[0] >= extent[2] ? 0
                   : extent[1] >= extent[2]                         ? 1
                                                                    : 2;
  const size_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](uint32_t a, uint32_t b) { return points[a][axis] < points[b][axis]; });
  splits_[mid] = Split{axis, points[order_[mid]][axis]};
  Build(points, begin, mid);
  Build(points, mid, end);
}

void PointKdTree::Search(absl::Span<const Vec3f> points, const Vec3f& query, uint32_t skip,
                         size_t k, NeighbourHeap* heap) const {
  if (k == 0 || order_.empty()) return;
  SearchRange(points, 0, order_.size(), query, skip, k, heap);
}

void PointKdTree::SearchRange(absl::Span<const Vec3f> points, size_t begin, size_t end,
                              const Vec3f& query, uint32_t skip, size_t k,
                              NeighbourHeap* heap) const {
  if (end - begin <= kLeafPoints) {
    for (size_t i = begin; i < end; ++i) {
      const uint32_t id = order_[i];
      if (id == skip) continue;
      const float d2 = (points[id] - query).sqrnorm();
      if (heap->size() < k) {
        heap->emplace(d2, id);
      } else if (d2 < heap->top().first) {
        heap->pop();
        heap->emplace(d2, id);
      }
    }
    return;
  }
  const size_t mid = begin + (end - begin) / 2;
  const Split& split = splits_[mid];
  const float offset = query[split.axis] - split.value;
  // The side holding the query first; the other only if it may hold a nearer point.
  const bool left_first = offset < 0;
  if (left_first) {
    SearchRange(points, begin, mid, query, skip, k, heap);
  } else {
    SearchRange(points, mid, end, query, skip, k, heap);
  }
  if (heap->size() < k || offset * offset < heap->top().first) {
    if (left_first) {
      SearchRange(points, mid, end, query, skip, k, heap);
    } else {
      SearchRange(points, begin, mid, query, skip, k, heap);
    }
  }
}

}  // namespace neuralmesh
