#include "core/learning/morton_vertex_order.h"

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include <OpenMesh/Core/Utils/Property.hh>

#include "core/morton_code.h"

namespace neuralmesh {
namespace {

// The old indices of the live elements among `n`, in the order garbage_collection() leaves
// them: it fills each deleted slot, from the front, with the last live element, from the back.
template <typename IsDeleted>
std::vector<int> CollectedOrder(size_t n, IsDeleted deleted) {
  std::vector<int> at(n);
  for (size_t i = 0; i < n; ++i) at[i] = static_cast<int>(i);
  if (n == 0) return at;
  size_t i0 = 0, i1 = n - 1;
  while (true) {
    while (!deleted(at[i0]) && i0 < i1) ++i0;
    while (deleted(at[i1]) && i0 < i1) --i1;
    if (i0 >= i1) break;
    std::swap(at[i0], at[i1]);
  }
  at.resize(deleted(at[i0]) ? i0 : i0 + 1);
  return at;
}

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

// If `property` holds values of type T: makes element k (`stride` values) hold what element
// old_of[k] held, drops the others and returns true. The storage keeps its capacity, so the
// elements that splits append next do not reallocate it.
template <typename T>
bool GatherIfOfType(OpenMesh::BaseProperty& property, const std::vector<int>& old_of,
                    size_t stride) {
  auto* typed = dynamic_cast<OpenMesh::PropertyT<T>*>(&property);
  if (typed == nullptr) return false;
  auto& values = typed->data_vector();
  std::remove_reference_t<decltype(values)> gathered;
  gathered.reserve(values.capacity());
  gathered.resize(old_of.size() * stride);
  for (size_t k = 0; k < old_of.size(); ++k) {
    const size_t from = static_cast<size_t>(old_of[k]) * stride;
    for (size_t j = 0; j < stride; ++j) gathered[k * stride + j] = values[from + j];
  }
  values.swap(gathered);
  return true;
}

// Makes element k of `property` (`stride` values each, `old_count` elements) hold what element
// old_of[k] held, and drops the elements old_of does not name.
void GatherProperty(OpenMesh::BaseProperty& property, const std::vector<int>& old_of, size_t stride,
                    size_t old_count) {
  using OpenMesh::Attributes::StatusInfo;
  if (GatherIfOfType<StatusInfo>(property, old_of, stride) ||
      GatherIfOfType<Vec3>(property, old_of, stride) ||
      GatherIfOfType<Vec3f>(property, old_of, stride) ||
      GatherIfOfType<bool>(property, old_of, stride) ||
      GatherIfOfType<double>(property, old_of, stride) ||
      GatherIfOfType<float>(property, old_of, stride) ||
      GatherIfOfType<int32_t>(property, old_of, stride) ||
      GatherIfOfType<uint32_t>(property, old_of, stride) ||
      GatherIfOfType<int64_t>(property, old_of, stride) ||
      GatherIfOfType<uint64_t>(property, old_of, stride)) {
    return;
  }
  // Any other value type, through the property's own swap: the kept elements first, in their
  // new order, then the dropped ones, cut off.
  std::vector<int> order = old_of;
  std::vector<bool> kept(old_count, false);
  for (const int i : old_of) kept[static_cast<size_t>(i)] = true;
  for (size_t i = 0; i < old_count; ++i) {
    if (!kept[i]) order.push_back(static_cast<int>(i));
  }
  PermuteBySwaps(order, [&property, stride](size_t a, size_t b) {
    for (size_t j = 0; j < stride; ++j) property.swap(a * stride + j, b * stride + j);
  });
  property.resize(old_of.size() * stride);
}

// The live vertices (old indices) in garbage_collection()'s order, then sorted by Morton code.
std::vector<int> VertexOrder(const Mesh& mesh) {
  const std::vector<int> collected = CollectedOrder(
      mesh.n_vertices(), [&mesh](int v) { return mesh.status(Mesh::VertexHandle(v)).deleted(); });
  const size_t n = collected.size();
  if (n == 0) return collected;
  Vec3 min = mesh.point(Mesh::VertexHandle(collected[0]));
  Vec3 max = min;
  for (const int v : collected) {
    min.minimize(mesh.point(Mesh::VertexHandle(v)));
    max.maximize(mesh.point(Mesh::VertexHandle(v)));
  }
  std::vector<std::pair<uint64_t, int>> keyed(n);
  for (size_t i = 0; i < n; ++i) {
    keyed[i] = {MortonCode(mesh.point(Mesh::VertexHandle(collected[i])), min, max),
                static_cast<int>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> order(n);
  for (size_t k = 0; k < n; ++k) order[k] = collected[static_cast<size_t>(keyed[k].second)];
  return order;
}

// The live edges (old indices) in garbage_collection()'s order, then sorted by their new vertex
// indices: counted out by the smaller one, which keeps that order among equals, then within
// each count (a few edges) by the larger one, by insertion, which keeps it too. Every live
// edge's ends must be live vertices, as OpenMesh's deletions leave them.
std::vector<int> EdgeOrder(const Mesh& mesh, const std::vector<int>& new_vertex,
                           size_t num_vertices) {
  const std::vector<int> collected = CollectedOrder(
      mesh.n_edges(), [&mesh](int e) { return mesh.status(Mesh::EdgeHandle(e)).deleted(); });
  const size_t n = collected.size();
  std::vector<std::pair<int, int>> ends(n);  // (smaller, larger) new vertex index.
  std::vector<int> first(num_vertices + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const Mesh::HalfedgeHandle h(2 * collected[i]);
    const int a = new_vertex[static_cast<size_t>(mesh.to_vertex_handle(h).idx())];
    const int b = new_vertex[static_cast<size_t>(mesh.from_vertex_handle(h).idx())];
    ends[i] = {std::min(a, b), std::max(a, b)};
    ++first[static_cast<size_t>(ends[i].first) + 1];
  }
  for (size_t v = 0; v < num_vertices; ++v) first[v + 1] += first[v];
  std::vector<int> slot(n);  // Collected slots, by smaller end.
  std::vector<int> next = first;
  for (size_t i = 0; i < n; ++i) {
    slot[static_cast<size_t>(next[static_cast<size_t>(ends[i].first)]++)] = static_cast<int>(i);
  }
  for (size_t v = 0; v < num_vertices; ++v) {
    const auto begin = slot.begin() + first[v], end = slot.begin() + first[v + 1];
    for (auto it = begin + (begin == end ? 0 : 1); it < end; ++it) {
      const int moving = *it;
      auto hole = it;
      for (; hole > begin && ends[static_cast<size_t>(*(hole - 1))].second >
                                 ends[static_cast<size_t>(moving)].second;
           --hole) {
        *hole = *(hole - 1);
      }
      *hole = moving;
    }
  }
  std::vector<int> order(n);
  for (size_t k = 0; k < n; ++k) order[k] = collected[static_cast<size_t>(slot[k])];
  return order;
}

// Where every element is linked, in the new numbering, read off the old one.
struct HalfedgeLinks {
  Mesh::VertexHandle to;
  Mesh::FaceHandle face;
  Mesh::HalfedgeHandle next;
};

}  // namespace

std::vector<int> CompactInMortonOrder(Mesh& mesh) {
  const size_t old_vertices = mesh.n_vertices();
  const size_t old_edges = mesh.n_edges();
  const size_t old_faces = mesh.n_faces();

  const std::vector<int> vertex_order = VertexOrder(mesh);
  std::vector<int> new_vertex(old_vertices, -1);
  for (size_t k = 0; k < vertex_order.size(); ++k) {
    new_vertex[static_cast<size_t>(vertex_order[k])] = static_cast<int>(k);
  }
  const std::vector<int> edge_order = EdgeOrder(mesh, new_vertex, vertex_order.size());
  std::vector<int> new_edge(old_edges, -1);
  for (size_t k = 0; k < edge_order.size(); ++k) {
    new_edge[static_cast<size_t>(edge_order[k])] = static_cast<int>(k);
  }
  const std::vector<int> face_order = CollectedOrder(
      old_faces, [&mesh](int f) { return mesh.status(Mesh::FaceHandle(f)).deleted(); });
  std::vector<int> new_face(old_faces, -1);
  for (size_t k = 0; k < face_order.size(); ++k) {
    new_face[static_cast<size_t>(face_order[k])] = static_cast<int>(k);
  }
  auto new_halfedge = [&new_edge](Mesh::HalfedgeHandle h) {
    return h.is_valid() ? Mesh::HalfedgeHandle(2 * new_edge[static_cast<size_t>(h.idx() >> 1)] +
                                               (h.idx() & 1))
                        : h;
  };

  // The connectivity in the new numbering, read while the old one still stands.
  std::vector<Mesh::HalfedgeHandle> vertex_halfedge(vertex_order.size());
  for (size_t k = 0; k < vertex_order.size(); ++k) {
    vertex_halfedge[k] = new_halfedge(mesh.halfedge_handle(Mesh::VertexHandle(vertex_order[k])));
  }
  std::vector<HalfedgeLinks> links(2 * edge_order.size());
  for (size_t k = 0; k < edge_order.size(); ++k) {
    for (int side = 0; side < 2; ++side) {
      const Mesh::HalfedgeHandle h(2 * edge_order[k] + side);
      const Mesh::FaceHandle face = mesh.face_handle(h);
      links[2 * k + static_cast<size_t>(side)] = {
          Mesh::VertexHandle(new_vertex[static_cast<size_t>(mesh.to_vertex_handle(h).idx())]),
          face.is_valid() ? Mesh::FaceHandle(new_face[static_cast<size_t>(face.idx())]) : face,
          new_halfedge(mesh.next_halfedge_handle(h))};
    }
  }
  std::vector<Mesh::HalfedgeHandle> face_halfedge(face_order.size());
  for (size_t k = 0; k < face_order.size(); ++k) {
    face_halfedge[k] = new_halfedge(mesh.halfedge_handle(Mesh::FaceHandle(face_order[k])));
  }

  // Every property with its element, then the elements themselves.
  for (auto p = mesh.vprops_begin(); p != mesh.vprops_end(); ++p) {
    if (*p != nullptr) GatherProperty(**p, vertex_order, 1, old_vertices);
  }
  for (auto p = mesh.eprops_begin(); p != mesh.eprops_end(); ++p) {
    if (*p != nullptr) GatherProperty(**p, edge_order, 1, old_edges);
  }
  for (auto p = mesh.hprops_begin(); p != mesh.hprops_end(); ++p) {
    if (*p != nullptr) GatherProperty(**p, edge_order, 2, old_edges);
  }
  for (auto p = mesh.fprops_begin(); p != mesh.fprops_end(); ++p) {
    if (*p != nullptr) GatherProperty(**p, face_order, 1, old_faces);
  }
  mesh.resize(vertex_order.size(), edge_order.size(), face_order.size());
  for (size_t k = 0; k < vertex_halfedge.size(); ++k) {
    mesh.set_halfedge_handle(Mesh::VertexHandle(static_cast<int>(k)), vertex_halfedge[k]);
  }
  for (size_t h = 0; h < links.size(); ++h) {
    const Mesh::HalfedgeHandle handle(static_cast<int>(h));
    mesh.set_vertex_handle(handle, links[h].to);
    mesh.set_face_handle(handle, links[h].face);
  }
  // Setting a half-edge's next also sets that next's prev, as the collection does.
  for (size_t h = 0; h < links.size(); ++h) {
    if (links[h].next.is_valid()) {
      mesh.set_next_halfedge_handle(Mesh::HalfedgeHandle(static_cast<int>(h)), links[h].next);
    }
  }
  for (size_t k = 0; k < face_halfedge.size(); ++k) {
    mesh.set_halfedge_handle(Mesh::FaceHandle(static_cast<int>(k)), face_halfedge[k]);
  }
  return new_vertex;
}

}  // namespace neuralmesh
