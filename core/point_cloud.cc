#include "core/point_cloud.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace neuralmesh {

absl::Status ValidatePointCloud(const PointCloud& cloud) {
  for (size_t i = 0; i < cloud.positions.size(); ++i) {
    const Vec3f& p = cloud.positions[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return absl::InvalidArgumentError(
          absl::StrCat("point ", i, " has a non-finite coordinate (NaN or infinity)"));
    }
  }
  if (!cloud.weights.empty()) {
    if (cloud.weights.size() != cloud.positions.size()) {
      return absl::InvalidArgumentError(absl::StrCat("there are ", cloud.weights.size(),
                                                     " weights for ", cloud.positions.size(),
                                                     " points"));
    }
    double sum = 0;
    for (size_t i = 0; i < cloud.weights.size(); ++i) {
      const float w = cloud.weights[i];
      if (!std::isfinite(w) || w < 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("weight ", i, " is ", w, "; weights must be finite and non-negative"));
      }
      sum += w;
    }
    if (!cloud.positions.empty() && sum <= 0) {
      return absl::InvalidArgumentError("all weights are zero");
    }
  }
  if (!cloud.normals.empty() && cloud.normals.size() != cloud.positions.size()) {
    return absl::InvalidArgumentError(absl::StrCat("there are ", cloud.normals.size(),
                                                   " normals for ", cloud.positions.size(),
                                                   " points"));
  }
  if (!cloud.colors.empty() && cloud.colors.size() != cloud.positions.size()) {
    return absl::InvalidArgumentError(absl::StrCat("there are ", cloud.colors.size(),
                                                   " colours for ", cloud.positions.size(),
                                                   " points"));
  }
  for (size_t i = 0; i < cloud.normals.size(); ++i) {
    const Vec3f& n = cloud.normals[i];
    if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2])) {
      return absl::InvalidArgumentError(
          absl::StrCat("normal ", i, " has a non-finite component"));
    }
  }
  return absl::OkStatus();
}

PointCloud PointRange(const PointCloud& cloud, size_t begin, size_t end) {
  PointCloud part;
  part.origin = cloud.origin;
  part.positions.assign(cloud.positions.begin() + begin, cloud.positions.begin() + end);
  if (!cloud.weights.empty()) {
    part.weights.assign(cloud.weights.begin() + begin, cloud.weights.begin() + end);
  }
  if (!cloud.normals.empty()) {
    part.normals.assign(cloud.normals.begin() + begin, cloud.normals.begin() + end);
  }
  if (!cloud.colors.empty()) {
    part.colors.assign(cloud.colors.begin() + begin, cloud.colors.begin() + end);
  }
  return part;
}

}  // namespace neuralmesh
