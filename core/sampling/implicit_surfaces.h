// Implicitly defined surfaces with exact (or nearly exact) area-uniform samplers, distances and
// reference tessellations: targets with known ground truth for tests, benchmarks and demos
// (Section 2.1: "in some examples the underlying set Omega is a surface described
// implicitly"; Section 4.1, Fig. 8).
//
// Each surface samples in O(1) and is immutable after construction, so one object may be
// sampled from several threads, each with its own Random.
#ifndef NEURALMESH_CORE_SAMPLING_IMPLICIT_SURFACES_H_
#define NEURALMESH_CORE_SAMPLING_IMPLICIT_SURFACES_H_

#include <memory>

#include "absl/status/statusor.h"
#include "core/mesh.h"
#include "core/sampling/sampler.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

class ImplicitSurface : public Sampler {
 public:
  // The implicit function, < 0 inside, > 0 outside, 0 on the surface.
  virtual double Value(const Vec3& p) const = 0;
  // Unsigned distance from `p` to the surface (exact for the sphere and torus; see each
  // factory for the others).
  virtual double Distance(const Vec3& p) const = 0;
  virtual int genus() const = 0;
  // A dense closed 2-manifold tessellation of the surface with vertices on it, faces
  // counter-clockwise seen from outside, for error measurement. The vertex count grows as
  // resolution^2 (each factory gives it); values below 1 count as 1, and each surface caps
  // resolution so the mesh stays below 2^28 vertices.
  virtual TriangleMesh ReferenceMesh(int resolution) const = 0;
  // The surface's area.
  virtual double Area() const = 0;

  // Sampler: empty() is false; Sample is uniform in area measure; Bounds() contains the
  // surface (exact for the sphere and torus).
  bool empty() const override { return false; }
};

// The sphere |p - center| = radius; Value(p) = |p - center| - radius.
// Sample: Archimedes' theorem (z uniform in [-r, r], azimuth uniform), exactly area-uniform.
// ReferenceMesh(n): a geodesic sphere, the icosahedron with each edge split into 2n segments,
// projected: 40 n^2 + 2 vertices, genus 0; n at most 2048.
// Returns INVALID_ARGUMENT unless the centre is finite and the radius finite and > 0.
absl::StatusOr<std::unique_ptr<ImplicitSurface>> MakeSphere(const Vec3& center, double radius);

// The ring torus around the z axis through `center`: the points at distance minor_radius (r)
// from the circle of radius major_radius (R) in the plane z = center z. Value(p) = distance to
// that circle - r. Area 4 pi^2 R r.
// Sample: both angles uniform, then the tube angle v is kept with probability
// (R + r cos v) / (R + r), the area element's share, so the result is exactly area-uniform
// (at most (R + r) / R <= 2 tries on average).
// ReferenceMesh(n): a closed grid of 4n segments around the tube and max(3, round(4n R / r))
// around the axis: about 16 n^2 R / r vertices, genus 1; n at most 2048, and the segments
// around the axis at most 2^28 / (4n).
// Returns INVALID_ARGUMENT unless all values are finite and 0 < r < R.
absl::StatusOr<std::unique_ptr<ImplicitSurface>> MakeTorus(const Vec3& center, double major_radius,
                                                           double minor_radius);

// A smooth closed surface of genus 2: a tube around the lemniscate of Bernoulli
// (x^2 + y^2)^2 = x^2 - y^2, in local coordinates q = (p - center) / scale:
//
//   Value(p) = g(q)^2 + q_z^2 - t^2,   g(q) = (q_x^2 + q_y^2)^2 - q_x^2 + q_y^2,   t = thickness
//
// The two lobes of the figure eight give the two holes (around q = (+-0.71, 0, 0), where
// g = -1/4, so the holes stay open for t < 1/4). The surface spans exactly
// |q_x| <= sqrt((1 + sqrt(1 + 4t)) / 2), |q_y| <= sqrt((1 + 4t) / 8), |q_z| <= t (at t = 0.1:
// 1.046 x 0.418 x 0.1); the tube is thinnest at the ends of the lobes, t across in the plane
// and 2t high. Value is a degree-8 polynomial, not a distance.
// Distance: Newton projection onto the zero set, then the foot is slid along the surface until
// p - foot is normal to it; exact to round-off within t / 4 * scale of the surface (the
// smallest radius of curvature), an upper bound farther away.
// Sample: a reference tessellation of about 50000 vertices (built once here, O(100 ms)) drawn
// by area, then the point projected onto the zero set by Newton steps: O(1), area-uniform to
// about 1e-3 relative. Area(): that tessellation's area, within 1e-3 relative (2e-4 at t = 0.1).
// ReferenceMesh(n): marching tetrahedra on a grid of 8n cells across the x extent (at least
// 4 x extent / t cells, so that two span the thinnest part; n at most 128), vertices projected
// onto the surface: a closed 2-manifold of genus 2 with about 200 n^2 vertices at t = 0.1
// (120 n^2 at 0.05, 310 n^2 at 0.2) and never fewer than about 5000 at t = 0.1.
// Returns INVALID_ARGUMENT unless the centre and scale are finite, scale > 0, and thickness is
// in [0.05, 0.2] (thinner tubes need much finer grids; thicker ones nearly close the holes).
absl::StatusOr<std::unique_ptr<ImplicitSurface>> MakeGenusTwo(const Vec3& center,
                                                              double scale = 1.0,
                                                              double thickness = 0.1);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_IMPLICIT_SURFACES_H_
