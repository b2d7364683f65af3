#include "core/learning/hole_closing.h"

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/learning/triangle_removal.h"

namespace neuralmesh {
namespace {

using VertexLoop = std::vector<Mesh::VertexHandle>;

// The boundary loops with at most `max_vertices` vertices, each as the from-vertices of its
// boundary half-edges in half-edge order (loop[i] -> loop[i + 1] is a boundary half-edge).
std::vector<VertexLoop> CollectSmallLoops(const Mesh& mesh, size_t max_vertices) {
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
    if (loop.size() <= max_vertices) loops.push_back(std::move(loop));
  }
  return loops;
}

double Area(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  return 0.5 * OpenMesh::cross(p1 - p0, p2 - p0).norm();
}

// The triangulation of a loop chosen by FillLoop: for every interval [i, j] of the loop
// (i < j), the apex m of the triangle (i, m, j) in its best triangulation, or -1 when none
// satisfies the constraints.
class LoopTriangulation {
 public:
  LoopTriangulation(const Mesh& mesh, const VertexLoop& loop, double max_area, double max_edge)
      : mesh_(mesh),
        loop_(loop),
        n_(loop.size()),
        max_area_(max_area),
        max_edge2_(max_edge * max_edge),
        cost_(n_ * n_, kInfeasible),
        apex_(n_ * n_, -1) {}

  // Minimum total length of the new edges over the admissible triangulations (kInfeasible
  // when there is none). Interval DP: O(n^3) at worst; intervals whose chord is too long or
  // already an edge are skipped at once, so a loop around a real hole costs about O(n k^2),
  // k the number of loop vertices within max_edge of a vertex.
  double Solve() {
    for (size_t span = 2; span < n_; ++span) {
      for (size_t i = 0; i + span < n_; ++i) {
        const size_t j = i + span;
        const bool outer = (i == 0 && j == n_ - 1);  // The side loop[n-1] -> loop[0].
        double chord = 0;
        if (!outer && !ChordAllowed(i, j, &chord)) continue;
        for (size_t m = i + 1; m < j; ++m) {
          const double left = (m == i + 1) ? 0 : cost_[i * n_ + m];
          const double right = (j == m + 1) ? 0 : cost_[m * n_ + j];
          if (left >= kInfeasible || right >= kInfeasible) continue;
          if (!TriangleAllowed(i, m, j)) continue;
          const double total = left + right + chord;
          if (total < cost_[i * n_ + j]) {
            cost_[i * n_ + j] = total;
            apex_[i * n_ + j] = static_cast<int>(m);
          }
        }
      }
    }
    return n_ == 2 ? kInfeasible : cost_[n_ - 1];
  }

  // The triangles of the solution, children before parents: each added face then shares its
  // two inner sides with the current hole border.
  void Triangles(size_t i, size_t j, std::vector<std::array<size_t, 3>>& out) const {
    if (j <= i + 1) return;
    const size_t m = static_cast<size_t>(apex_[i * n_ + j]);
    Triangles(i, m, out);
    Triangles(m, j, out);
    out.push_back({i, m, j});
  }

  static constexpr double kInfeasible = std::numeric_limits<double>::infinity();

 private:
  // A new edge loop[i] - loop[j]: short enough, and not already an edge of the mesh (a double
  // edge would make the mesh non-manifold).
  bool ChordAllowed(size_t i, size_t j, double* length) const {
    const double l2 = (mesh_.point(loop_[i]) - mesh_.point(loop_[j])).sqrnorm();
    if (l2 > max_edge2_) return false;
    if (mesh_.find_halfedge(loop_[i], loop_[j]).is_valid()) return false;
    *length = std::sqrt(l2);
    return true;
  }

  // Step 4 would keep the triangle, and an ear tip (a vertex that gets no new edge) keeps a
  // legal valence once interior: the middle of an ear, or all three corners of a loop of 3.
  bool TriangleAllowed(size_t i, size_t m, size_t j) const {
    if (Area(mesh_.point(loop_[i]), mesh_.point(loop_[m]), mesh_.point(loop_[j])) > max_area_) {
      return false;
    }
    if (n_ == 3) {
      for (const auto& v : loop_) {
        if (mesh_.valence(v) < 3) return false;
      }
      return true;
    }
    if (m == i + 1 && j == m + 1 && mesh_.valence(loop_[m]) < 3) return false;
    // The ears that wrap around the outer side: loop[0] between loop[n-1] and loop[1], and
    // loop[n-1] between loop[n-2] and loop[0].
    if (i == 0 && m == 1 && j == n_ - 1 && mesh_.valence(loop_[0]) < 3) return false;
    if (i == 0 && m == n_ - 2 && j == n_ - 1 && mesh_.valence(loop_[n_ - 1]) < 3) return false;
    return true;
  }

  const Mesh& mesh_;
  const VertexLoop& loop_;
  const size_t n_;
  const double max_area_;
  const double max_edge2_;
  std::vector<double> cost_;
  std::vector<int> apex_;
};

// Fills `loop` with its admissible triangulation of least total new-edge length; returns the
// number of faces added, 0 when there is none (the mesh is then unchanged).
size_t FillLoop(Mesh& mesh, const VertexLoop& loop, double max_area, double max_edge) {
  if (loop.size() < 3) return 0;
  LoopTriangulation triangulation(mesh, loop, max_area, max_edge);
  if (triangulation.Solve() >= LoopTriangulation::kInfeasible) return 0;
  std::vector<std::array<size_t, 3>> triangles;
  triangulation.Triangles(0, loop.size() - 1, triangles);
  std::vector<Mesh::FaceHandle> added;
  for (const auto& t : triangles) {
    // Loop order is the order of the boundary half-edges, so (i, m, j) continues the
    // orientation of the faces around the hole.
    const Mesh::FaceHandle fh = mesh.add_face(loop[t[0]], loop[t[1]], loop[t[2]]);
    if (!fh.is_valid()) {
      for (auto it = added.rbegin(); it != added.rend(); ++it) {
        mesh.delete_face(*it, /*_delete_isolated_vertices=*/false);
      }
      for (auto vh : loop) mesh.adjust_outgoing_halfedge(vh);
      return 0;
    }
    added.push_back(fh);
  }
  return added.size();
}

}  // namespace

absl::Status HoleClosingOptions::Validate() const {
  if (!std::isfinite(alpha_r) || alpha_r <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("alpha_r (Eq. 2) must be finite and positive, got ", alpha_r));
  }
  if (!std::isfinite(alpha_m) || alpha_m <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("alpha_m (Eq. 3) must be finite and positive, got ", alpha_m));
  }
  if (max_loop_vertices < 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_loop_vertices must be at least 3, got ", max_loop_vertices));
  }
  return absl::OkStatus();
}

HoleClosingResult CloseSmallHoles(Mesh& mesh, const HoleClosingOptions& options, double mean_area) {
  HoleClosingResult result;
  const std::vector<VertexLoop> loops =
      CollectSmallLoops(mesh, static_cast<size_t>(options.max_loop_vertices));
  if (loops.empty()) return result;
  if (mean_area <= 0) mean_area = MeanTriangleArea(mesh);
  const double max_area = options.alpha_r * mean_area;
  const double max_edge = options.alpha_m * std::sqrt(mean_area);
  if (!(max_area > 0)) return result;
  for (const VertexLoop& loop : loops) {
    const size_t added = FillLoop(mesh, loop, max_area, max_edge);
    if (added == 0) continue;
    ++result.closed_holes;
    result.added_faces += added;
  }
  return result;
}

}  // namespace neuralmesh
