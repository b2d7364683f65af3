#include "core/learning/hole_closing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/learning/boundary_loops.h"
#include "core/learning/inactive_face_removal.h"
#include "core/learning/triangle_removal.h"

namespace neuralmesh {
namespace {

// Slits (ZipBorderSlits): the chains considered, and the work bounds per call.
constexpr size_t kMaxSlitChainEdges = 48;
constexpr double kMinSlitPathToChord = 3;
constexpr size_t kMaxSlitCandidatesPerLoop = 8;
constexpr size_t kMaxSlitZipsPerCall = 64;

// The boundary loops with at most `max_vertices` vertices (boundary_loops.h), without the one
// of greatest perimeter when `keep_longest_open`.
std::vector<VertexLoop> CollectLoops(const Mesh& mesh, size_t max_vertices,
                                     bool keep_longest_open) {
  std::vector<VertexLoop> loops = CollectBoundaryLoops(mesh);
  if (keep_longest_open && !loops.empty()) loops.erase(loops.begin() + LongestLoop(mesh, loops));
  loops.erase(std::remove_if(loops.begin(), loops.end(),
                             [max_vertices](const VertexLoop& loop) {
                               return loop.size() > max_vertices;
                             }),
              loops.end());
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
  // `closed`: the side loop[n-1] -> loop[0] is a boundary half-edge (a whole loop is filled).
  // Otherwise `loop` is a chain of boundary half-edges and that side is a new edge, which
  // becomes a boundary edge (a slit is zipped).
  LoopTriangulation(const Mesh& mesh, const VertexLoop& loop, double max_area, double max_edge,
                    bool closed = true)
      : mesh_(mesh),
        closed_(closed),
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
        const bool outer = closed_ && i == 0 && j == n_ - 1;  // loop[n-1] -> loop[0].
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
    if (n_ == 3 && closed_) {
      for (const auto& v : loop_) {
        if (mesh_.valence(v) < 3) return false;
      }
      return true;
    }
    if (m == i + 1 && j == m + 1 && mesh_.valence(loop_[m]) < 3) return false;
    if (!closed_) return true;  // A chain's ends stay on the border.
    // The ears that wrap around the outer side: loop[0] between loop[n-1] and loop[1], and
    // loop[n-1] between loop[n-2] and loop[0].
    if (i == 0 && m == 1 && j == n_ - 1 && mesh_.valence(loop_[0]) < 3) return false;
    if (i == 0 && m == n_ - 2 && j == n_ - 1 && mesh_.valence(loop_[n_ - 1]) < 3) return false;
    return true;
  }

