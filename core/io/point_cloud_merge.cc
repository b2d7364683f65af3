#include "core/io/point_cloud_merge.h"

#include <algorithm>
#include <utility>

#include "core/io/internal/geometry_data.h"
#include "core/io/internal/position_collector.h"

namespace neuralmesh {
namespace {

// Appends member `member` of every cloud to that of `out` when every cloud has it; clears it
// otherwise.
template <typename T>
void MergeAttribute(std::vector<PointCloud>& clouds, std::vector<T> PointCloud::*member,
                    PointCloud* out) {
  const bool everywhere = std::all_of(clouds.begin(), clouds.end(), [&](const PointCloud& cloud) {
    return !(cloud.*member).empty();
  });
  std::vector<T>& merged = out->*member;
  merged.clear();
  if (!everywhere) return;
  for (PointCloud& cloud : clouds) {
    merged.insert(merged.end(), (cloud.*member).begin(), (cloud.*member).end());
    std::vector<T>().swap(cloud.*member);
  }
}

}  // namespace

PointCloud MergePointClouds(std::vector<PointCloud> clouds) {
  PointCloud out;
  if (clouds.empty()) return out;
  const Origin origin = clouds.front().origin;
  const bool same_origin = std::all_of(clouds.begin(), clouds.end(), [&](const PointCloud& cloud) {
    return cloud.origin == origin;
  });
  size_t total = 0;
  for (const PointCloud& cloud : clouds) total += cloud.size();
  if (same_origin) {
    out.origin = origin;
    out.positions.reserve(total);
    for (PointCloud& cloud : clouds) {
      out.positions.insert(out.positions.end(), cloud.positions.begin(), cloud.positions.end());
      std::vector<Vec3f>().swap(cloud.positions);
    }
  } else {
    std::vector<io_internal::Point3d> absolute;
    absolute.reserve(total);
    for (PointCloud& cloud : clouds) {
      for (const Vec3f& p : cloud.positions) {
        absolute.push_back(
            {cloud.origin[0] + p[0], cloud.origin[1] + p[1], cloud.origin[2] + p[2]});
      }
      std::vector<Vec3f>().swap(cloud.positions);
    }
    io_internal::ParsedGeometry parsed;
    io_internal::PositionCollector(std::move(absolute)).MoveTo(&parsed);
    out.positions = std::move(parsed.positions);
    out.origin = parsed.origin;
  }
  MergeAttribute(clouds, &PointCloud::normals, &out);
  MergeAttribute(clouds, &PointCloud::weights, &out);
  MergeAttribute(clouds, &PointCloud::colors, &out);
  return out;
}

}  // namespace neuralmesh
