#include "server/held_outliers.h"

namespace neuralmesh::server {

void HeldOutliers::Hold(const PointCloud& batch, const std::vector<bool>& held,
                        uint32_t first_index) {
  for (size_t i = 0; i < batch.size(); ++i) {
    if (!held[i]) continue;
    Point& point = points_[first_index + static_cast<uint32_t>(i)];
    point.position = batch.positions[i];
    if (!batch.weights.empty()) point.weight = batch.weights[i];
    if (!batch.normals.empty()) point.normal = batch.normals[i];
    if (!batch.colors.empty()) point.color = batch.colors[i];
  }
}

void HeldOutliers::AppendTo(absl::Span<const uint32_t> indices, PointCloud* cloud) const {
  if (indices.empty()) return;
  bool weights = !cloud->weights.empty();
  bool normals = !cloud->normals.empty();
  // A colour is not made up: all points keep theirs, or none does.
  bool colors = cloud->colors.size() == cloud->size();
  for (const uint32_t index : indices) {
    const Point& point = points_.at(index);
    weights = weights || point.weight.has_value();
    normals = normals || point.normal.has_value();
    colors = colors && point.color.has_value();
  }
  if (!colors) cloud->colors.clear();
  if (weights) cloud->weights.resize(cloud->size(), 1.0f);
  if (normals) cloud->normals.resize(cloud->size(), Vec3f(0, 0, 0));
  for (const uint32_t index : indices) {
    const Point& point = points_.at(index);
    cloud->positions.push_back(point.position);
    if (weights) cloud->weights.push_back(point.weight.value_or(1.0f));
    if (normals) cloud->normals.push_back(point.normal.value_or(Vec3f(0, 0, 0)));
    if (colors) cloud->colors.push_back(*point.color);
  }
}

void HeldOutliers::Forget(absl::Span<const uint32_t> indices) {
  for (const uint32_t index : indices) points_.erase(index);
}

}  // namespace neuralmesh::server
