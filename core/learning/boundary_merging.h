// Step 5 of Neural Meshes: boundary merging (Ivrissimtzis, Jeong, Seidel, "Neural Meshes:
// Statistical Learning Methods in Surface Reconstruction", Section 2 Step 5, Eq. 3, and
// Section 2.3). Two boundary loops that have come close are sewn together with a strip of
// triangles: within one component this creates a handle (genus + 1), across two components
// it joins them.
//
//   E <- E(Area) (given, or the mean area of the live faces)
//   L <- the boundary loops of the mesh with at least min_loop_vertices vertices (3: all)
//   for every pair (A, B) of loops:                                       (box prefilter first)
//     H(A, B) <- symmetric Hausdorff distance of their VERTEX SETS         (Section 2.3)
//     keep (A, B) if H(A, B) < alpha_m * sqrt(E)                           (Eq. 3)
//   for the kept pairs, closest first, skipping loops already merged in this call:
//     plan a strip: start at the closest vertex pair (a_0, c_0) not already joined by an
//       edge, and walk A along its boundary half-edges and B against them; each step adds
//       one of the two triangles
//         (a_i, a_i+1, c_k)    advance on A, using A's boundary half-edge a_i -> a_i+1
//         (c_k+1, c_k, a_i)    advance on B, using B's boundary half-edge c_k+1 -> c_k
//       until both loops are consumed and the strip closes on (a_0, c_0); of all such walks,
//       take the one whose triangles are closest to equilateral: least sum of 1 / quality
//     if a plan exists, add its |A| + |B| faces (undo them all if OpenMesh refuses one)
//
// Orientation: a new face sharing a boundary edge must traverse it in the direction of the
// boundary half-edge (the existing face owns the opposite half-edge). Both triangle kinds
// above contain the half-edge c_k -> a_i of the current cross edge, and leave the next cross
// edge as a_i+1 -> c_k or a_i -> c_k+1, which the next triangle uses reversed; so the strip is
// consistently oriented with both sides exactly when A is walked forward and B backward.
// Geometrically this is the same sense of rotation: two facing tube ends carry opposite
// boundary half-edge directions.
//
// Quality of a triangle (the paper: "how close it is to be equilateral"):
// q = 4 sqrt(3) area / (l0^2 + l1^2 + l2^2), 1 for an equilateral triangle and 0 for a
// degenerate one; cheap, scale-free and without trigonometry.
// The best walk, not the best next triangle: the paper adds "the best triangle" at each step.
// That greedy choice fails where one loop has a short edge right after a long one (common on
// the holes Step 4 cuts): every triangle over the short edge is a sliver, so the walk runs
// all the way round the other loop first and closes the strip with two fans of slivers. On a
// torus this gave vertices of valence 19 and 21, and the strip then tore into holes that were
// sewn into an extra handle. A dynamic program over the same walks (O(|A| |B|)) finds the one
// of least total cost; with 1 / q as the cost, one sliver costs more than many good
// triangles save.
//
// Legality: the walk never creates an edge that already exists (two loops of one thin
// component are often joined by edges) nor the same cross edge twice (possible only where it
// wraps around; the loop not advanced by the first triangle is consumed last, which excludes
// it). The dynamic program only walks through allowed states, so a strip is found whenever
// one of this kind exists, and a pair is skipped, untouched, only when none does. Every step
// is then legal for OpenMesh: it uses one free boundary half-edge of a loop, and cross edges
// that are either new or the free side of an earlier one. Loops never share a vertex and have at least 3 vertices, since every boundary vertex
// of a valid mesh has exactly one boundary gap and there are no double edges.
// Foldovers created by the strip are left to the learner's Laplacian smoothing (Section 2.3).
//
// Not in the paper, off by default (the learner turns it on, LearnerOptions::
// close_small_holes): before looking for pairs, small loops whose filling triangles Step 4
// would keep are closed again (CloseSmallHoles, hole_closing.h, which gives the reasons), so
// that only real boundaries are merged and two tiny holes cut while the geometry was still
// converging are never sewn into a spurious handle. Slits in a border are zipped the same way
// (ZipBorderSlits), and two holes split by a bridge of two triangles are closed as one
// (CloseBridgedHoles: sewn together, they would make a handle whose tunnel is the bridge); the
// learner turns both on with close_small_holes.
#ifndef NEURALMESH_CORE_LEARNING_BOUNDARY_MERGING_H_
#define NEURALMESH_CORE_LEARNING_BOUNDARY_MERGING_H_

