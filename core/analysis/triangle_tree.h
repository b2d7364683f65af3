// A bounding volume hierarchy (axis-aligned boxes) over the triangles of a mesh, answering
// exact closest-point queries.
//
// Build: split the triangles at the median of their centroids along the longest axis of the
// centroid bounds, recursively, down to leaves of at most 4 triangles; depth <= ceil(log2 n),
// O(n log n) time, O(n) memory. Triangles are copied in leaf order for cache locality.
// Query: depth-first, nearer child first, skipping every box farther than the best distance
// so far. The result is the exact minimum over all triangles (ClosestPointOnTriangle), not an
// approximation; typically O(log n).
#ifndef NEURALMESH_CORE_ANALYSIS_TRIANGLE_TREE_H_
#define NEURALMESH_CORE_ANALYSIS_TRIANGLE_TREE_H_

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/bounding_box.h"
#include "core/mesh.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

class TriangleTree {
 public:
  struct ClosestPointResult {
    double distance;  // Euclidean distance from the query to `point`.
    Vec3 point;       // The nearest point of the surface.
    uint32_t face;    // Index into the mesh's faces of the triangle holding `point`.
  };

  // Builds the tree over every face of `mesh` (degenerate faces included: they are segments
  // or points), holding copies of a face (the same corners in the same cyclic order) once: the
  // first, whose index the queries report. Returns INVALID_ARGUMENT when the mesh has no faces (or
  // more than 2^32 - 1), a face index is out of range, or a position is not finite. O(f log f).
  static absl::StatusOr<TriangleTree> Build(const TriangleMesh& mesh);

  // The nearest point of the surface to `p`. Exact. A non-finite `p` gives an infinite
  // distance. Thread-safe (const).
  ClosestPointResult ClosestPoint(const Vec3& p) const { return ClosestPointOrWithin(p, 0.0); }

  // Like ClosestPoint, but the search may stop at the first surface point found within
  // `radius` of p: then `distance` <= radius and `point` is that point, not necessarily the
  // nearest. When the surface is farther than `radius` the result is exact. For maxima of
  // distances (Hausdorff), where distances below a known bound do not matter.
  ClosestPointResult ClosestPointOrWithin(const Vec3& p, double radius) const;

  struct BatchOptions {
    int threads = 0;      // 0: one per hardware thread. Results do not depend on it.
    double radius = 0.0;  // As in ClosestPointOrWithin; 0 gives exact closest points.
  };

  // ClosestPointOrWithin for every point, in the order of `points`, over several threads.
  // Queries are processed in Z-order for cache locality.
  std::vector<ClosestPointResult> ClosestPoints(absl::Span<const Vec3> points,
                                                const BatchOptions& options) const;

  size_t num_triangles() const { return triangles_.size(); }  // Distinct faces held.
  const BoundingBox& bounds() const { return bounds_; }

 private:
  // Internal node: children at index + 1 and `second`; leaf: triangles [first, first + count).
  struct Node {
    float lo[3], hi[3];
    uint32_t first_or_second;
    uint32_t count;  // 0 for an internal node.
  };
  struct Triangle {
    Vec3f a, b, c;
    uint32_t face;
  };

  TriangleTree() = default;

  std::vector<Node> nodes_;
  std::vector<Triangle> triangles_;
  BoundingBox bounds_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_TRIANGLE_TREE_H_