  const Mesh& mesh_;
  const bool closed_;
  const VertexLoop& loop_;
  const size_t n_;
  const double max_area_;
  const double max_edge2_;
  std::vector<double> cost_;
  std::vector<int> apex_;
};

// Whether a filling triangle lies folded back over the face across one of its chain edges
// (their normals point apart): the chain then went round a tongue of the mesh, not a slit.
bool FoldsOver(const Mesh& mesh, const VertexLoop& chain,
               const std::vector<std::array<size_t, 3>>& triangles) {
  for (const auto& t : triangles) {
    const Vec3 n = OpenMesh::cross(mesh.point(chain[t[1]]) - mesh.point(chain[t[0]]),
                                   mesh.point(chain[t[2]]) - mesh.point(chain[t[0]]));
    for (int k = 0; k < 3; ++k) {
      const size_t a = t[k], b = t[(k + 1) % 3];
      if (b != a + 1) continue;  // Not a chain edge.
      const auto h = mesh.find_halfedge(chain[a], chain[b]);  // The boundary half-edge.
      const auto across = mesh.opposite_face_handle(h);
      if (across.is_valid() && OpenMesh::dot(n, mesh.calc_face_normal(across)) <= 0) return true;
    }
  }
  return false;
}

// Fills `loop` with its admissible triangulation of least total new-edge length; returns the
// number of faces added, 0 when there is none (the mesh is then unchanged).
size_t FillLoop(Mesh& mesh, const VertexLoop& loop, double max_area, double max_edge,
                bool closed = true) {
  if (loop.size() < 3) return 0;
  LoopTriangulation triangulation(mesh, loop, max_area, max_edge, closed);
  if (triangulation.Solve() >= LoopTriangulation::kInfeasible) return 0;
  std::vector<std::array<size_t, 3>> triangles;
  triangulation.Triangles(0, loop.size() - 1, triangles);
  if (!closed && FoldsOver(mesh, loop, triangles)) return 0;
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

// The chains of `loop` that may close a slit, most slit-like first: for each start, the chain
// of at least 3 and at most kMaxSlitChainEdges edges (and at most half the loop) whose ends
// are at most max_edge apart and whose chord is the smallest share of its path, if that share
// is at most 1 / kMinSlitPathToChord. Along a smooth border the path is barely longer than the
// chord; across the mouth of a slit it is many times longer, and the mouth is where the share
// is smallest.
std::vector<VertexLoop> SlitCandidates(const Mesh& mesh, const VertexLoop& loop,
                                       double max_edge) {
  const size_t n = loop.size();
  const size_t max_k = std::min(kMaxSlitChainEdges, n / 2);
  std::vector<double> edge(n);
  for (size_t i = 0; i < n; ++i) {
    edge[i] = (mesh.point(loop[(i + 1) % n]) - mesh.point(loop[i])).norm();
  }
  struct Candidate {
    double share;  // chord / path.
    size_t start;
    size_t edges;
  };
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < n; ++i) {
    double path = 0;
    Candidate best = {1.0 / kMinSlitPathToChord, i, 0};
    for (size_t k = 1; k <= max_k; ++k) {
      path += edge[(i + k - 1) % n];
      const double chord = (mesh.point(loop[(i + k) % n]) - mesh.point(loop[i])).norm();
      if (k >= 3 && chord <= max_edge && path > 0 && chord / path <= best.share) {
        best = {chord / path, i, k};
      }
    }
    if (best.edges > 0) candidates.push_back(best);
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.share != b.share ? a.share < b.share : a.start < b.start;
  });
  if (candidates.size() > kMaxSlitCandidatesPerLoop) candidates.resize(kMaxSlitCandidatesPerLoop);
  std::vector<VertexLoop> chains;
  for (const Candidate& c : candidates) {
    VertexLoop chain;
    for (size_t step = 0; step <= c.edges; ++step) chain.push_back(loop[(c.start + step) % n]);
    chains.push_back(std::move(chain));
  }
  return chains;
}

// Cuts the bridge of the two faces on either side of the interior half-edge `h`, whose ends
// lie on two different loops of `joined_vertices` vertices together, and fills the one loop
// that the cut leaves (FillLoop) if it has at most `max_vertices`. When that loop has no
// admissible triangulation, puts the two faces back and returns 0; otherwise returns the
// number of faces added. The cut must be legal (IsFaceSetRemovalOk).
size_t CutBridgeAndFill(Mesh& mesh, Mesh::HalfedgeHandle h, size_t joined_vertices,
                        size_t max_vertices, double max_area, double max_edge) {
  const std::array<Mesh::FaceHandle, 2> bridge = {mesh.face_handle(h),
                                                  mesh.opposite_face_handle(h)};
  std::array<std::array<Mesh::VertexHandle, 3>, 2> corners;
  for (int k = 0; k < 2; ++k) {
    int i = 0;
    for (auto v : mesh.fv_range(bridge[k])) corners[k][i++] = v;
  }
  const Mesh::VertexHandle from = mesh.from_vertex_handle(h);
  const Mesh::VertexHandle to = mesh.to_vertex_handle(h);
  // As in CutInactiveBridges: the first removal leaves a pinch that the second one resolves.
  RemoveTriangle(mesh, bridge[0], nullptr);
  RemoveTriangle(mesh, bridge[1], nullptr);
  // The loop through `from` (OpenMesh keeps a boundary half-edge as its outgoing one).
  const Mesh::HalfedgeHandle out = mesh.halfedge_handle(from);
  const VertexLoop joined = mesh.is_boundary(out) ? BoundaryLoopFrom(mesh, out) : VertexLoop();
  const bool one_loop = joined.size() >= joined_vertices &&
                        std::find(joined.begin(), joined.end(), to) != joined.end();
  const size_t added =
      one_loop && joined.size() <= max_vertices ? FillLoop(mesh, joined, max_area, max_edge) : 0;
  if (added > 0) return added;
  // Undo in reverse order: each add_face restores the state before the matching removal (the
  // first one the pinch in between). Should OpenMesh refuse one, the mesh keeps the legal cut
  // of both faces rather than a pinch.
  const Mesh::FaceHandle second = mesh.add_face(corners[1][0], corners[1][1], corners[1][2]);
  if (second.is_valid() &&
      !mesh.add_face(corners[0][0], corners[0][1], corners[0][2]).is_valid()) {
    RemoveTriangle(mesh, second, nullptr);
  }
  return 0;
}

