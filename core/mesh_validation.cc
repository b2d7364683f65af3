#include "core/mesh_validation.h"

#include <algorithm>
#include <vector>

#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

absl::Status Fail(const std::string& what) { return absl::InternalError(what); }

}  // namespace

absl::Status ValidateMesh(const Mesh& mesh) {
  for (auto fh : mesh.all_faces()) {
    if (mesh.status(fh).deleted()) continue;
    const auto h0 = mesh.halfedge_handle(fh);
    if (!h0.is_valid() || mesh.status(h0).deleted()) {
      return Fail(absl::StrCat("face ", fh.idx(), " has no live half-edge"));
    }
    auto h = h0;
    int n = 0;
    do {
      if (mesh.face_handle(h) != fh) {
        return Fail(absl::StrCat("face ", fh.idx(), ": half-edge ", h.idx(), " points elsewhere"));
      }
      if (mesh.status(mesh.to_vertex_handle(h)).deleted()) {
        return Fail(absl::StrCat("face ", fh.idx(), " uses a deleted vertex"));
      }
      h = mesh.next_halfedge_handle(h);
      if (++n > 3) break;
    } while (h != h0);
    if (n != 3) return Fail(absl::StrCat("face ", fh.idx(), " is not a triangle"));
    const auto a = mesh.to_vertex_handle(h0);
    const auto b = mesh.to_vertex_handle(mesh.next_halfedge_handle(h0));
    const auto c = mesh.from_vertex_handle(h0);
    if (a == b || b == c || a == c) {
      return Fail(absl::StrCat("face ", fh.idx(), " repeats a vertex"));
    }
  }

  for (auto heh : mesh.all_halfedges()) {
    if (mesh.status(heh).deleted()) continue;
    const auto opp = mesh.opposite_halfedge_handle(heh);
    if (mesh.status(opp).deleted() || mesh.status(mesh.edge_handle(heh)).deleted()) {
      return Fail(absl::StrCat("half-edge ", heh.idx(), " has a deleted twin or edge"));
    }
    const auto next = mesh.next_halfedge_handle(heh);
    if (!next.is_valid() || mesh.status(next).deleted() || mesh.prev_halfedge_handle(next) != heh) {
      return Fail(absl::StrCat("half-edge ", heh.idx(), ": next/prev links disagree"));
    }
    if (mesh.from_vertex_handle(next) != mesh.to_vertex_handle(heh)) {
      return Fail(absl::StrCat("half-edge ", heh.idx(), " and its next do not meet"));
    }
    if (mesh.is_boundary(heh) && mesh.is_boundary(opp)) {
      return Fail(absl::StrCat("edge ", mesh.edge_handle(heh).idx(), " has no face (dangling)"));
    }
    const auto fh = mesh.face_handle(heh);
    if (fh.is_valid() && mesh.status(fh).deleted()) {
      return Fail(absl::StrCat("half-edge ", heh.idx(), " borders a deleted face"));
    }
  }

  std::vector<int> neighbours;
  for (auto vh : mesh.all_vertices()) {
    if (mesh.status(vh).deleted()) continue;
    const auto out = mesh.halfedge_handle(vh);
    if (!out.is_valid()) return Fail(absl::StrCat("vertex ", vh.idx(), " is isolated"));
    if (mesh.status(out).deleted() || mesh.from_vertex_handle(out) != vh) {
      return Fail(absl::StrCat("vertex ", vh.idx(), " has a broken outgoing half-edge"));
    }
    // Walk the fan: next outgoing = next(opposite(h)).
    int valence = 0;
    int boundary_gaps = 0;
    neighbours.clear();
    auto h = out;
    do {
      if (mesh.from_vertex_handle(h) != vh) {
        return Fail(absl::StrCat("vertex ", vh.idx(), ": fan walk leaves the vertex"));
      }
      if (mesh.is_boundary(h)) ++boundary_gaps;
      neighbours.push_back(mesh.to_vertex_handle(h).idx());
      h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
      if (++valence > 100000) return Fail(absl::StrCat("vertex ", vh.idx(), ": fan never closes"));
    } while (h != out);
    if (boundary_gaps > 1) {
      return Fail(absl::StrCat("vertex ", vh.idx(), " is non-manifold (", boundary_gaps,
                               " boundary gaps)"));
    }
    if (boundary_gaps == 1 && !mesh.is_boundary(out)) {
      return Fail(absl::StrCat("boundary vertex ", vh.idx(),
                               " does not store its boundary half-edge"));
    }
    if (valence < (boundary_gaps ? 2 : 3)) {
      return Fail(absl::StrCat("vertex ", vh.idx(), " has valence ", valence));
    }
    std::sort(neighbours.begin(), neighbours.end());
    if (std::adjacent_find(neighbours.begin(), neighbours.end()) != neighbours.end()) {
      return Fail(absl::StrCat("vertex ", vh.idx(), " has two edges to the same neighbour"));
    }
  }
  return absl::OkStatus();
}

}  // namespace neuralmesh
