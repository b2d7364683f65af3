// A point set with optional per-point confidence weights, normals and colours.
#ifndef NEURALMESH_CORE_POINT_CLOUD_H_
#define NEURALMESH_CORE_POINT_CLOUD_H_

#include <array>
#include <cstddef>
#include <vector>

#include "absl/status/status.h"
#include "core/mesh.h"
#include "core/origin.h"
#include "core/rgb.h"

namespace neuralmesh {

// Points of a file that its reader left out because the file marks them as not to be used
// (LAS: the withheld flag, and the noise classes 7 and 18) or gives them no position (the
// empty cells of a scan's grid: NaN coordinates in PCD, 0 0 0 in PTX).
struct PointsLeftOut {
  size_t withheld = 0;
  size_t noise = 0;
  size_t invalid = 0;
  size_t other_class = 0;  // Of a class the reader was not asked for (PointSelection).

  size_t total() const { return withheld + noise + invalid + other_class; }
  PointsLeftOut& operator+=(const PointsLeftOut& other) {
    withheld += other.withheld;
    noise += other.noise;
    invalid += other.invalid;
    other_class += other.other_class;
    return *this;
  }
};

struct PointCloud {
  std::vector<Vec3f> positions;
  std::vector<float> weights;   // Empty, or one non-negative weight per point (Section 4.1).
  std::vector<Vec3f> normals;   // Empty, or one normal per point.
  std::vector<Rgb> colors;      // Empty, or one colour per point (scans that carry them).
  // Where the file's coordinates put position (0, 0, 0): a reader of georeferenced data (LAS)
  // moves the points there to keep a float's resolution. Zero for most files.
  Origin origin = kNoOrigin;

  size_t size() const { return positions.size(); }
  bool empty() const { return positions.empty(); }
};

// Checks that `cloud` is usable as a target space: every coordinate finite, weights, normals
// and colours either absent or one per point, weights finite and non-negative with a positive
// sum.
// Returns INVALID_ARGUMENT with the first offending index otherwise.
absl::Status ValidatePointCloud(const PointCloud& cloud);

// Points [begin, end) of `cloud`, with their weights, normals and colours; begin <= end <= size().
PointCloud PointRange(const PointCloud& cloud, size_t begin, size_t end);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_POINT_CLOUD_H_
