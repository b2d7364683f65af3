// Vertex colours for a reconstructed mesh from the colours of what it was learned from. Not in
// the paper, whose learner moves positions only: scans often carry a colour per point (RGB-D
// cameras, photogrammetry, coloured lidar) and meshes a colour per vertex, and a mesh learned
// from them should show it, as Open3D's and CGAL's reconstructions carry colours over.
//   - From points (point_colors.cc): the inverse-distance weighted mean of the colours of the
//     k nearest points, so a vertex on a point takes that point's colour and one between
//     points blends them.
//   - From a mesh (mesh_colors.cc, for remeshing): the colour at the nearest point of the
//     mesh's surface, interpolated across its triangle from the corners' colours.
#ifndef NEURALMESH_CORE_ANALYSIS_COLOR_SOURCE_H_
#define NEURALMESH_CORE_ANALYSIS_COLOR_SOURCE_H_

#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/analysis/point_kd_tree.h"
#include "core/point_cloud.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

// Colours indexed once, to paint any number of meshes (the milestones of a run). Immutable;
// every method may run on several threads at once.
class ColorSource {
 public:
  virtual ~ColorSource() = default;

  // The colour at `position`.
  virtual Rgb ColorAt(const Vec3f& position) const = 0;

  // Sets `mesh->colors` to ColorAt of each vertex. O(v log n).
  void Paint(TriangleMesh* mesh) const;
};

struct PointColorOptions {
  int neighbours = 8;  // k, in [1, 64]: how many of the nearest points a vertex's colour blends.

  // INVALID_ARGUMENT naming the first field out of range.
  absl::Status Validate() const;
};

// Colours from the points of `cloud` (copied). INVALID_ARGUMENT for invalid options, an empty
// cloud or one without a colour for every point. O(n log n); ColorAt O(k log n) on spread
// data.
absl::StatusOr<std::unique_ptr<ColorSource>> MakePointColorSource(
    const PointCloud& cloud, const PointColorOptions& options = {});

// Coloured points that arrive in batches (a session's stream), and the colours they give a
// mesh's vertices: what MakePointColorSource over every point so far would give. The points
// are indexed by two k-d trees, one over the points up to some count M and one over the rest,
// which alone hold the positions (about 18 bytes a point, and 3 of colour; a tree rebuilt is
// built from the points of those it replaces). Paint rebuilds the second when points arrived,
// and both once the second would hold more than a quarter as many points as the first: the
// first tree's rebuilds cost about five times one build over all n points, the second's at
// most M/4 points per Paint after an arrival
// (build/bin/color-bench: a stream of 1M points in batches of 10,000, a mesh of 10,000
// vertices painted after each, took 4.2-5.6 s of painting, 1.3-2 times what as many paints
// from points indexed once take).
// Thread-safe: Append and Paint may be called from any threads. Append only queues the points
// (it never waits for a Paint, which may take a fraction of a second on large meshes); Paint
// takes the queued ones in and paints, one Paint at a time.
class GrowingPointColors {
 public:
  // `options` must be valid (PointColorOptions::Validate).
  explicit GrowingPointColors(const PointColorOptions& options = {});

  // Appends points and their colours (one per point; extra colours or points are ignored).
  void Append(absl::Span<const Vec3f> positions, absl::Span<const Rgb> colors);

  // The points appended so far.
  size_t size() const;

  // Sets `mesh->colors` from every point appended so far; leaves `mesh` as it is when there
  // are none. O(v k log n) plus the rebuilds above.
  void Paint(TriangleMesh* mesh);

 private:
  const size_t neighbours_;
  // std::mutex rather than absl::Mutex, as in growing_point_cloud.h: ThreadSanitizer sees the
  // hand-offs of pthreads' mutexes, not those of Debian's uninstrumented Abseil.
  mutable std::mutex queue_mu_;  // Guards the three below.
  std::vector<Vec3f> queued_positions_;
  std::vector<Rgb> queued_colors_;
  size_t taken_ = 0;  // Points Paint has taken from the queue.
  std::mutex paint_mu_;  // Guards the three below; taken before queue_mu_.
  std::vector<Rgb> colors_;
  // The points taken so far are held by the trees alone (the rebuilt one takes the points of
  // those it replaces).
  std::optional<PointKdTree> head_;  // Points [0, M).
  std::optional<PointKdTree> tail_;  // Points [M, n).
};

// Colours from the surface of `mesh` (copied). INVALID_ARGUMENT for a mesh without faces,
// without a colour for every vertex, or with a face index out of range or a non-finite
// position. O(f log f); ColorAt typically O(log f).
absl::StatusOr<std::unique_ptr<ColorSource>> MakeMeshColorSource(const TriangleMesh& mesh);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_COLOR_SOURCE_H_
