// Extracts the zero set of a scalar function as a triangle mesh by marching tetrahedra on a
// regular grid, used to build the reference tessellation of implicit surfaces that have no
// parametrisation (the genus-2 surface of implicit_surfaces.h).
//
//   evaluate f at the (nx+1)(ny+1)(nz+1) grid points; a point is inside when f < 0
//   split every cube into the 6 tetrahedra of Kuhn's (Freudenthal's) triangulation, which
//     agree across shared cube faces
//   per tetrahedron with mixed signs, emit 1 triangle (one vertex apart) or 2 (two and two),
//     their corners on the tetrahedron's edges at the zero of the linear interpolant
//
// Unlike marching cubes there are no ambiguous cases: every output edge lies in a tetrahedron
// face shared by exactly two tetrahedra and every output vertex (one per grid edge) is
// surrounded by the ring of tetrahedra around its grid edge, so the result is a closed,
// consistently oriented 2-manifold whenever f >= 0 on the grid's boundary. Its topology is
// that of the surface when the grid resolves the surface's thinnest parts.
//
// A. Doi and A. Koide, "An efficient method of triangulating equi-valued surfaces by using
// tetrahedral cells", IEICE Transactions E74(1), 1991.
#ifndef NEURALMESH_CORE_SAMPLING_MARCHING_TETRAHEDRA_H_
#define NEURALMESH_CORE_SAMPLING_MARCHING_TETRAHEDRA_H_

#include <array>
#include <functional>

#include "absl/status/statusor.h"
#include "core/bounding_box.h"
#include "core/mesh.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

// The zero set of `f` inside `box`, which is split into cells[0] x cells[1] x cells[2] cubes
// (boxes, if the spacing differs per axis). Faces are counter-clockwise seen from the side
// where f >= 0. Vertices lie on the grid edges (linear interpolation): project them onto the
// exact zero set if needed.
// Returns INVALID_ARGUMENT when `box` is empty or flat, a cell count is below 1, the grid has
// more than 2^31 points, f is not finite at a grid point, or f < 0 at a grid point on the
// box's boundary (the surface would not be closed). O(grid points) evaluations of f.
absl::StatusOr<TriangleMesh> MarchingTetrahedra(const std::function<double(const Vec3&)>& f,
                                                const BoundingBox& box,
                                                const std::array<int, 3>& cells);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_MARCHING_TETRAHEDRA_H_