// The largest face (alpha_r E(Area), Eq. 2) and edge (alpha_m sqrt(E(Area)), Eq. 3) a filling
// may have.
struct FillLimits {
  double max_area;
  double max_edge;
};

// The limits for `options`, with E(Area) = `mean_area`, or that of the live faces when it is
// <= 0; none when no face may be added (E(Area) is 0).
std::optional<FillLimits> LimitsOf(const Mesh& mesh, const HoleClosingOptions& options,
                                   double mean_area) {
  if (mean_area <= 0) mean_area = MeanTriangleArea(mesh);
  const FillLimits limits{options.alpha_r * mean_area, options.alpha_m * std::sqrt(mean_area)};
  if (!(limits.max_area > 0)) return std::nullopt;
  return limits;
}

// Whether the border half-edges h = a -> t and t -> b turn back at t as at the tip of a crack:
// a and b within 90 degrees of each other as seen from t, in a loop of more than 3 vertices
// (a loop of 3 is a hole, CloseSmallHoles'). Whether the triangle (a, t, b) may close it is
// FillLoop's test of the chain a, t, b (see CloseCrackTips in the header).
bool IsCrackTip(const Mesh& mesh, Mesh::HalfedgeHandle h) {
  const Mesh::HalfedgeHandle next = mesh.next_halfedge_handle(h);
  const Mesh::VertexHandle a = mesh.from_vertex_handle(h);
  const Mesh::VertexHandle t = mesh.to_vertex_handle(h);
  if (mesh.to_vertex_handle(mesh.next_halfedge_handle(next)) == a) return false;
  const Vec3& pt = mesh.point(t);
  return OpenMesh::dot(mesh.point(a) - pt, mesh.point(mesh.to_vertex_handle(next)) - pt) >= 0;
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
      CollectLoops(mesh, static_cast<size_t>(options.max_loop_vertices),
                   options.keep_longest_loop_open);
  if (loops.empty()) return result;
  const std::optional<FillLimits> limits = LimitsOf(mesh, options, mean_area);
  if (!limits) return result;
  const auto [max_area, max_edge] = *limits;
  for (const VertexLoop& loop : loops) {
    const size_t added = FillLoop(mesh, loop, max_area, max_edge);
    if (added == 0) continue;
    ++result.closed_holes;
    result.added_faces += added;
  }
  return result;
}

