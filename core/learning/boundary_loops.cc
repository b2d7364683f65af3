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

double LoopPerimeter(const Mesh& mesh, const VertexLoop& loop) {
  double perimeter = 0;
  for (size_t i = 0; i < loop.size(); ++i) {
    const size_t next = i + 1 == loop.size() ? 0 : i + 1;
    perimeter += (mesh.point(loop[next]) - mesh.point(loop[i])).norm();
  }
  return perimeter;
}

int LongestLoop(const Mesh& mesh, const std::vector<VertexLoop>& loops) {
  int longest = -1;
  double longest_perimeter = -1;
  for (size_t i = 0; i < loops.size(); ++i) {
    const double perimeter = LoopPerimeter(mesh, loops[i]);
    if (perimeter > longest_perimeter) {
      longest = static_cast<int>(i);
      longest_perimeter = perimeter;
    }
  }
  return longest;
}

}  // namespace neuralmesh
