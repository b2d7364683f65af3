// Topological report of a triangle soup: counts, valence distribution (as in Table 2 of
// Ivrissimtzis, Jeong, Seidel, "Neural Meshes: Statistical Learning Based on Normals", 2003),
// boundary loops, components, Euler characteristic, genus and manifoldness.
//
// Computed from a TriangleMesh with index arithmetic only, so it works on any input,
// including non-manifold and inconsistently oriented files:
//   1. drop faces with an out-of-range index (invalid) or a repeated index (degenerate);
//   2. bucket the face corners by vertex (counting sort) and number the undirected edges
//      from their lower endpoint, counting faces and directions per edge;
//   3. per vertex, build its link (one link edge per incident face, joining the two other
//      corners) and find the link's components with a small union-find: the vertex is
//      manifold when its link is one path (boundary, a half-disc) or one cycle (a disc);
//   4. pair the boundary edges at every vertex fan by fan, then walk the pairs into loops;
//   5. union-find over the faces for components; per-component chi gives the genus.
// Everything is O(v + f) time and memory, deterministic, without hashing.
#ifndef NEURALMESH_CORE_ANALYSIS_MESH_REPORT_H_
#define NEURALMESH_CORE_ANALYSIS_MESH_REPORT_H_

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/triangle_mesh.h"

namespace neuralmesh {

// Columns of the paper's Table 2: valences 4, 5, 6, 7, 8, 9 and everything else.
inline constexpr int kValenceShareColumns = 7;

struct MeshReport {
  // Vertices referenced by `faces`. Positions referenced by no such face are counted in
  // isolated_vertices (this includes vertices used only by degenerate faces), so
  // vertices + isolated_vertices = positions.size().
  size_t vertices = 0;
  // Faces that take part in the topology: in range and with three distinct indices. Input
  // faces = faces + degenerate_faces + invalid_faces. Duplicates are included in `faces`.
  size_t faces = 0;
  size_t edges = 0;  // Distinct undirected edges of `faces`.
  size_t isolated_vertices = 0;
  size_t degenerate_faces = 0;  // A vertex index repeated within the face.
  size_t invalid_faces = 0;     // A vertex index >= positions.size().
  size_t duplicate_faces = 0;   // Same vertex set as an earlier face, in any order/orientation.

  // Valence (number of distinct neighbours) -> number of vertices, over all `vertices`.
  std::map<int, size_t> valence_histogram;
  // Percentages for valences 4, 5, 6, 7, 8, 9 and "other", as in Table 2, over the interior
  // vertices only (those on no boundary edge): boundary vertices have fewer neighbours by
  // construction and would skew the distribution of an open mesh. All zero when there is no
  // interior vertex.
  double valence_share[kValenceShareColumns] = {0, 0, 0, 0, 0, 0, 0};
  double valence6_share = 0.0;   // = valence_share[2].
  size_t interior_vertices = 0;  // The denominator of the shares.

  // Boundary edges lie in exactly one face. At every vertex they are paired within the fans
  // (link components) they bound, so two loops touching at a pinched vertex stay two loops.
  // Exact for edge-manifold input; around non-manifold edges the pairing is a documented
  // best effort (leftover edges at a vertex are paired in index order, unpaired ones end an
  // open chain that is counted as one loop).
  size_t boundary_edges = 0;
  size_t boundary_loops = 0;
  std::vector<size_t> boundary_loop_lengths;  // In edges, longest first.

  size_t components = 0;  // Edge-connected components of `faces` (isolated vertices excluded).
  int64_t euler_characteristic = 0;  // vertices - edges + faces.
  // Sum over components of g_i, where chi_i = 2 - 2 g_i - b_i. Only meaningful for an oriented
  // manifold; -1 when manifold() or oriented is false.
  int genus = 0;

  bool closed = true;                // No boundary edge.
  bool edge_manifold = true;         // Every edge in one or two faces.
  bool vertex_manifold = true;       // Every vertex's faces form one fan (disc or half-disc); a
                                     // vertex on a non-manifold edge is not manifold either.
  bool oriented = true;              // Every edge in two faces is used in opposite directions.
                                     // Edges in three or more faces are not judged here.
  size_t non_manifold_edges = 0;     // Edges in three or more faces.
  size_t non_manifold_vertices = 0;  // Vertices whose faces do not form one fan.
  size_t misoriented_edges = 0;      // Edges in two faces used in the same direction.
  bool colored = false;              // A colour per vertex (TriangleMesh::colors).

  // Edge and vertex manifold, with no degenerate or invalid face.
  bool manifold() const {
    return edge_manifold && vertex_manifold && degenerate_faces == 0 && invalid_faces == 0;
  }
};

// Computes the report of `mesh`. Never fails: invalid and degenerate faces are counted and
// left out of the topology. O(v + f) time and memory.
MeshReport ComputeMeshReport(const TriangleMesh& mesh);

// A few aligned human-readable lines, ending with the valence table in the layout of the
// paper's Table 2.
std::string MeshReportToText(const MeshReport& report);

// One JSON object with snake_case keys named after the MeshReport fields, plus "manifold";
// the histogram is an object keyed by valence, the shares an object keyed "4".."9","other".
// indent as in JsonWriter (0: one line).
std::string MeshReportToJson(const MeshReport& report, int indent = 0);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_MESH_REPORT_H_
