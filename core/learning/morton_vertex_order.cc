#include "core/learning/morton_vertex_order.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "core/morton_code.h"

namespace neuralmesh {
namespace {

// Rearranges slots 0..n-1 so that slot k holds what slot order[k] held (order: a permutation),
// through swap_slots(a, b) calls that exchange two slots' contents: at most n - 1 of them.
template <typename SwapSlots>
void PermuteBySwaps(const std::vector<int>& order, SwapSlots swap_slots) {
  const size_t n = order.size();
  // slot_of[i]: where the original content of slot i is now; held_by: the reverse.
  std::vector<int> slot_of(n), held_by(n);
  for (size_t i = 0; i < n; ++i) slot_of[i] = held_by[i] = static_cast<int>(i);
  for (size_t k = 0; k < n; ++k) {
    const int wanted = order[k];
    const size_t from = static_cast<size_t>(slot_of[wanted]);
    if (from == k) continue;
    swap_slots(k, from);
    const int displaced = held_by[k];
    held_by[from] = displaced;
    slot_of[displaced] = static_cast<int>(from);
    held_by[k] = wanted;
    slot_of[wanted] = static_cast<int>(k);
  }
}

}  // namespace

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

  // Then every vertex property: slot k receives old vertex keyed[k].second.
  std::vector<int> order(n);
  for (size_t k = 0; k < n; ++k) order[k] = keyed[k].second;
  PermuteBySwaps(order, [&mesh](size_t a, size_t b) {
    for (auto p = mesh.vprops_begin(); p != mesh.vprops_end(); ++p) {
      if (*p != nullptr) (*p)->swap(a, b);
    }
  });
  return new_index;
}

void SortEdgesByVertexIndex(Mesh& mesh) {
  const size_t n = mesh.n_edges();
  if (n == 0) return;
  std::vector<std::pair<std::pair<int, int>, int>> keyed(n);
  for (size_t e = 0; e < n; ++e) {
    const Mesh::HalfedgeHandle h(static_cast<int>(2 * e));
    const int a = mesh.to_vertex_handle(h).idx();
    const int b = mesh.to_vertex_handle(mesh.opposite_halfedge_handle(h)).idx();
    keyed[e] = {{std::min(a, b), std::max(a, b)}, static_cast<int>(e)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> new_edge(n);
  for (size_t k = 0; k < n; ++k) new_edge[keyed[k].second] = static_cast<int>(k);
  auto moved = [&new_edge](Mesh::HalfedgeHandle h) {
    return h.is_valid() ? Mesh::HalfedgeHandle(2 * new_edge[h.idx() >> 1] + (h.idx() & 1)) : h;
  };

  // The handles first, while the half-edges are still where the old indices say. OpenMesh sets
  // a half-edge's next only together with that next's prev, so the links are kept aside and
  // set once the half-edges have moved.
  for (auto v : mesh.all_vertices()) mesh.set_halfedge_handle(v, moved(mesh.halfedge_handle(v)));
  for (auto f : mesh.all_faces()) mesh.set_halfedge_handle(f, moved(mesh.halfedge_handle(f)));
  std::vector<Mesh::HalfedgeHandle> next_of(2 * n);  // By new half-edge index.
  for (auto h : mesh.all_halfedges()) next_of[moved(h).idx()] = moved(mesh.next_halfedge_handle(h));

  // Then the edges with their half-edges' connectivity and every property: slot k receives old
  // edge keyed[k].second.
  std::vector<int> order(n);
  for (size_t k = 0; k < n; ++k) order[k] = keyed[k].second;
  PermuteBySwaps(order, [&mesh](size_t a, size_t b) {
    std::swap(mesh.edge(Mesh::EdgeHandle(static_cast<int>(a))),
              mesh.edge(Mesh::EdgeHandle(static_cast<int>(b))));
    for (auto p = mesh.eprops_begin(); p != mesh.eprops_end(); ++p) {
      if (*p != nullptr) (*p)->swap(a, b);
    }
    for (auto p = mesh.hprops_begin(); p != mesh.hprops_end(); ++p) {
      if (*p == nullptr) continue;
      (*p)->swap(2 * a, 2 * b);
      (*p)->swap(2 * a + 1, 2 * b + 1);
    }
  });
  for (auto h : mesh.all_halfedges()) {
    if (next_of[h.idx()].is_valid()) mesh.set_next_halfedge_handle(h, next_of[h.idx()]);
  }
}

}  // namespace neuralmesh
