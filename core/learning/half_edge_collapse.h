// Step 3's half-edge collapse (Section 2.2, Fig. 2): an inactive vertex v is collapsed into the
// neighbour u that minimises the connectivity irregularity after the collapse,
//   inside   (Eq. 10): 1/3 sqrt((a+b-10)^2 + (c-7)^2 + (d-7)^2)
//   boundary (Eq. 11): 1/2 sqrt((a+b-7)^2 + (c-7)^2)
// with a = valence(v), b = valence(u), c, d the valences of the vertices opposite the edge.
// Both are the root-mean-square deviation of the affected vertices from the ideal valence (6
// inside, 4 on a boundary) after the collapse; where an affected vertex lies on a boundary
// while the equation assumes it inside (or the reverse), its own ideal valence is used.
// A boundary vertex collapses only along a boundary edge, keeping the border in place.
// Every candidate is checked first (OpenMesh's link condition plus minimum valences), so the
// mesh stays a manifold.
// Not in the paper: nor may a collapse leave u with more than twice its ideal valence (12
// inside, 8 on a boundary). Eq. 10-11 only rank the candidates of one vertex; when all of
// them are bad the least bad one was taken, and on the membranes that Step 4 cuts away (no
// data, so every vertex is inactive) the border vertices passed their stars on from collapse
// to collapse, into hubs of valence 20-45 whose sliver fans Step 4 could not remove and which
// kept reopening holes in the data once the handle had formed. Such a vertex now waits, and
// Step 4 removes its large faces instead.
#ifndef NEURALMESH_CORE_LEARNING_HALF_EDGE_COLLAPSE_H_
#define NEURALMESH_CORE_LEARNING_HALF_EDGE_COLLAPSE_H_

#include "core/mesh.h"

namespace neuralmesh {

// The half-edge v -> u of the legal collapse with the lowest irregularity, or an invalid
// handle when no collapse of v is legal. `live_vertices` is the number of undeleted vertices.
// Needs a non-const mesh only because OpenMesh's is_collapse_ok uses tag bits.
Mesh::HalfedgeHandle BestCollapse(Mesh& mesh, Mesh::VertexHandle v, size_t live_vertices);

// The irregularity of collapsing `h` (Eq. 10 or 11, generalised as above).
double CollapseIrregularity(const Mesh& mesh, Mesh::HalfedgeHandle h);

// Whether collapsing `h` keeps the mesh a manifold with valences >= 3 inside and >= 2 on
// boundaries, leaves the target vertex at most twice its ideal valence, and leaves at least 4
// vertices.
bool IsCollapseLegal(Mesh& mesh, Mesh::HalfedgeHandle h, size_t live_vertices);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_HALF_EDGE_COLLAPSE_H_
