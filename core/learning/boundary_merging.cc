#include "core/learning/boundary_merging.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/learning/boundary_loops.h"
#include "core/learning/triangle_removal.h"

namespace neuralmesh {
namespace {

using Triangle = std::array<Mesh::VertexHandle, 3>;

// A boundary loop with its bounding box.
struct BoundaryLoop {
  VertexLoop vertices;  // In half-edge order (boundary_loops.h).
  Vec3 box_min;
  Vec3 box_max;
};

std::vector<BoundaryLoop> LoopsWithBoxes(const Mesh& mesh) {
  std::vector<BoundaryLoop> loops;
  for (VertexLoop& vertices : CollectBoundaryLoops(mesh)) {
    BoundaryLoop loop;
    loop.box_min = Vec3(std::numeric_limits<double>::infinity());
    loop.box_max = Vec3(-std::numeric_limits<double>::infinity());
    for (auto vh : vertices) {
      loop.box_min.minimize(mesh.point(vh));
      loop.box_max.maximize(mesh.point(vh));
    }
    loop.vertices = std::move(vertices);
    loops.push_back(std::move(loop));
  }
  return loops;
}

// A lower bound on the Hausdorff distance of two point sets from their bounding boxes: the
// point of A with the largest x is at least max_x(A) - max_x(B) away from every point of B,
// and likewise for each side and axis in both directions.
double HausdorffLowerBound(const BoundaryLoop& a, const BoundaryLoop& b) {
  double bound = 0;
  for (int axis = 0; axis < 3; ++axis) {
    bound = std::max(bound, std::abs(a.box_max[axis] - b.box_max[axis]));
    bound = std::max(bound, std::abs(a.box_min[axis] - b.box_min[axis]));
  }
  return bound;
}

// The squared directed Hausdorff distance max_p min_q |p - q|^2 from `from` to `to`, or
// nullopt as soon as it reaches `limit_squared`. The inner search stops once a point of `to`
// is closer than the running maximum, since that p can no longer raise it.
std::optional<double> DirectedHausdorffSquared(const Mesh& mesh, const VertexLoop& from,
                                               const VertexLoop& to, double limit_squared) {
  double running_max = 0;
  for (auto p : from) {
    const Vec3& pp = mesh.point(p);
    double nearest = std::numeric_limits<double>::infinity();
    for (auto q : to) {
      nearest = std::min(nearest, (pp - mesh.point(q)).sqrnorm());
      if (nearest <= running_max) break;
    }
    running_max = std::max(running_max, nearest);
    if (running_max >= limit_squared) return std::nullopt;
  }
  return running_max;
}

// The symmetric Hausdorff distance of the vertex sets, or nullopt when it is >= `limit`.
std::optional<double> HausdorffBelow(const Mesh& mesh, const VertexLoop& a, const VertexLoop& b,
                                     double limit) {
  const double limit_squared = limit * limit;
  const auto ab = DirectedHausdorffSquared(mesh, a, b, limit_squared);
  if (!ab) return std::nullopt;
  const auto ba = DirectedHausdorffSquared(mesh, b, a, limit_squared);
  if (!ba) return std::nullopt;
  return std::sqrt(std::max(*ab, *ba));
}

// 4 sqrt(3) area / (sum of squared edge lengths): 1 when equilateral, 0 when degenerate.
double TriangleQuality(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const double squared_lengths = (p1 - p0).sqrnorm() + (p2 - p1).sqrnorm() + (p0 - p2).sqrnorm();
  if (squared_lengths <= 0) return 0;
  return 2 * std::sqrt(3.0) * OpenMesh::cross(p1 - p0, p2 - p0).norm() / squared_lengths;
}

// The cost of a strip triangle: 1 / quality, so 1 for an equilateral triangle, and a sliver
// costs more than any number of good triangles can save.
double TriangleCost(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  return 1.0 / std::max(TriangleQuality(p0, p1, p2), 1e-9);
}

constexpr double kNoStrip = std::numeric_limits<double>::infinity();

// Plans the strip between loop `a` (boundary half-edges a[i] -> a[i+1]) and loop `b`
// (b[j] -> b[j+1]). Returns the faces in the order they must be added, or nullopt when no
// legal strip of this kind exists. O(|a| |b| + sum of the valences of a).
//
// The walk runs over a[0..n] forward and c[0..m] = b backward, both rotated to start at the
// closest pair of vertices that is not already an edge. State (i, k) means the current cross
// edge joins a[i mod n] and c[k mod m]; the walk goes from (0, 0) to (n, m), which is the
// first cross edge again. A state is allowed when its pair is not an edge of the mesh and the
// walk cannot have joined that pair before. Since i and k never decrease, a pair can repeat
// only where the walk wraps: (n, k) against (0, k) and (i, m) against (i, 0). We rule that
// out by deciding the first move: if it advances on A, no (0, k > 0) is visited, so only
// (i < n, m) and (n, 0) are forbidden (B is consumed last); symmetrically if it advances on B.
// For each choice, a table of the least cost from every state to (n, m) (infinite where it
// cannot be reached) gives the best walk of that kind; the cheaper of the two is taken.
std::optional<std::vector<Triangle>> PlanStrip(const Mesh& mesh, const VertexLoop& a,
                                               const VertexLoop& b) {
  const int n = static_cast<int>(a.size());
  const int m = static_cast<int>(b.size());

  // linked[i * m + j]: a[i] and b[j] are already joined by an edge.
  std::unordered_map<int, int> index_in_b;
  for (int j = 0; j < m; ++j) index_in_b.emplace(b[j].idx(), j);
  std::vector<char> linked(static_cast<size_t>(n) * m, 0);
  for (int i = 0; i < n; ++i) {
    for (auto neighbour : mesh.vv_range(a[i])) {
      const auto it = index_in_b.find(neighbour.idx());
      if (it != index_in_b.end()) linked[static_cast<size_t>(i) * m + it->second] = 1;
    }
  }

  // The tiling starts at the two closest vertices, one on each loop (Section 2.3), that are
  // not already joined by an edge.
  int start_a = -1;
  int start_b = -1;
  double closest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      if (linked[static_cast<size_t>(i) * m + j]) continue;
      const double d = (mesh.point(a[i]) - mesh.point(b[j])).sqrnorm();
      if (d < closest) {
        closest = d;
        start_a = i;
        start_b = j;
      }
    }
  }
  if (start_a < 0) return std::nullopt;
  auto walk_a = [&](int i) { return (start_a + i) % n; };          // Index into a.
  auto walk_c = [&](int k) { return (start_b + m - k % m) % m; };  // Index into b.
  auto vertex_a = [&](int i) { return a[walk_a(i)]; };
  auto vertex_c = [&](int k) { return b[walk_c(k)]; };

