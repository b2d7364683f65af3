// Closing of small holes: the inverse of Step 4 of Neural Meshes (Ivrissimtzis, Jeong, Seidel,
// "Neural Meshes: Statistical Learning Methods in Surface Reconstruction", Section 2 Step 4,
// Eq. 2, and Section 2.3), run right before Step 5. Not in the paper; it keeps the paper's
// promise of "absence of topological noise, that is, tiny boundaries or handles" (Section 1).
//
//   E <- E(Area) (given, or the mean area of the live faces)
//   for every boundary loop L with at most max_loop_vertices vertices:
//     among the triangulations of L in which every triangle has area <= alpha_r * E (Step 4
//     would keep it), every new edge is at most alpha_m * sqrt(E) long (the distance at which
//     Step 5 merges two boundaries) and does not exist yet, and every vertex keeps a legal
//     valence: add the one of least total new-edge length, if there is one
//
// Why: Step 4 removes a triangle when its area says that it covers a region without data
// (Eq. 2). While the mesh is still learning the geometry (a misplaced vertex, the remains of a
// strip sewn across a cavity by Step 5), it also cuts triangles in regions that do have data.
// The hole then shrinks back as its vertices converge, but it can never vanish: Step 3 may not
// collapse an edge of a loop of 3 vertices (OpenMesh's link condition), so the hole stays
// forever, and Step 5 sews pairs of such tiny holes into extra handles. Removals along a seam
// that Step 5 has sewn can also open a long thin slit: one loop whose two sides lie a few
// edges apart, which Step 5 cannot merge because it joins two different loops. A hole is
// refilled here only when Step 4 itself would keep every filling triangle (the data has come
// back, so the removal was premature) and no new edge is longer than Step 5 would bridge: the
// slit is zipped as Step 5 would sew two loops that close. A real boundary (an open surface's
// border, a hole over a cavity that Step 5 still has to merge) is never closed: any
// triangulation of a round hole has an edge across it, about sqrt(3) times its radius, so only
// holes narrower than about alpha_m sqrt(E) (a few edge lengths) qualify, and their filling
// triangles must still pass Step 4. Closing a hole is undone by Step 4 if its triangles grow
// large again, so the rule cannot fight the paper's steps; it only removes loops that would
// otherwise be stuck.
//
// Slits in longer loops (ZipBorderSlits): Step 4 can also cut a slit into a border, two sides
// about an edge apart running several edges into the data (hemisphere scenario of
// topology_learning_test: notches 3 to 5 edge lengths deep that stayed to the end). It is part
// of the border's loop, so CloseSmallHoles never sees it, and Step 5 merges different loops
// only. A stretch of a loop whose ends lie within alpha_m sqrt(E) of each other while the loop
// runs at least 3 times as far between them is filled as a hole whose last side is the new edge
// between its ends; a smooth border never qualifies (its path is barely longer than its chords).
// The fill is refused when a filling triangle folds back over the face across a chain edge
// (their normals point apart): the chain then went round a tongue of the mesh, not a slit.
//
// Cracks (CloseCrackTips): a slit longer than a chain may be, or one whose shortest filling
// takes a turned-over triangle, stays: two borders an edge or so apart over data are stable,
// since each stops a little inside the data as any border does (Section 2.3), and neither is
// another loop for Step 5. From the disc start (LearnerOptions::initial_mesh) the first Step 4
// cuts such cracks from the disc's rim deep into the sheet, and on the flat rectangle of
// topology_learning_test 10 of seeds 61-260 ended with one 0.03 to 0.25 deep. At a
// crack's tip the border turns back on itself: the vertex t there sees its two border
// neighbours a and b within 90 degrees of each other, on the side where it has no faces, while
// along a border, smooth or jagged, that angle is 180 degrees or more (a convex corner of the
// data: 270). The triangle (a, t, b) closes the tip and makes a or b the next one, so the crack
// zips up from its tip to its mouth, one triangle at a time, each subject to the limits of a
// hole's filling triangles and facing the way of the faces beside it. A concave corner of the
// data sharper than 90 degrees is filled the same way, over no data, until the opening is
// wider than alpha_m sqrt(E(Area)): a few edge lengths from its tip.
//
// Holes split by a bridge (CloseBridgedHoles): two loops joined by an interior edge, a bridge of
// two triangles whose free sides lie one on each loop, are one hole that a bridge one edge wide
// cuts in two. They arise where Step 4 opens a second hole right beside one that is still open
// while the mesh there is converging (a fold of the surface), and the bridge's corners lie over
// data and win, so CutInactiveBridges keeps it. Step 5 then sews the two loops together, and since
// the bridge already joins them, the strip and the bridge make a handle whose tunnel is the bridge:
// a handle one edge across, the topological noise the paper rules out (Section 1). Nor can
// CloseSmallHoles close either loop alone when the hole runs round a tube: each loop then winds
// round the tube, and a filling would span the tube with edges as long as its diameter (genus-2
// scenario of topology_learning_test, seed 18: two loops of 16 to 19 vertices side by side round a
// tube of 0.18 x 0.30, joined by a bridge, were sewn into a third handle at 4,944 vertices). Cut
// the bridge, and the two loops become the one loop of the hole, a band one or two edges wide round
// the tube, which has a filling of ordinary triangles. The rule cuts the bridge only when that loop
// then has an admissible triangulation as above (it is filled at once, and the bridge's two faces
// are put back otherwise), so it adds no face Step 4 would remove and no edge Step 5 would not
// bridge; it replaces two faces and a hole by a filling of the hole.
//
// Legality: no new edge may exist yet (no double edge, which also excludes closing a loop of 3
// vertices that bounds a single face on the other side); a vertex that gets no new edge (an
// ear tip, or each corner of a loop of 3) becomes interior and must have valence >= 3. The
// faces are added children first, each sharing two sides with the current hole border, in
// the loop's half-edge order, so orientation is kept. A loop never shares a vertex with another
// loop in a valid mesh, so filling one leaves every other loop intact and the mesh passes
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
  // alpha_m of Eq. 3: a new edge may be at most alpha_m * sqrt(E(Area)) long, the distance
  // below which Step 5 merges two boundaries. > 0.
  double alpha_m = 5;
  // Loops with more vertices are never closed. >= 3. It bounds the O(k^3) work per loop.
  int max_loop_vertices = 256;
  // Never fill the boundary loop of greatest perimeter (the first found among equals), nor
  // close it together with another through a bridge (CloseBridgedHoles): with the learner's
  // disc start (LearnerOptions::initial_mesh) it is the open sheet's own border. Slits in it
  // are still zipped (ZipBorderSlits), which leaves it open.
  bool keep_longest_loop_open = false;

  // Returns INVALID_ARGUMENT unless alpha_r and alpha_m are finite and positive and
  // max_loop_vertices >= 3.
  absl::Status Validate() const;
};

