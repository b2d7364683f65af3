// The points of a session that its outlier filter holds back (streaming_outlier_filter.h),
// kept whole (position, weight, normal, colour) by arrival index until the filter accepts them
// after all or drops them for good.
#ifndef NEURALMESH_SERVER_HELD_OUTLIERS_H_
#define NEURALMESH_SERVER_HELD_OUTLIERS_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/types/span.h"
#include "core/mesh.h"
#include "core/point_cloud.h"

namespace neuralmesh::server {

class HeldOutliers {
 public:
  // Keeps the points of `batch` flagged in `held` (one flag per point); the batch's first point
  // has arrival index `first_index`.
  void Hold(const PointCloud& batch, const std::vector<bool>& held, uint32_t first_index);

  // Appends the points of arrival indices `indices`, all held, to `cloud`. Where only one side
  // has weights (normals), the other's points get weight 1 (a zero normal), as a point cloud
  // that grows gives them; colours are kept only when every point, in `cloud` and among the
  // held, has one (they paint meshes, and a made-up colour would show).
  void AppendTo(absl::Span<const uint32_t> indices, PointCloud* cloud) const;

  // Forgets the points of arrival indices `indices` (accepted or dropped).
  void Forget(absl::Span<const uint32_t> indices);

  size_t size() const { return points_.size(); }

 private:
  struct Point {
    Vec3f position;
    std::optional<float> weight;
    std::optional<Vec3f> normal;
    std::optional<Rgb> color;
  };
  absl::flat_hash_map<uint32_t, Point> points_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_HELD_OUTLIERS_H_