  const size_t width = static_cast<size_t>(m) + 1;
  auto point = [&](Mesh::VertexHandle vh) -> const Vec3& { return mesh.point(vh); };
  auto cost_a = [&](int i, int k) {  // The triangle that advances on A from (i, k).
    return TriangleCost(point(vertex_a(i)), point(vertex_a(i + 1)), point(vertex_c(k)));
  };
  auto cost_b = [&](int i, int k) {  // The triangle that advances on B from (i, k).
    return TriangleCost(point(vertex_c(k + 1)), point(vertex_c(k)), point(vertex_a(i)));
  };
  // For one choice of the first move: the least total cost of a walk from each state to
  // (n, m), infinite where (n, m) cannot be reached, and whether that walk advances on B next.
  struct Walks {
    std::vector<double> to_end;
    std::vector<char> advance_b;
  };
  auto best_walks = [&](bool a_first) {
    auto allowed = [&](int i, int k) {
      if ((i == 0 && k == 0) || (i == n && k == m)) return true;
      if (linked[static_cast<size_t>(walk_a(i)) * m + walk_c(k)]) return false;
      if (a_first) return !(i == 0 || (k == m && i < n) || (i == n && k == 0));
      return !(k == 0 || (i == n && k < m) || (k == m && i == 0));
    };
    const size_t states = (static_cast<size_t>(n) + 1) * width;
    Walks walks{std::vector<double>(states, kNoStrip), std::vector<char>(states, 0)};
    for (int i = n; i >= 0; --i) {
      for (int k = m; k >= 0; --k) {
        if (!allowed(i, k)) continue;
        double& best = walks.to_end[i * width + k];
        if (i == n && k == m) {
          best = 0;
          continue;
        }
        if (i < n && walks.to_end[(i + 1) * width + k] < kNoStrip) {
          best = cost_a(i, k) + walks.to_end[(i + 1) * width + k];
        }
        if (k < m && walks.to_end[i * width + k + 1] < kNoStrip) {
          const double via_b = cost_b(i, k) + walks.to_end[i * width + k + 1];
          if (via_b < best) {
            best = via_b;
            walks.advance_b[i * width + k] = 1;
          }
        }
      }
    }
    return walks;
  };

  const Walks a_first = best_walks(true);
  const Walks b_first = best_walks(false);
  if (a_first.to_end[0] >= kNoStrip && b_first.to_end[0] >= kNoStrip) return std::nullopt;
  const Walks& walks = a_first.to_end[0] <= b_first.to_end[0] ? a_first : b_first;

  // Follow the cheapest walk.
  std::vector<Triangle> strip;
  strip.reserve(n + m);
  int i = 0;
  int k = 0;
  while (i < n || k < m) {
    if (walks.advance_b[i * width + k]) {
      strip.push_back({vertex_c(k + 1), vertex_c(k), vertex_a(i)});
      ++k;
    } else {
      strip.push_back({vertex_a(i), vertex_a(i + 1), vertex_c(k)});
      ++i;
    }
  }
  return strip;
}

