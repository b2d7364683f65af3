#include "core/analysis/closest_point_triangle.h"

#include <algorithm>

namespace neuralmesh {
namespace {

// Below this |sin(angle at a)|^2 the triangle is treated as a segment: the face branch would
// divide by ~|ab x ac|^2 and amplify rounding.
constexpr double kDegenerateSin2 = 1e-20;

// Closest point of segment [a, b] to p; `t` returns the parameter in [0, 1].
Vec3 ClosestPointOnSegment(const Vec3& p, const Vec3& a, const Vec3& b, double& t) {
  const Vec3 ab = b - a;
  const double length2 = ab.sqrnorm();
  t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return a + ab * t;
}

TriangleClosestPoint ClosestPointOnDegenerate(const Vec3& p, const Vec3& a, const Vec3& b,
                                              const Vec3& c) {
  struct Edge {
    const Vec3* from;
    const Vec3* to;
    TriangleFeature start, end, edge;
  };
  const Edge edge_list[3] = {
      {&a, &b, TriangleFeature::kVertexA, TriangleFeature::kVertexB, TriangleFeature::kEdgeAB},
      {&b, &c, TriangleFeature::kVertexB, TriangleFeature::kVertexC, TriangleFeature::kEdgeBC},
      {&c, &a, TriangleFeature::kVertexC, TriangleFeature::kVertexA, TriangleFeature::kEdgeCA}};
  TriangleClosestPoint best{a, TriangleFeature::kVertexA};
  double best_d2 = (p - a).sqrnorm();
  for (const Edge& e : edge_list) {
    double t;
    const Vec3 q = ClosestPointOnSegment(p, *e.from, *e.to, t);
    const double d2 = (p - q).sqrnorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best.point = q;
      best.feature = t <= 0.0 ? e.start : (t >= 1.0 ? e.end : e.edge);
    }
  }
  return best;
}

}  // namespace

TriangleClosestPoint ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                            const Vec3& c) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const double ab2 = ab.sqrnorm(), ac2 = ac.sqrnorm();
  if (!((ab % ac).sqrnorm() > kDegenerateSin2 * ab2 * ac2)) {
    return ClosestPointOnDegenerate(p, a, b, c);
  }

  const Vec3 ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, TriangleFeature::kVertexA};

  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, TriangleFeature::kVertexB};

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return {a + ab * v, TriangleFeature::kEdgeAB};
  }

  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, TriangleFeature::kVertexC};

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return {a + ac * w, TriangleFeature::kEdgeCA};
  }

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + (c - b) * w, TriangleFeature::kEdgeBC};
  }

  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom;
  const double w = vc * denom;
  return {a + ab * v + ac * w, TriangleFeature::kFace};
}

}  // namespace neuralmesh
