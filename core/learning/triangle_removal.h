// Step 4 of Neural Meshes: triangle removal (Ivrissimtzis, Jeong, Seidel, "Neural Meshes:
// Statistical Learning Methods in Surface Reconstruction", Section 2 Step 4, Eq. 2, and
// Section 2.3). Triangles far larger than the mean represent parts of the target with almost no
// probability density (Section 3.1), so they are cut out, opening a boundary.
//
//   E <- mean area of the live faces                                  (once per call)
//   L <- faces with area > alpha_r * E                                 (Eq. 2)
//   while some face of L is queued:
//     f <- the largest queued face with a boundary edge (it grows a hole or boundary), or,
//          when there is none, the largest queued face (it opens a new hole)
//     if f's component has at most 4 faces, or removing f is not
//        manifold-safe (IsTriangleRemovalOk):  park f                  (skip, may become legal)
//     else: remove f (and a corner left without faces);
//           queue again the parked faces around f's corners            (their legality changed)
//
// Why holes are grown before new ones are opened: removing the large faces of a region in
// plain largest-first order scatters small holes over it, and the faces left between two
// holes touch both, so every one of them would pinch a vertex and none could ever go (on a
// sphere whose faces are all large, 54 of 80 faces stay). Growing a hole from its boundary
// keeps it one disc, and a disc always has a removable face, so the region goes entirely.
// Largest first still orders the faces along a boundary and the seeds of new holes.
//
// Legality of removing a face f (IsTriangleRemovalOk) and why:
//  - An edge of f that is interior becomes a boundary edge; an edge of f that is already on
//    the boundary loses its only face and is deleted with it, so no edge is left without a
//    face (no dangling edge).
//  - A corner v of f whose two edges in f are both interior must itself be interior. If v is
//    already on a boundary, f lies in the middle of v's fan and removing it would split the
//    fan in two: v would become a pinch (non-manifold vertex), and the faces on one side
//    would hang on the rest only through v (a dangling fan). This is the only way a removal
//    can break manifoldness, so it is the only local rule.
//  - A corner whose two edges in f are both boundary edges has f as its only face: it would
//    be left isolated, so it is removed with f and reported. We allow this on purpose: it is
//    how a spike whose whole fan is large (a misplaced vertex) or an ear of large triangles
//    on a boundary goes away; skipping it would keep such faces forever.
//  - Every other corner keeps a single fan, with one boundary gap. It loses at most one edge
//    and still has at least one face, so its boundary valence stays >= 2.
//  - A removal never splits a component: the neighbours of f stay connected through the fans
//    of f's corners, which remain contiguous.
// Policy on top of legality (RemoveLargeTriangles only): a face whose component has at most
// 4 faces (a tetrahedron or less) is never removed, so the learner always keeps a minimal
// surface to grow from, and no component (hence never the whole mesh) disappears.
//
// Elements are only marked deleted (no garbage collection), faces and vertices already
// marked deleted are skipped, and the mesh passes ValidateMesh after every single removal,
// including OpenMesh's invariant that a boundary vertex stores a boundary outgoing half-edge.
#ifndef NEURALMESH_CORE_LEARNING_TRIANGLE_REMOVAL_H_
#define NEURALMESH_CORE_LEARNING_TRIANGLE_REMOVAL_H_

#include <cstddef>
#include <functional>
#include <vector>

#include "absl/status/status.h"
#include "core/mesh.h"

namespace neuralmesh {

struct TriangleRemovalOptions {
  double alpha_r = 7;  // alpha_r, Eq. 2: remove faces with area > alpha_r * E(Area), > 0.

  // Returns INVALID_ARGUMENT unless alpha_r is finite and positive.
  absl::Status Validate() const;
};

struct TriangleRemovalResult {
  size_t removed_faces = 0;
  // Vertices deleted because their last face was removed. The learner must drop them from
  // its spatial index and its per-vertex statistics.
  std::vector<Mesh::VertexHandle> removed_vertices;
  // The surviving corners of the removed faces: they lie on a boundary that grew in this call
  // (Step 5 leaves such still-growing boundaries alone, see boundary_merging.h).
  std::vector<Mesh::VertexHandle> touched_vertices;
  // E(Area): the mean area of the live faces at the start of the call (0 for an empty mesh).
  double mean_area = 0;
};

// The mean area of the live (not deleted) faces of `mesh`: E(Area) of Eq. 2 and 3. 0 when the
// mesh has no face. O(f).
double MeanTriangleArea(const Mesh& mesh);

// Whether deleting the live face `fh` keeps `mesh` a manifold (rules in the file comment):
// false when a corner of `fh` whose two edges in `fh` are interior lies on a boundary. O(1).
bool IsTriangleRemovalOk(const Mesh& mesh, Mesh::FaceHandle fh);

// Deletes the live face `fh`, for which IsTriangleRemovalOk holds, together with its edges
// that are left without a face and its corners that are left without a face; appends those
// corners to `removed_vertices` (may be null). Restores OpenMesh's boundary half-edge
// invariant at the surviving corners. O(valence).
void RemoveTriangle(Mesh& mesh, Mesh::FaceHandle fh,
                    std::vector<Mesh::VertexHandle>* removed_vertices);

// Step 4 (Eq. 2): removes every face with area > options.alpha_r * E(Area) whose removal is
// legal and whose component has more than 4 faces, growing holes from their boundary before
// opening new ones, largest first within each (see the file comment). A face skipped as
// illegal is retried after a neighbouring removal has changed its surroundings. `options`
// must be valid (Validate()). O(f + k log k) for k large faces.
TriangleRemovalResult RemoveLargeTriangles(Mesh& mesh, const TriangleRemovalOptions& options);

// As above, but a face for which `spared` returns true is never removed (it still counts in
// E(Area)).
TriangleRemovalResult RemoveLargeTriangles(
    Mesh& mesh, const TriangleRemovalOptions& options,
    const std::function<bool(Mesh::FaceHandle)>& spared);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_TRIANGLE_REMOVAL_H_