// Adds the planned faces; if OpenMesh refuses one, deletes those already added (their new
// edges go with them, and no vertex can become isolated: each keeps its old faces) and
// returns false, leaving the mesh as it was up to deleted-marked elements.
bool AddStrip(Mesh& mesh, const std::vector<Triangle>& strip, const VertexLoop& a,
              const VertexLoop& b) {
  std::vector<Mesh::FaceHandle> added;
  added.reserve(strip.size());
  for (const Triangle& t : strip) {
    const Mesh::FaceHandle fh = mesh.add_face(t[0], t[1], t[2]);
    if (fh.is_valid()) {
      added.push_back(fh);
      continue;
    }
    for (auto it = added.rbegin(); it != added.rend(); ++it) {
      mesh.delete_face(*it, /*_delete_isolated_vertices=*/false);
    }
    for (auto vh : a) mesh.adjust_outgoing_halfedge(vh);
    for (auto vh : b) mesh.adjust_outgoing_halfedge(vh);
    return false;
  }
  return true;
}

struct CandidatePair {
  double distance;
  size_t first;
  size_t second;
};

}  // namespace

absl::Status BoundaryMergingOptions::Validate() const {
  if (!std::isfinite(alpha_m) || alpha_m < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("alpha_m (Eq. 3) must be finite and non-negative, got ", alpha_m));
  }
  if (min_loop_vertices < 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_loop_vertices must be at least 3, got ", min_loop_vertices));
  }
  if (close_small_holes || zip_border_slits || close_bridged_holes) {
    return hole_closing.Validate();
  }
  return absl::OkStatus();
}

BoundaryMergingResult MergeCloseBoundaries(Mesh& mesh, const BoundaryMergingOptions& options,
                                           double mean_area) {
  return MergeCloseBoundaries(mesh, options, mean_area, {});
}

BoundaryMergingResult MergeCloseBoundaries(Mesh& mesh, const BoundaryMergingOptions& options,
                                           double mean_area,
                                           absl::Span<const Mesh::VertexHandle> growing_vertices) {
  BoundaryMergingResult result;
  if (options.close_small_holes) {
    result.closed = CloseSmallHoles(mesh, options.hole_closing, mean_area);
  }
  if (options.close_bridged_holes) {
    result.bridged = CloseBridgedHoles(mesh, options.hole_closing, mean_area);
  }
  if (options.zip_border_slits) {
    result.zipped = ZipBorderSlits(mesh, options.hole_closing, mean_area);
  }
  const std::vector<BoundaryLoop> loops = LoopsWithBoxes(mesh);
  if (loops.size() < 2) return result;
  if (mean_area <= 0) mean_area = MeanTriangleArea(mesh);
  const double limit = options.alpha_m * std::sqrt(mean_area);
  if (!(limit > 0)) return result;

  // Loops that Step 4 is still growing take no part.
  std::vector<bool> growing(loops.size(), false);
  if (!growing_vertices.empty()) {
    std::unordered_map<int, size_t> loop_of;
    for (size_t x = 0; x < loops.size(); ++x) {
      for (auto vh : loops[x].vertices) loop_of.emplace(vh.idx(), x);
    }
    for (auto vh : growing_vertices) {
      if (!vh.is_valid() || vh.idx() >= static_cast<int>(mesh.n_vertices()) ||
          mesh.status(vh).deleted()) {
        continue;
      }
      const auto it = loop_of.find(vh.idx());
      if (it != loop_of.end()) growing[it->second] = true;
    }
  }

  // Neither loops that Step 4 is still growing nor loops below min_loop_vertices take part.
  std::vector<bool> excluded = growing;
  for (size_t x = 0; x < loops.size(); ++x) {
    if (loops[x].vertices.size() < options.min_loop_vertices) excluded[x] = true;
  }
  std::vector<CandidatePair> candidates;
  for (size_t x = 0; x < loops.size(); ++x) {
    if (excluded[x]) continue;
    for (size_t y = x + 1; y < loops.size(); ++y) {
      if (excluded[y]) continue;
      if (HausdorffLowerBound(loops[x], loops[y]) >= limit) continue;
      const auto distance = HausdorffBelow(mesh, loops[x].vertices, loops[y].vertices, limit);
      if (distance) candidates.push_back({*distance, x, y});
    }
  }
  std::sort(
      candidates.begin(), candidates.end(), [](const CandidatePair& l, const CandidatePair& r) {
        return std::tie(l.distance, l.first, l.second) < std::tie(r.distance, r.first, r.second);
      });

  // Merging two loops only touches their own boundary half-edges and edges between their
  // vertices, so the other loops collected above stay valid.
  std::vector<bool> merged(loops.size(), false);
  for (const CandidatePair& pair : candidates) {
    if (merged[pair.first] || merged[pair.second]) continue;
    const VertexLoop& a = loops[pair.first].vertices;
    const VertexLoop& b = loops[pair.second].vertices;
    const auto strip = PlanStrip(mesh, a, b);
    if (!strip || !AddStrip(mesh, *strip, a, b)) continue;
    merged[pair.first] = merged[pair.second] = true;
    result.sewn_vertices.insert(result.sewn_vertices.end(), a.begin(), a.end());
    result.sewn_vertices.insert(result.sewn_vertices.end(), b.begin(), b.end());
    ++result.merges;
    result.added_faces += strip->size();
  }
  return result;
}

}  // namespace neuralmesh
