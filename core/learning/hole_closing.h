// Closing of small holes: the inverse of Step 4 of Neural Meshes (Ivrissimtzis, Jeong, Seidel,
// "Neural Meshes: Statistical Learning Methods in Surface Reconstruction", Section 2 Step 4,
// Eq. 2, and Section 2.3), run right before Step 5. Not in the paper; it keeps the paper's
// promise of "absence of topological noise, that is, tiny boundaries or handles" (Section 1).
//
//   E <- E(Area) (given, or the mean area of the live faces)
//   for every boundary loop L with at most max_loop_vertices vertices:
//     repeat until L is filled or no ear qualifies:
//       among the ears (a, b, c) of L (three consecutive vertices, b removable) whose area is
//       <= alpha_r * E, whose new edge a-c does not exist yet, and that leave every vertex
//       with a legal valence: add the one of largest minimum angle quality
//     when L cannot be filled completely, the ears already added are removed again
//
// Why: Step 4 removes a triangle when its area says that it covers a region without data
// (Eq. 2). While the mesh is still learning the geometry (a misplaced vertex, the remains of a
// strip sewn across a cavity by Step 5), it also cuts triangles in regions that do have data.
// The hole then shrinks back as its vertices converge, but it can never vanish: Step 3 may not
// collapse an edge of a loop of 3 vertices (OpenMesh's link condition), so the hole stays
// forever, and Step 5 sews pairs of such tiny holes into extra handles. A hole is refilled here
// only when Step 4 itself would no longer remove any of the filling triangles: the data has
// come back, so the removal was premature. A real boundary (an open surface's border, a hole
// over a cavity that Step 5 still has to merge) is never closed: its filling triangles span a
// region without data and are far larger than alpha_r E (a loop of v vertices around a real
// hole spans about v^2 / (4 pi) mean triangles), or it has more than max_loop_vertices vertices.
// Closing a hole is undone by Step 4 if its triangles grow large again, so the rule cannot
// fight the paper's steps; it only removes loops that would otherwise be stuck.
//
// Legality: each ear uses two boundary half-edges of the loop and adds one edge (a, c) that
// must not exist yet (no double edge, which also excludes closing a loop of 3 vertices that
// bounds a single face on the other side); its middle vertex b becomes interior and must keep
// valence >= 3; the last triangle of a loop uses three boundary half-edges, and each of its
// vertices becomes interior with valence >= 3. A loop never shares a vertex with another loop
// in a valid mesh, so filling one leaves every other loop intact and the mesh passes
// ValidateMesh after every closed hole.
#ifndef NEURALMESH_CORE_LEARNING_HOLE_CLOSING_H_
#define NEURALMESH_CORE_LEARNING_HOLE_CLOSING_H_

#include <cstddef>

#include "absl/status/status.h"
#include "core/mesh.h"

namespace neuralmesh {

struct HoleClosingOptions {
  // alpha_r of Eq. 2: a filling triangle must have area <= alpha_r * E(Area), the test that
  // Step 4 applies to keep a triangle. > 0.
  double alpha_r = 7;
  // Loops with more vertices are never closed, whatever their area. >= 3. Six vertices are
  // the ring of one vertex: the largest hole that a single premature removal with its corner
  // (or two neighbouring removals) opens.
  int max_loop_vertices = 6;

  // Returns INVALID_ARGUMENT unless alpha_r is finite and positive and max_loop_vertices >= 3.
  absl::Status Validate() const;
};

struct HoleClosingResult {
  size_t closed_holes = 0;
  size_t added_faces = 0;
};

// Fills every boundary loop of `mesh` with at most options.max_loop_vertices vertices whose
// filling triangles all have area <= options.alpha_r * mean_area and are legal (see the file
// comment). `mean_area` is E(Area) (for example TriangleRemovalResult::mean_area); pass <= 0
// to compute it from the live faces. `options` must be valid (Validate()). Works on meshes
// with deleted elements, adds faces and edges without garbage collection, never adds or
// removes a vertex. O(h) to find the loops plus O(k^3) per loop of k vertices.
HoleClosingResult CloseSmallHoles(Mesh& mesh, const HoleClosingOptions& options, double mean_area);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_HOLE_CLOSING_H_