#include <cstddef>
#include <vector>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "core/learning/hole_closing.h"
#include "core/mesh.h"

namespace neuralmesh {

struct BoundaryMergingOptions {
  double alpha_m = 5;  // alpha_m, Eq. 3: merge loops closer than alpha_m sqrt(E(Area)), >= 0.
  // Loops with fewer vertices take no part. 3 (every loop) is the paper's rule. >= 3.
  size_t min_loop_vertices = 3;
  // Close small holes (CloseSmallHoles with `hole_closing`) before merging. Not in the paper.
  bool close_small_holes = false;
  // Zip slits in borders (ZipBorderSlits with `hole_closing`) before merging. Not in the paper.
  bool zip_border_slits = false;
  // Close pairs of holes split by a bridge (CloseBridgedHoles with `hole_closing`) before
  // merging, right after the small holes. Not in the paper.
  bool close_bridged_holes = false;
  HoleClosingOptions hole_closing;

  // Returns INVALID_ARGUMENT unless alpha_m is finite and non-negative, min_loop_vertices is
  // at least 3 and, when close_small_holes, zip_border_slits or close_bridged_holes is set,
  // hole_closing is valid.
  absl::Status Validate() const;
};

struct BoundaryMergingResult {
  size_t merges = 0;          // Pairs of loops sewn together.
  size_t added_faces = 0;     // Faces of all strips; no vertex is ever added or removed.
  HoleClosingResult closed;   // Small holes closed before merging (close_small_holes).
  HoleClosingResult zipped;   // Slits zipped before merging (zip_border_slits).
  HoleClosingResult bridged;  // Pairs of holes split by a bridge closed (close_bridged_holes).
  // The vertices of the loops that were sewn together: the corners of every strip face.
  std::vector<Mesh::VertexHandle> sewn_vertices;
};

// Step 5 (Eq. 3): when options.close_small_holes is set, first closes the small holes as
// CloseSmallHoles does, when options.close_bridged_holes is set, the pairs of holes split by a
// bridge as CloseBridgedHoles does, and when options.zip_border_slits is set, zips slits as
// ZipBorderSlits does; then merges every pair of boundary loops of `mesh` whose vertex sets are
// closer than options.alpha_m * sqrt(mean_area) in Hausdorff distance, closest pair first, each
// loop at most once per call. `mean_area` is E(Area) (for example
// TriangleRemovalResult::mean_area); pass <= 0 to compute it from the live faces. `options` must be
// valid (Validate()). Works on meshes with deleted elements, adds elements without garbage
// collection, and leaves the mesh passing ValidateMesh after each merge. O(h) to find the loops,
// plus O(|A| |B|) per pair that passes a bounding-box lower bound on H and per merge.
BoundaryMergingResult MergeCloseBoundaries(Mesh& mesh, const BoundaryMergingOptions& options,
                                           double mean_area);

// As above, but a loop through any of `growing_vertices` is not merged in this call (it may
// still be closed as a small hole). Not in the paper: the learner passes the corners of the
// faces that Step 4 has just removed (TriangleRemovalResult::touched_vertices). A boundary
// that Step 4 is still enlarging lies, at least in part, over a region without data that is
// being cut away (the membranes a shrinking mesh stretches across the hole of a torus, the
// remains of a strip sewn too early); sewing it now would build the handle inside that
// region and leave the rest of it to be cut again into further holes, each merged into a
// spurious handle. A boundary that Step 4 no longer touches has reached the data (Section
// 2.3: a real boundary slightly underestimates P), and is merged as the paper says.
// Deleted handles in `growing_vertices` are ignored.
BoundaryMergingResult MergeCloseBoundaries(Mesh& mesh, const BoundaryMergingOptions& options,
                                           double mean_area,
                                           absl::Span<const Mesh::VertexHandle> growing_vertices);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_BOUNDARY_MERGING_H_
