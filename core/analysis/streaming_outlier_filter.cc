#include "core/analysis/streaming_outlier_filter.h"

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <utility>

#include "core/bounding_box.h"

namespace neuralmesh {
namespace {

constexpr uint32_t kSkipNone = UINT32_MAX;

// A held point that fails this many judgements after its arrival is dropped for good.
constexpr uint32_t kJudgementsToDrop = 4;

}  // namespace

StreamingOutlierFilter::StreamingOutlierFilter(const OutlierOptions& options) : options_(options) {}

void StreamingOutlierFilter::SearchSeen(const Vec3f& query, uint32_t skip,
                                        NeighbourHeap* heap) const {
  const size_t k = static_cast<size_t>(options_.neighbours);
  // Newest first: the small trees are cheap and fill the heap, so the large ones prune more.
  for (auto tree = trees_.rbegin(); tree != trees_.rend(); ++tree) {
    tree->Search(query, skip, k, heap);
  }
}

OutlierJudgement StreamingOutlierFilter::Judge(absl::Span<const Vec3f> batch) const {
  const size_t m = batch.size();
  const size_t k = static_cast<size_t>(options_.neighbours);
  OutlierJudgement judgement;
  judgement.held.assign(m, false);
  if (m == 0 || size_ + m <= k) {
    judgement.still_held_ = held_;
    return judgement;
  }

  const PointKdTree batch_tree(batch, 0, static_cast<uint32_t>(m));
  NeighbourHeap heap;
  // The batch's points, each skipping itself among the batch.
  std::vector<double> mean_distance(m);
  std::vector<float> radius_squared(m);
  // In the batch tree's order, each query near the one before.
  for (const PointKdTree::LeafPoint& point : batch_tree.leaf_order()) {
    const uint32_t i = point.index;
    SearchSeen(point.position, kSkipNone, &heap);
    batch_tree.Search(point.position, i, k, &heap);
    radius_squared[i] = heap.top().first;
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

  // The points held before: each is judged again when the batch brings the k/4-th point closer
  // to it than its k-th neighbour was when last judged (nothing else changes its mean
  // distance), against the reference's limit, which does not follow the batch's spread.
  const double held_limit =
      reference_.size() >= 2 ? OutlierDistanceLimit(reference_, options_.std_ratio) : limit;
  const uint32_t arrivals_to_judge = std::max<uint32_t>(1, static_cast<uint32_t>(k / 4));
  BoundingBox box;
  for (const Vec3f& p : batch) box.Extend(Vec3(p));
  std::vector<OutlierJudgement::HeldPoint> still_held;
  for (OutlierJudgement::HeldPoint held : held_) {
    const Vec3f& q = held.position;
    // With a margin: the searches measure in floats, the box in doubles.
    if (box.SquaredDistance(Vec3(q)) > 1.0001 * static_cast<double>(held.radius_squared)) {
      still_held.push_back(held);
      continue;
    }
    batch_tree.Search(q, kSkipNone, arrivals_to_judge - held.arrivals, &heap);
    for (; !heap.empty(); heap.pop()) held.arrivals += heap.top().first < held.radius_squared;
    if (held.arrivals < arrivals_to_judge) {
      still_held.push_back(held);
      continue;
    }
    SearchSeen(q, held.index, &heap);
    batch_tree.Search(q, kSkipNone, k, &heap);
    held.radius_squared = heap.top().first;
    held.arrivals = 0;
    if (MeanDistance(heap) <= held_limit) {
      judgement.released.push_back(held.index);
    } else if (++held.failures == kJudgementsToDrop) {
      judgement.dropped.push_back(held.index);
    } else {
      still_held.push_back(held);
    }
  }
  // The batch's own outliers, after the earlier ones: still_held stays in arrival order.
  const auto first_index = static_cast<uint32_t>(size_);
  for (size_t i = 0; i < m; ++i) {
    if (mean_distance[i] <= limit) continue;
    judgement.held[i] = true;
    still_held.push_back(
        {first_index + static_cast<uint32_t>(i), batch[i], radius_squared[i], 0, 0});
  }
  judgement.still_held_ = std::move(still_held);
  return judgement;
}

void StreamingOutlierFilter::Add(absl::Span<const Vec3f> batch, OutlierJudgement judgement) {
  held_ = std::move(judgement.still_held_);
  const auto begin = static_cast<uint32_t>(size_);
  const auto end = static_cast<uint32_t>(size_ + batch.size());
  if (end == begin) return;
  size_ = end;
  // The new points form the newest tree; while the tree before it is at most twice its size,
  // the two are rebuilt as one, so sizes at least double toward the oldest tree.
  size_t merged = 0;  // Trees, newest first.
  uint32_t first = begin;
  while (merged < trees_.size() &&
         trees_[trees_.size() - 1 - merged].size() <= 2 * static_cast<size_t>(end - first)) {
    first = trees_[trees_.size() - 1 - merged].begin();
    ++merged;
  }
  std::vector<PointKdTree> merging(std::make_move_iterator(trees_.end() - merged),
                                   std::make_move_iterator(trees_.end()));
  trees_.erase(trees_.end() - merged, trees_.end());
  trees_.push_back(PointKdTree::Merged(std::move(merging), begin, batch));
  if (size_ - reference_measured_at_ > size_ / 16 || reference_.empty()) MeasureReference();
}

std::vector<uint32_t> StreamingOutlierFilter::DropHeld() {
  std::vector<uint32_t> dropped;
  dropped.reserve(held_.size());
  for (const OutlierJudgement::HeldPoint& held : held_) dropped.push_back(held.index);
  held_.clear();
  return dropped;
}

void StreamingOutlierFilter::MeasureReference() {
  const size_t n = size_;
  const size_t count = std::min(n, kReferencePoints);
  // The points of indices j * n / count, j < count, found in one pass over the trees: index i
  // is one if the least j with j * n / count >= i gives i (n / count >= 1, so at most one j
  // does).
  std::vector<PointKdTree::LeafPoint> chosen(count);
  for (const PointKdTree& tree : trees_) {
    for (const PointKdTree::LeafPoint& point : tree.leaf_order()) {
      const size_t j = (point.index * count + n - 1) / n;
      if (j < count && j * n / count == point.index) chosen[j] = point;
    }
  }
  reference_.resize(count);
  NeighbourHeap heap;
  for (size_t j = 0; j < count; ++j) {
    SearchSeen(chosen[j].position, chosen[j].index, &heap);
    reference_[j] = MeanDistance(heap);
  }
  reference_measured_at_ = n;
}

}  // namespace neuralmesh