struct HoleClosingResult {
  size_t closed_holes = 0;
  size_t added_faces = 0;
};

// Fills every boundary loop of `mesh` with at most options.max_loop_vertices vertices that has
// an admissible triangulation (see the file comment). `mean_area` is E(Area) (for example
// TriangleRemovalResult::mean_area); pass <= 0 to compute it from the live faces. `options` must be
// valid (Validate()). Works on meshes with deleted elements, adds faces and edges without garbage
// collection, never adds or removes a vertex. O(h) to find the loops plus O(k^3) per loop of k
// vertices.
HoleClosingResult CloseSmallHoles(Mesh& mesh, const HoleClosingOptions& options, double mean_area);

// Closes pairs of holes split by a bridge (see the file comment): for every interior edge whose
// ends lie on two different boundary loops with at most options.max_loop_vertices vertices
// together, when removing its two faces together is legal (IsFaceSetRemovalOk) and the one
// loop this leaves has an admissible triangulation (as in CloseSmallHoles), removes the two
// faces and adds that triangulation; otherwise the mesh is left as it was, up to
// deleted-marked elements. Each pair of loops is tried once per call, through the first of its
// bridges whose cut is legal, and each loop takes part in at most one fill. HoleClosingResult
// counts each pair as one closed hole. `mean_area` and `options` as for CloseSmallHoles.
// O(h + sum of the valences of the loops' vertices) plus O(k^3) per tried pair of k vertices
// together.
HoleClosingResult CloseBridgedHoles(Mesh& mesh, const HoleClosingOptions& options,
                                    double mean_area);

// Closes the tips of cracks (see the file comment): while a border vertex t has border
// neighbours a and b at most 90 degrees apart as seen from t, on the side where t has no
// faces, with a - b not yet an edge and no longer than alpha_m sqrt(E(Area)), the triangle
// (a, t, b) no larger than alpha_r E(Area) and facing the way of the faces along a - t and
// t - b, and t of valence >= 3, adds the triangle. Loops of 3 are left to CloseSmallHoles.
// HoleClosingResult counts each triangle as a closed hole. `mean_area` and `options` as for
// CloseSmallHoles. O(h) to find the border half-edges, plus O(1) per triangle.
HoleClosingResult CloseCrackTips(Mesh& mesh, const HoleClosingOptions& options,
                                 double mean_area);

// Zips slits in boundary loops of any length (see the file comment): first CloseCrackTips,
// then repeatedly, the most slit-like chain of a loop (the smallest ratio of the distance between its ends to its length,
// at most 1/3, ends at most alpha_m sqrt(E(Area)) apart, 3 to 48 edges and at most half the
// loop) is filled by the same admissible triangulation as a small hole, with the chord between
// its ends as the new boundary edge, unless a filling triangle would fold back over the face
// across a chain edge. HoleClosingResult counts zipped slits as closed holes. `mean_area` and
// `options` as for CloseSmallHoles. O(h) per zip to find the loops plus O(n * 48) per loop of n
// vertices and O(48^3) per tried chain; at most 64 zips per call.
HoleClosingResult ZipBorderSlits(Mesh& mesh, const HoleClosingOptions& options,
                                 double mean_area);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_HOLE_CLOSING_H_
