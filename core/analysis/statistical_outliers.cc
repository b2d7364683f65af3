#include "core/analysis/statistical_outliers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/analysis/point_kd_tree.h"
#include "core/parallel_ranges.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

constexpr int kMaxNeighbours = 256;
constexpr int kMaxPasses = 16;

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
  if (passes < 1 || passes > kMaxPasses) {
    return absl::InvalidArgumentError(absl::StrCat("outlier passes = ", passes,
                                                   " is out of range; it must be in [1, ",
                                                   kMaxPasses, "]"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<bool>> FindStatisticalOutliers(const PointCloud& cloud,
                                                          const OutlierOptions& options) {
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  const size_t n = cloud.size();
  const size_t k = static_cast<size_t>(options.neighbours);
  std::vector<bool> outlier(n, false);
  if (n <= k) return outlier;
  const PointKdTree tree(cloud.positions, 0, static_cast<uint32_t>(n), options.threads);
  std::vector<double> mean_distance(n);
  // Queried in the tree's order, each query near the one before.
  const absl::Span<const PointKdTree::LeafPoint> leaves = tree.leaf_order();
  ForEachRange(n, options.threads, 4096, [&](size_t first, size_t last) {
    NeighbourHeap heap;
    for (size_t j = first; j < last; ++j) {
      tree.Search(leaves[j].position, leaves[j].index, k, &heap);
      mean_distance[leaves[j].index] = MeanDistance(heap);
    }
  });

  const double limit = OutlierDistanceLimit(mean_distance, options.std_ratio);
  for (size_t i = 0; i < n; ++i) outlier[i] = mean_distance[i] > limit;
  return outlier;
}

double OutlierDistanceLimit(absl::Span<const double> mean_distances, double std_ratio) {
  const size_t n = mean_distances.size();
  if (n < 2) return std::numeric_limits<double>::infinity();
  double sum = 0;
  for (double d : mean_distances) sum += d;
  const double mean = sum / static_cast<double>(n);
  double squares = 0;
  for (double d : mean_distances) squares += (d - mean) * (d - mean);
  const double deviation = std::sqrt(squares / static_cast<double>(n - 1));
  return mean + std_ratio * deviation;
}

absl::StatusOr<std::vector<bool>> FindStatisticalOutliersInPasses(const PointCloud& cloud,
                                                                  const OutlierOptions& options) {
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  std::vector<bool> dropped(cloud.size(), false);
  // What a pass judges: the cloud itself, then the points kept so far (copied only when a pass
  // follows), with the index in the cloud of each.
  const PointCloud* judged = &cloud;
  PointCloud kept;
  std::vector<uint32_t> index_in_cloud;  // Empty while judged is the cloud.
  for (int pass = 0; pass < options.passes; ++pass) {
    absl::StatusOr<std::vector<bool>> outlier = FindStatisticalOutliers(*judged, options);
    if (!outlier.ok()) return outlier.status();
    if (std::find(outlier->begin(), outlier->end(), true) == outlier->end()) break;
    const bool last = pass + 1 == options.passes;
    std::vector<uint32_t> kept_indices;
    for (size_t i = 0; i < judged->size(); ++i) {
      const uint32_t index = index_in_cloud.empty() ? static_cast<uint32_t>(i) : index_in_cloud[i];
      if ((*outlier)[i]) {
        dropped[index] = true;
      } else if (!last) {
        kept_indices.push_back(index);
      }
    }
    if (last) break;
    kept = WithoutPoints(*judged, *outlier);
    judged = &kept;
    index_in_cloud = std::move(kept_indices);
  }
  return dropped;
}

absl::StatusOr<size_t> RemoveStatisticalOutliers(PointCloud& cloud,
                                                 const OutlierOptions& options) {
  NM_ASSIGN_OR_RETURN(const std::vector<bool> outlier,
                      FindStatisticalOutliersInPasses(cloud, options));
  const size_t removed = static_cast<size_t>(std::count(outlier.begin(), outlier.end(), true));
  if (removed > 0) cloud = WithoutPoints(cloud, outlier);
  return removed;
}

PointCloud WithoutPoints(const PointCloud& cloud, const std::vector<bool>& drop) {
  PointCloud kept;
  kept.origin = cloud.origin;
  size_t dropped = 0;
  for (size_t i = 0; i < std::min(drop.size(), cloud.size()); ++i) dropped += drop[i];
  const size_t count = cloud.size() - dropped;
  kept.positions.reserve(count);
  if (!cloud.weights.empty()) kept.weights.reserve(count);
  if (!cloud.normals.empty()) kept.normals.reserve(count);
  if (!cloud.colors.empty()) kept.colors.reserve(count);
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (i < drop.size() && drop[i]) continue;
    kept.positions.push_back(cloud.positions[i]);
    if (!cloud.weights.empty()) kept.weights.push_back(cloud.weights[i]);
    if (!cloud.normals.empty()) kept.normals.push_back(cloud.normals[i]);
    if (!cloud.colors.empty()) kept.colors.push_back(cloud.colors[i]);
  }
  return kept;
}

}  // namespace neuralmesh
