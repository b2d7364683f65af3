#include "core/learning/morton_vertex_order.h"

#include <algorithm>
#include <utility>

#include "core/morton_code.h"

namespace neuralmesh {

std::vector<int> SortVerticesInMortonOrder(Mesh& mesh) {
  const size_t n = mesh.n_vertices();
  std::vector<int> new_index(n);
  if (n == 0) return new_index;
  Vec3 min = mesh.point(Mesh::VertexHandle(0));
  Vec3 max = min;
  for (auto v : mesh.all_vertices()) {
    min.minimize(mesh.point(v));
    max.maximize(mesh.point(v));
  }
  std::vector<std::pair<uint64_t, int>> keyed(n);
  for (size_t i = 0; i < n; ++i) {
    const int v = static_cast<int>(i);
    keyed[i] = {MortonCode(mesh.point(Mesh::VertexHandle(v)), min, max), v};
  }
  std::sort(keyed.begin(), keyed.end());
  for (size_t k = 0; k < n; ++k) new_index[keyed[k].second] = static_cast<int>(k);

  // The connectivity first, while the old indices still name the old vertices.
  std::vector<Mesh::HalfedgeHandle> outgoing(n);
  for (size_t i = 0; i < n; ++i) {
    outgoing[new_index[i]] = mesh.halfedge_handle(Mesh::VertexHandle(static_cast<int>(i)));
  }
  for (size_t k = 0; k < n; ++k) {
    mesh.set_halfedge_handle(Mesh::VertexHandle(static_cast<int>(k)), outgoing[k]);
  }
  for (auto h : mesh.all_halfedges()) {
    const Mesh::VertexHandle to = mesh.to_vertex_handle(h);
    if (to.is_valid()) mesh.set_vertex_handle(h, Mesh::VertexHandle(new_index[to.idx()]));
  }

  // Then every vertex property, by swaps: slot k receives old vertex keyed[k].second.
  // slot_of[old] is where old vertex `old` currently sits, held_by[slot] the reverse.
  std::vector<int> slot_of(n), held_by(n);
  for (size_t i = 0; i < n; ++i) slot_of[i] = held_by[i] = static_cast<int>(i);
  for (size_t k = 0; k < n; ++k) {
    const int wanted = keyed[k].second;
    const size_t from = static_cast<size_t>(slot_of[wanted]);
    if (from == k) continue;
    for (auto p = mesh.vprops_begin(); p != mesh.vprops_end(); ++p) {
      if (*p != nullptr) (*p)->swap(k, from);
    }
    const int displaced = held_by[k];
    held_by[from] = displaced;
    slot_of[displaced] = static_cast<int>(from);
    held_by[k] = wanted;
    slot_of[wanted] = static_cast<int>(k);
  }
  return new_index;
}

}  // namespace neuralmesh
