#include "core/learning/boundary_loops.h"

namespace neuralmesh {

std::vector<VertexLoop> CollectBoundaryLoops(const Mesh& mesh) {
  std::vector<VertexLoop> loops;
  std::vector<bool> visited(mesh.n_halfedges(), false);
  for (auto start : mesh.halfedges()) {
    if (visited[start.idx()] || !mesh.is_boundary(start)) continue;
    VertexLoop loop;
    auto h = start;
    do {
      visited[h.idx()] = true;
      loop.push_back(mesh.from_vertex_handle(h));
      h = mesh.next_halfedge_handle(h);
    } while (h != start);
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace neuralmesh
