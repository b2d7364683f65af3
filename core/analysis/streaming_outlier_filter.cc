#include "core/analysis/streaming_outlier_filter.h"

#include <algorithm>
#include <cstdint>

namespace neuralmesh {
namespace {

constexpr uint32_t kSkipNone = UINT32_MAX;

}  // namespace

StreamingOutlierFilter::StreamingOutlierFilter(const OutlierOptions& options) : options_(options) {}

void StreamingOutlierFilter::SearchSeen(const Vec3f& query, uint32_t skip,
                                        NeighbourHeap* heap) const {
  const size_t k = static_cast<size_t>(options_.neighbours);
  // Newest first: the small trees are cheap and fill the heap, so the large ones prune more.
  for (auto tree = trees_.rbegin(); tree != trees_.rend(); ++tree) {
    tree->Search(points_, query, skip, k, heap);
  }
}

std::vector<bool> StreamingOutlierFilter::FindOutliers(absl::Span<const Vec3f> batch) const {
  const size_t m = batch.size();
  const size_t k = static_cast<size_t>(options_.neighbours);
  std::vector<bool> outlier(m, false);
  if (points_.size() + m <= k) return outlier;

  const PointKdTree batch_tree(batch, 0, static_cast<uint32_t>(m));
  NeighbourHeap heap;
  // The batch's points, each skipping itself among the batch.
  std::vector<double> mean_distance(m);
  for (size_t i = 0; i < m; ++i) {
    SearchSeen(batch[i], kSkipNone, &heap);
    batch_tree.Search(batch, batch[i], static_cast<uint32_t>(i), k, &heap);
    mean_distance[i] = MeanDistance(heap);
  }
  // The reference population: the batch, and when it is small the points seen before.
  double limit = 0;
  if (m < kReferencePoints) {
    std::vector<double> reference = mean_distance;
    reference.insert(reference.end(), reference_.begin(), reference_.end());
    limit = OutlierDistanceLimit(reference, options_.std_ratio);
  } else {
    limit = OutlierDistanceLimit(mean_distance, options_.std_ratio);
  }
  for (size_t i = 0; i < m; ++i) outlier[i] = mean_distance[i] > limit;
  return outlier;
}

void StreamingOutlierFilter::Add(absl::Span<const Vec3f> batch) {
  const auto begin = static_cast<uint32_t>(points_.size());
  points_.insert(points_.end(), batch.begin(), batch.end());
  const auto end = static_cast<uint32_t>(points_.size());
  if (end == begin) return;
  // The new points form the newest tree; while the tree before it is at most twice its size,
  // the two are rebuilt as one, so sizes at least double toward the oldest tree.
  uint32_t first = begin;
  while (!trees_.empty() && trees_.back().size() <= 2 * static_cast<size_t>(end - first)) {
    first = trees_.back().begin();
    trees_.pop_back();
  }
  trees_.emplace_back(points_, first, end);
  if (points_.size() - reference_measured_at_ > points_.size() / 16 || reference_.empty()) {
    MeasureReference();
  }
}

void StreamingOutlierFilter::MeasureReference() {
  const size_t n = points_.size();
  const size_t count = std::min(n, kReferencePoints);
  reference_.resize(count);
  NeighbourHeap heap;
  for (size_t j = 0; j < count; ++j) {
    const auto index = static_cast<uint32_t>(j * n / count);
    SearchSeen(points_[index], index, &heap);
    reference_[j] = MeanDistance(heap);
  }
  reference_measured_at_ = n;
}

}  // namespace neuralmesh