HoleClosingResult CloseBridgedHoles(Mesh& mesh, const HoleClosingOptions& options,
                                    double mean_area) {
  HoleClosingResult result;
  const std::vector<VertexLoop> loops = CollectBoundaryLoops(mesh);
  if (loops.size() < 2) return result;
  const std::optional<FillLimits> limits = LimitsOf(mesh, options, mean_area);
  if (!limits) return result;
  const auto [max_area, max_edge] = *limits;
  std::vector<int> loop_of(mesh.n_vertices(), -1);
  for (size_t i = 0; i < loops.size(); ++i) {
    for (auto v : loops[i]) loop_of[v.idx()] = static_cast<int>(i);
  }
  // The edges between two loops, as vertex pairs: a tried cut that is undone replaces the
  // edges of its two faces, so half-edge handles would not survive it.
  std::vector<std::pair<Mesh::VertexHandle, Mesh::VertexHandle>> bridges;
  for (const VertexLoop& loop : loops) {
    for (auto v : loop) {
      for (auto u : mesh.vv_range(v)) {
        if (loop_of[u.idx()] > loop_of[v.idx()]) bridges.emplace_back(v, u);
      }
    }
  }
  // A fill only changes the faces and edges of its own two loops, so the others stay as
  // collected; a loop takes part in one fill per call. A pair of loops is tried once, through
  // the first of its bridges whose cut is legal: the loop left by the cut is nearly the same
  // whichever bridge goes, and a band of faces one triangle wide between two holes, every
  // edge across it a bridge, would otherwise cost a triangulation per edge.
  std::vector<bool> closed(loops.size(), false);
  if (options.keep_longest_loop_open) closed[LongestLoop(mesh, loops)] = true;
  std::set<std::pair<int, int>> tried;
  for (const auto& [v, u] : bridges) {
    const int a = loop_of[v.idx()];
    const int b = loop_of[u.idx()];
    if (closed[a] || closed[b] || tried.count({a, b}) > 0) continue;
    const size_t joined = loops[a].size() + loops[b].size();
    if (joined > static_cast<size_t>(options.max_loop_vertices)) continue;
    const Mesh::HalfedgeHandle h = mesh.find_halfedge(v, u);
    if (!h.is_valid() || mesh.is_boundary(mesh.edge_handle(h))) continue;
    const std::array<Mesh::FaceHandle, 2> bridge = {mesh.face_handle(h),
                                                    mesh.opposite_face_handle(h)};
    if (!IsFaceSetRemovalOk(mesh, bridge, Mesh::VertexHandle())) continue;
    tried.insert({a, b});
    const size_t added =
        CutBridgeAndFill(mesh, h, joined, static_cast<size_t>(options.max_loop_vertices),
                         max_area, max_edge);
    if (added == 0) continue;
    closed[a] = closed[b] = true;
    ++result.closed_holes;
    result.added_faces += added;
  }
  return result;
}

HoleClosingResult CloseCrackTips(Mesh& mesh, const HoleClosingOptions& options,
                                 double mean_area) {
  HoleClosingResult result;
  const std::optional<FillLimits> limits = LimitsOf(mesh, options, mean_area);
  if (!limits) return result;
  // Border half-edges a -> t to look at; each closed tip puts the two that may form the next
  // one back: the new border edge a -> b and the one into a.
  std::vector<Mesh::HalfedgeHandle> pending;
  for (const Mesh::HalfedgeHandle h : mesh.halfedges()) {
    if (!mesh.status(h).deleted() && mesh.is_boundary(h)) pending.push_back(h);
  }
  while (!pending.empty()) {
    const Mesh::HalfedgeHandle h = pending.back();
    pending.pop_back();
    if (mesh.status(h).deleted() || !mesh.is_boundary(h) || !IsCrackTip(mesh, h)) continue;
    const Mesh::VertexHandle a = mesh.from_vertex_handle(h);
    const Mesh::VertexHandle b = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
    const VertexLoop tip = {a, mesh.to_vertex_handle(h), b};
    if (FillLoop(mesh, tip, limits->max_area, limits->max_edge, /*closed=*/false) == 0) continue;
    ++result.closed_holes;
    ++result.added_faces;
    const Mesh::HalfedgeHandle border = mesh.find_halfedge(a, b);
    pending.push_back(border);
    pending.push_back(mesh.prev_halfedge_handle(border));
  }
  return result;
}

HoleClosingResult ZipBorderSlits(Mesh& mesh, const HoleClosingOptions& options,
                                 double mean_area) {
  HoleClosingResult result = CloseCrackTips(mesh, options, mean_area);
  const std::optional<FillLimits> limits = LimitsOf(mesh, options, mean_area);
  if (!limits) return result;
  const auto [max_area, max_edge] = *limits;
  // Each zip changes the loops, so they are collected again after it.
  for (size_t zips = 0; zips < kMaxSlitZipsPerCall; ++zips) {
    bool zipped = false;
    for (const VertexLoop& loop : CollectBoundaryLoops(mesh)) {
      for (const VertexLoop& chain : SlitCandidates(mesh, loop, max_edge)) {
        const size_t added = FillLoop(mesh, chain, max_area, max_edge, /*closed=*/false);
        if (added == 0) continue;
        ++result.closed_holes;
        result.added_faces += added;
        zipped = true;
        break;
      }
      if (zipped) break;
    }
    if (!zipped) break;
  }
  return result;
}

}  // namespace neuralmesh
