#include "core/learning/inactive_face_removal.h"

#include <algorithm>
#include <array>
#include <vector>

#include "core/learning/boundary_loops.h"
#include "core/learning/triangle_removal.h"

namespace neuralmesh {
namespace {

// The boundary loop of each vertex (-1 for an interior vertex), and a union-find over the loop
// numbers so that two loops joined by a cut count as one from then on.
class BoundaryLoops {
 public:
  explicit BoundaryLoops(const Mesh& mesh) : loop_of_vertex_(mesh.n_vertices(), -1) {
    for (const VertexLoop& vertices : CollectBoundaryLoops(mesh)) {
      const int loop = static_cast<int>(parent_.size());
      parent_.push_back(loop);
      for (auto v : vertices) loop_of_vertex_[v.idx()] = loop;
    }
  }

  // The loop of `v` (its representative after joins), or -1.
  int Of(Mesh::VertexHandle v) {
    const int loop = loop_of_vertex_[v.idx()];
    return loop < 0 ? -1 : Find(loop);
  }

  void Join(int a, int b) { parent_[Find(a)] = Find(b); }
  size_t count() const { return parent_.size(); }  // Loops found, joins not subtracted.

 private:
  int Find(int loop) {
    while (parent_[loop] != loop) loop = parent_[loop] = parent_[parent_[loop]];
    return loop;
  }

  std::vector<int> loop_of_vertex_;
  std::vector<int> parent_;
};

}  // namespace

bool IsFaceSetRemovalOk(const Mesh& mesh, absl::Span<const Mesh::FaceHandle> faces,
                        Mesh::VertexHandle emptied) {
  for (const Mesh::FaceHandle f : faces) {
    if (!f.is_valid() || mesh.status(f).deleted()) return false;
  }
  auto removed = [&faces](Mesh::FaceHandle f) {
    return std::find(faces.begin(), faces.end(), f) != faces.end();
  };
  for (const Mesh::FaceHandle f : faces) {
    for (auto x : mesh.fv_range(f)) {
      if (x == emptied) continue;
      // Around x, count the runs of kept faces: a kept face that follows a gap (a boundary
      // half-edge or a removed face) starts one. Exactly one run: one fan, not isolated.
      int runs = 0;
      bool any_gap = false;
      bool previous_kept = false;
      bool first = true;
      bool first_kept = false;
      for (auto h : mesh.voh_range(x)) {
        const Mesh::FaceHandle g = mesh.face_handle(h);
        const bool kept = g.is_valid() && !removed(g);
        any_gap |= !kept;
        if (first) {
          first_kept = kept;
          first = false;
        } else if (kept && !previous_kept) {
          ++runs;
        }
        previous_kept = kept;
      }
      // The walk is cyclic: the first half-edge starts a run if the last one was a gap.
      if (first_kept && !previous_kept) ++runs;
      if (!any_gap || runs != 1) return false;
    }
  }
  return true;
}

bool CutOutBorderVertex(Mesh& mesh, Mesh::VertexHandle v,
                        std::vector<Mesh::VertexHandle>* removed_vertices,
                        std::vector<Mesh::VertexHandle>* touched_vertices) {
  if (mesh.status(v).deleted() || !mesh.is_boundary(v)) return false;
  std::vector<Mesh::FaceHandle> fan;
  for (auto h : mesh.voh_range(v)) {
    const Mesh::FaceHandle f = mesh.face_handle(h);
    if (!f.is_valid()) continue;
    fan.push_back(f);
    // The side of the face across from v must stay: the ring around v then still connects
    // what v's faces connected.
    const auto across = mesh.next_halfedge_handle(h);
    if (mesh.is_boundary(mesh.opposite_halfedge_handle(across))) return false;
  }
  if (fan.empty() || !IsFaceSetRemovalOk(mesh, fan, v)) return false;
  std::vector<Mesh::VertexHandle> ring;
  for (auto u : mesh.vv_range(v)) ring.push_back(u);
  for (const Mesh::FaceHandle f : fan) RemoveTriangle(mesh, f, removed_vertices);
  if (touched_vertices) touched_vertices->insert(touched_vertices->end(), ring.begin(), ring.end());
  return true;
}

BridgeCuttingResult CutInactiveBridges(
    Mesh& mesh, const std::function<bool(Mesh::VertexHandle)>& inactive) {
  BridgeCuttingResult result;
  BoundaryLoops loops(mesh);
  if (loops.count() < 2) return result;  // A closed mesh or a single border: nothing to join.
  const size_t num_edges = mesh.n_edges();  // Cuts only delete edges.
  for (size_t i = 0; i < num_edges; ++i) {
    const Mesh::EdgeHandle e(static_cast<int>(i));
    if (mesh.status(e).deleted() || mesh.is_boundary(e)) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    const Mesh::VertexHandle a = mesh.from_vertex_handle(h);
    const Mesh::VertexHandle b = mesh.to_vertex_handle(h);
    const int loop_a = loops.Of(a);
    const int loop_b = loops.Of(b);
    if (loop_a < 0 || loop_b < 0 || loop_a == loop_b) continue;
    const Mesh::FaceHandle f1 = mesh.face_handle(h);
    const Mesh::FaceHandle f2 = mesh.opposite_face_handle(h);
    bool dead = true;
    for (const Mesh::FaceHandle f : {f1, f2}) {
      for (auto v : mesh.fv_range(f)) dead &= inactive(v);
    }
    const std::array<Mesh::FaceHandle, 2> bridge = {f1, f2};
    if (!dead || !IsFaceSetRemovalOk(mesh, bridge, Mesh::VertexHandle())) continue;
    std::array<Mesh::VertexHandle, 4> corners = {a, b, mesh.opposite_vh(h),
                                                 mesh.opposite_he_opposite_vh(h)};
    // The first removal leaves a pinch that the second one resolves; OpenMesh's half-edge
    // structure represents the pinch in between.
    RemoveTriangle(mesh, f1, nullptr);
    RemoveTriangle(mesh, f2, nullptr);
    loops.Join(loop_a, loop_b);
    ++result.cut_bridges;
    result.touched_vertices.insert(result.touched_vertices.end(), corners.begin(), corners.end());
  }
  return result;
}

}  // namespace neuralmesh
