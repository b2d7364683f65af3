#include "core/learning/boundary_loops.h"

namespace neuralmesh {

std::vector<VertexLoop> CollectBoundaryLoops(const Mesh& mesh) {
  std::vector<VertexLoop> loops;
  std::vector<bool> visited(mesh.n_halfedges(), false);
  for (auto start : mesh.halfedges()) {
    if (visited[start.idx()] || !mesh.is_boundary(start)) continue;
    loops.push_back(BoundaryLoopFrom(mesh, start, &visited));
  }
  return loops;
}

VertexLoop BoundaryLoopFrom(const Mesh& mesh, Mesh::HalfedgeHandle start,
                            std::vector<bool>* visited) {
  VertexLoop loop;
  auto h = start;
  do {
    if (visited != nullptr) (*visited)[h.idx()] = true;
    loop.push_back(mesh.from_vertex_handle(h));
    h = mesh.next_halfedge_handle(h);
  } while (h != start);
  return loop;
}

}  // namespace neuralmesh
