#include "core/analysis/statistical_outliers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <queue>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

constexpr int kMaxNeighbours = 256;
constexpr size_t kLeafPoints = 8;

// A k-d tree over an index permutation: each node splits its range at the median of the axis
// of largest extent; ranges of at most kLeafPoints are leaves.
class KdTree {
 public:
  explicit KdTree(const std::vector<Vec3f>& points)
      : points_(points), order_(points.size()), splits_(points.size()) {
    std::iota(order_.begin(), order_.end(), 0u);
    Build(0, order_.size());
  }

  // The mean distance from point `query` to its k nearest other points.
  double MeanNeighbourDistance(uint32_t query, size_t k) const {
    Heap heap;  // The k nearest so far, the farthest on top: (squared distance, index).
    Search(0, order_.size(), query, k, &heap);
    double sum = 0;
    const size_t found = heap.size();
    for (; !heap.empty(); heap.pop()) sum += std::sqrt(heap.top().first);
    return found == 0 ? 0 : sum / static_cast<double>(found);
  }

 private:
  using Heap = std::priority_queue<std::pair<float, uint32_t>>;
  struct Split {
    int axis = 0;
    float value = 0;
  };

  // The split of the range [begin, end) lives at its midpoint's slot in splits_ (no two
  // ranges of more than kLeafPoints share a midpoint).
  void Build(size_t begin, size_t end) {
    if (end - begin <= kLeafPoints) return;
    Vec3f low = points_[order_[begin]];
    Vec3f high = low;
    for (size_t i = begin; i < end; ++i) {
      low.minimize(points_[order_[i]]);
      high.maximize(points_[order_[i]]);
    }
    const Vec3f extent = high - low;
    const int axis = extent[0] >= extent[1] && extent[0] >= extent[2] ? 0
                     : extent[1] >= extent[2]                         ? 1
                                                                      : 2;
    const size_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](uint32_t a, uint32_t b) { return points_[a][axis] < points_[b][axis]; });
    splits_[mid] = Split{axis, points_[order_[mid]][axis]};
    Build(begin, mid);
    Build(mid, end);
  }

  void Search(size_t begin, size_t end, uint32_t query, size_t k, Heap* heap) const {
    const Vec3f& q = points_[query];
    if (end - begin <= kLeafPoints) {
      for (size_t i = begin; i < end; ++i) {
        const uint32_t id = order_[i];
        if (id == query) continue;
        const float d2 = (points_[id] - q).sqrnorm();
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
    const float offset = q[split.axis] - split.value;
    // The side holding the query first; the other only if it may hold a nearer point.
    const bool left_first = offset < 0;
    if (left_first) {
      Search(begin, mid, query, k, heap);
    } else {
      Search(mid, end, query, k, heap);
    }
    if (heap->size() < k || offset * offset < heap->top().first) {
      if (left_first) {
        Search(mid, end, query, k, heap);
      } else {
        Search(begin, mid, query, k, heap);
      }
    }
  }

  const std::vector<Vec3f>& points_;
  std::vector<uint32_t> order_;
  std::vector<Split> splits_;
};

}  // namespace

absl::Status OutlierOptions::Validate() const {
  if (neighbours < 1 || neighbours > kMaxNeighbours) {
    return absl::InvalidArgumentError(absl::StrCat("outlier neighbours = ", neighbours,
                                                   " is out of range; it must be in [1, ",
                                                   kMaxNeighbours, "]"));
  }
  if (!(std_ratio > 0) || !std::isfinite(std_ratio)) {
    return absl::InvalidArgumentError(absl::StrCat("outlier std_ratio = ", std_ratio,
                                                   " is out of range; it must be finite and > 0"));
  }
  if (threads < 0) return absl::InvalidArgumentError("outlier threads must be >= 0");
  return absl::OkStatus();
}

absl::StatusOr<std::vector<bool>> FindStatisticalOutliers(const PointCloud& cloud,
                                                          const OutlierOptions& options) {
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  const size_t n = cloud.size();
  const size_t k = static_cast<size_t>(options.neighbours);
  std::vector<bool> outlier(n, false);
  if (n <= k) return outlier;
  const KdTree tree(cloud.positions);
  std::vector<double> mean_distance(n);
  size_t threads = options.threads > 0 ? static_cast<size_t>(options.threads)
                                       : std::max(1u, std::thread::hardware_concurrency());
  threads = std::min(threads, std::max<size_t>(1, n / 4096));
  auto measure = [&](size_t first, size_t last) {
    for (size_t i = first; i < last; ++i) {
      mean_distance[i] = tree.MeanNeighbourDistance(static_cast<uint32_t>(i), k);
    }
  };
  std::vector<std::thread> workers;
  for (size_t t = 1; t < threads; ++t) {
    workers.emplace_back(measure, n * t / threads, n * (t + 1) / threads);
  }
  measure(0, n / threads);
  for (std::thread& worker : workers) worker.join();

  double sum = 0;
  for (double d : mean_distance) sum += d;
  const double mean = sum / static_cast<double>(n);
  double squares = 0;
  for (double d : mean_distance) squares += (d - mean) * (d - mean);
  const double deviation = std::sqrt(squares / static_cast<double>(n - 1));
  const double limit = mean + options.std_ratio * deviation;
  for (size_t i = 0; i < n; ++i) outlier[i] = mean_distance[i] > limit;
  return outlier;
}

PointCloud WithoutPoints(const PointCloud& cloud, const std::vector<bool>& drop) {
  PointCloud kept;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (i < drop.size() && drop[i]) continue;
    kept.positions.push_back(cloud.positions[i]);
    if (!cloud.weights.empty()) kept.weights.push_back(cloud.weights[i]);
    if (!cloud.normals.empty()) kept.normals.push_back(cloud.normals[i]);
  }
  return kept;
}

}  // namespace neuralmesh
