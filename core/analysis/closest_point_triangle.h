// The exact closest point of a triangle to a query point, by Voronoi regions (C. Ericson,
// "Real-Time Collision Detection", 2005, Section 5.1.5):
//   - project p on the edges through each vertex; if p lies behind both edges at a vertex,
//     that vertex is closest;
//   - otherwise, for each edge, if p projects inside the edge and lies outside the triangle
//     across it (its barycentric coordinate for the opposite vertex is <= 0), the edge is;
//   - otherwise the orthogonal projection on the plane, inside the triangle, is.
// Degenerate triangles (collinear or coincident corners, |sin| of the corner angle below
// 1e-10) have no face region: the closest point of their three edges is returned instead.
#ifndef NEURALMESH_CORE_ANALYSIS_CLOSEST_POINT_TRIANGLE_H_
#define NEURALMESH_CORE_ANALYSIS_CLOSEST_POINT_TRIANGLE_H_

#include "core/mesh.h"

namespace neuralmesh {

// The feature of triangle (a, b, c) whose Voronoi region holds the query point.
enum class TriangleFeature { kVertexA, kVertexB, kVertexC, kEdgeAB, kEdgeBC, kEdgeCA, kFace };

struct TriangleClosestPoint {
  Vec3 point;
  TriangleFeature feature;
};

// The point of triangle (a, b, c) nearest to p, and the feature it lies on. All inputs must be
// finite. O(1).
TriangleClosestPoint ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                            const Vec3& c);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_CLOSEST_POINT_TRIANGLE_H_
