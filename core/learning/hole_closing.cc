#include "core/learning/hole_closing.h"

#include <cmath>
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

// 4 sqrt(3) area / (sum of squared edge lengths): 1 when equilateral, 0 when degenerate.
double Quality(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const double squared_lengths = (p1 - p0).sqrnorm() + (p2 - p1).sqrnorm() + (p0 - p2).sqrnorm();
  if (squared_lengths <= 0) return 0;
  return 4 * std::sqrt(3.0) * Area(p0, p1, p2) / squared_lengths;
}

// Fills `loop` ear by ear; on failure removes the faces it added and returns 0, else the
// number of faces added.
size_t FillLoop(Mesh& mesh, VertexLoop loop, double max_area) {
  std::vector<Mesh::FaceHandle> added;
  auto undo = [&](const VertexLoop& original) {
    for (auto it = added.rbegin(); it != added.rend(); ++it) {
      mesh.delete_face(*it, /*_delete_isolated_vertices=*/false);
    }
    for (auto vh : original) mesh.adjust_outgoing_halfedge(vh);
    return size_t{0};
  };
  const VertexLoop original = loop;
  while (loop.size() >= 3) {
    const size_t n = loop.size();
    int best = -1;
    double best_quality = -1;
    for (size_t i = 0; i < n; ++i) {
      const auto a = loop[(i + n - 1) % n];
      const auto b = loop[i];
      const auto c = loop[(i + 1) % n];
      const Vec3& pa = mesh.point(a);
      const Vec3& pb = mesh.point(b);
      const Vec3& pc = mesh.point(c);
      if (Area(pa, pb, pc) > max_area) continue;
      // b becomes interior without gaining an edge; on the last triangle all three do.
      if (mesh.valence(b) < 3) continue;
      if (n == 3) {
        if (mesh.valence(a) < 3 || mesh.valence(c) < 3) continue;
      } else if (mesh.find_halfedge(a, c).is_valid()) {
        continue;  // The new edge a-c would double an existing one.
      }
      const double quality = Quality(pa, pb, pc);
      if (quality > best_quality) {
        best_quality = quality;
        best = static_cast<int>(i);
      }
      if (n == 3) break;  // Every corner gives the same triangle.
    }
    if (best < 0) return undo(original);
    const size_t i = static_cast<size_t>(best);
    const Mesh::FaceHandle fh = mesh.add_face(loop[(i + n - 1) % n], loop[i], loop[(i + 1) % n]);
    if (!fh.is_valid()) return undo(original);
    added.push_back(fh);
    if (n == 3) break;
    loop.erase(loop.begin() + static_cast<std::ptrdiff_t>(i));
  }
  return added.size();
}

}  // namespace

absl::Status HoleClosingOptions::Validate() const {
  if (!std::isfinite(alpha_r) || alpha_r <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("alpha_r (Eq. 2) must be finite and positive, got ", alpha_r));
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
  if (!(max_area > 0)) return result;
  for (const VertexLoop& loop : loops) {
    const size_t added = FillLoop(mesh, loop, max_area);
    if (added == 0) continue;
    ++result.closed_holes;
    result.added_faces += added;
  }
  return result;
}

}  // namespace neuralmesh
