#include "core/learning/half_edge_collapse.h"

#include <cmath>
#include <limits>

namespace neuralmesh {
namespace {

int IdealValence(const Mesh& mesh, Mesh::VertexHandle v) { return mesh.is_boundary(v) ? 4 : 6; }

// Minimum valence a vertex may keep: a boundary vertex needs 2 edges, an inner one 3.
int MinValence(const Mesh& mesh, Mesh::VertexHandle v) { return mesh.is_boundary(v) ? 2 : 3; }

}  // namespace

double CollapseIrregularity(const Mesh& mesh, Mesh::HalfedgeHandle h) {
  const auto v = mesh.from_vertex_handle(h);
  const auto u = mesh.to_vertex_handle(h);
  const int a = static_cast<int>(mesh.valence(v));
  const int b = static_cast<int>(mesh.valence(u));
  double sum = 0;
  int terms = 1;
  // u inherits v's neighbours except itself and the one or two opposite vertices it already has.
  const int shared = (mesh.is_boundary(h) || mesh.is_boundary(mesh.opposite_halfedge_handle(h)))
                         ? 1 : 2;
  const double du = (a + b - 2 - shared) - IdealValence(mesh, u);
  sum += du * du;
  for (auto side : {h, mesh.opposite_halfedge_handle(h)}) {
    if (mesh.is_boundary(side)) continue;
    const auto w = mesh.to_vertex_handle(mesh.next_halfedge_handle(side));
    const double dw = (static_cast<int>(mesh.valence(w)) - 1) - IdealValence(mesh, w);
    sum += dw * dw;
    ++terms;
  }
  return std::sqrt(sum) / terms;
}

bool IsCollapseLegal(Mesh& mesh, Mesh::HalfedgeHandle h, size_t live_vertices) {
  if (live_vertices <= 4) return false;
  const auto v = mesh.from_vertex_handle(h);
  const auto u = mesh.to_vertex_handle(h);
  const bool boundary_edge =
      mesh.is_boundary(h) || mesh.is_boundary(mesh.opposite_halfedge_handle(h));
  // A boundary vertex may only slide along its border.
  if (mesh.is_boundary(v) && !boundary_edge) return false;
  if (!mesh.is_collapse_ok(h)) return false;
  // Valences after the collapse.
  const int a = static_cast<int>(mesh.valence(v));
  const int b = static_cast<int>(mesh.valence(u));
  const int shared = boundary_edge ? 1 : 2;
  if (a + b - 2 - shared < MinValence(mesh, u)) return false;
  if (a + b - 2 - shared > 2 * IdealValence(mesh, u)) return false;  // No hubs (header).
  for (auto side : {h, mesh.opposite_halfedge_handle(h)}) {
    if (mesh.is_boundary(side)) continue;
    const auto w = mesh.to_vertex_handle(mesh.next_halfedge_handle(side));
    if (static_cast<int>(mesh.valence(w)) - 1 < MinValence(mesh, w)) return false;
  }
  return true;
}

Mesh::HalfedgeHandle BestCollapse(Mesh& mesh, Mesh::VertexHandle v, size_t live_vertices) {
  Mesh::HalfedgeHandle best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (auto h : mesh.voh_range(v)) {
    if (!IsCollapseLegal(mesh, h, live_vertices)) continue;
    const double cost = CollapseIrregularity(mesh, h);
    if (cost < best_cost) {
      best_cost = cost;
      best = h;
    }
  }
  return best;
}

}  // namespace neuralmesh
