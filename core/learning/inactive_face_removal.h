// Removal of faces over no data that Steps 3 and 4 of Neural Meshes cannot remove
// (Ivrissimtzis, Jeong, Seidel, "Neural Meshes: Statistical Learning Methods in Surface
// Reconstruction", Section 2 Steps 3-4, Section 2.3). Not in the paper. Both rules below run
// right after Step 4 and judge the data as Step 3 does: a vertex that has not won since the last
// call of Step 3 is inactive, it represents no data. Over data a vertex gets on average C_ec
// wins between two calls (a border vertex about half as many), so the chance that all corners
// of a face are inactive there is negligible.
//
// 1. Bridges between two holes (CutInactiveBridges).
//      label the boundary loops
//      for every interior edge e = (a, b) with a and b on two different loops:
//        f1, f2 <- the two faces of e
//        if every corner of f1 and f2 is inactive and removing f1 and f2 together is legal:
//          remove f1 and f2; the two loops are now one
//    Why: a membrane over no data (across the tunnel of a torus the mesh has not learned yet)
//    loses its vertices to Step 3 and its triangles to Step 4; the paper expects it to open as
//    one hole whose border retreats onto the data, where Step 5 sews it to the hole on the other
//    side of the tunnel. When Step 4 opens two holes in one membrane, they grow towards each
//    other until only a bridge of triangles whose corners all lie on one hole or the other is
//    left. Nothing removes it: Step 3 may not collapse the edge across it (that joins the two
//    holes at one vertex, a pinch), and Step 4 may not remove either triangle alone (the same
//    pinch, at the corner across from the triangle's boundary edge). The two half-holes stay
//    too far from the hole on the other side for Step 5, and the tunnel never opens (genus-2
//    scenario of topology_learning_test, seed 8). Removing both triangles at once leaves no
//    pinch and joins the two holes into the one that Step 4 would have opened.
//
// 2. Border vertices that Step 3 cannot collapse (CutOutBorderVertex).
//      for every inactive boundary vertex v that Step 3 found no legal collapse for:
//        if removing all of v's faces is legal: remove them and v
//    Why: a border vertex moves only when it wins (the smoothing slides it along the border,
//    never across), and it is collapsed only along the border, into a neighbour that must not
//    become a hub (half_edge_collapse.h). Where the border has folded back under the surface, a
//    flap of the mesh lies beneath the vertices that take its samples: its border vertices
//    never win, never move and, with the valence they collect from the collapses around them,
//    never collapse. The border then keeps a notch in the data (hemisphere scenario, seeds 4,
//    11, 16: border vertices 3 to 5 edge lengths above the true border). Removing such a
//    vertex's fan moves the border one ring inwards, onto vertices that win if they lie on data
//    and meet the same rule next time if they do not, so the flap erodes down to its crease.
//
// Legality, for a set of faces removed together: every corner that keeps a face must keep
// exactly one fan of them (a single run of faces around it with one boundary gap), so no pinch
// and no isolated vertex is left; OpenMesh deletes the edges left without a face, so no edge
// dangles. A cut between two different boundary loops never separates the surface. A vertex is
// cut out only when every side of its fan across from it is an interior edge: those sides stay,
// so the ring around the vertex keeps connected what its faces connected. The mesh passes
// ValidateMesh after every removal.
#ifndef NEURALMESH_CORE_LEARNING_INACTIVE_FACE_REMOVAL_H_
#define NEURALMESH_CORE_LEARNING_INACTIVE_FACE_REMOVAL_H_

#include <cstddef>
#include <functional>
#include <vector>

#include "absl/types/span.h"
#include "core/mesh.h"

namespace neuralmesh {

struct BridgeCuttingResult {
  size_t cut_bridges = 0;  // Each removed two faces and joined two loops.
  // The corners of the removed faces: they lie on a boundary that grew in this call.
  std::vector<Mesh::VertexHandle> touched_vertices;
};

// Whether removing the live `faces` together leaves every corner of theirs but `emptied` with
// exactly one fan of faces (see the file comment). `emptied` (may be invalid) is a corner that
// is meant to lose all its faces. O(sum of the corners' valences times |faces|).
bool IsFaceSetRemovalOk(const Mesh& mesh, absl::Span<const Mesh::FaceHandle> faces,
                        Mesh::VertexHandle emptied);

// Removes, one after the other, the bridges between two different boundary loops whose corners
// are all `inactive` and whose removal is legal (see the file comment). Elements are only
// marked deleted. O(v + e).
BridgeCuttingResult CutInactiveBridges(
    Mesh& mesh, const std::function<bool(Mesh::VertexHandle)>& inactive);

// Removes every face around the boundary vertex `v`, which is deleted with them, when that
// leaves a manifold with the same components: every other corner keeps one fan (as in
// IsFaceSetRemovalOk) and no side across from v is a boundary edge. Returns whether it did;
// appends v to `removed_vertices` and its former neighbours to `touched_vertices` (either may
// be null).
bool CutOutBorderVertex(Mesh& mesh, Mesh::VertexHandle v,
                        std::vector<Mesh::VertexHandle>* removed_vertices,
                        std::vector<Mesh::VertexHandle>* touched_vertices);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_INACTIVE_FACE_REMOVAL_H_
