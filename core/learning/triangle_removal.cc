#include "core/learning/triangle_removal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <queue>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

// A component with this many faces or fewer is left alone (a tetrahedron-like minimum).
constexpr size_t kMinComponentFaces = 4;

double TriangleArea(const Mesh& mesh, Mesh::FaceHandle fh) {
  auto h = mesh.halfedge_handle(fh);
  const Vec3& p0 = mesh.point(mesh.from_vertex_handle(h));
  const Vec3& p1 = mesh.point(mesh.to_vertex_handle(h));
  const Vec3& p2 = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
  return 0.5 * OpenMesh::cross(p1 - p0, p2 - p0).norm();
}

// Whether the component of `fh` has more than `limit` faces. A breadth-first search across
// edges that stops as soon as it has seen limit + 1 faces, so it costs O(limit), not O(f).
bool ComponentHasMoreFacesThan(const Mesh& mesh, Mesh::FaceHandle fh, size_t limit) {
  std::vector<Mesh::FaceHandle> seen = {fh};
  for (size_t next = 0; next < seen.size(); ++next) {
    for (auto h : mesh.fh_range(seen[next])) {
      const auto neighbour = mesh.opposite_face_handle(h);
      if (!neighbour.is_valid()) continue;
      if (std::find(seen.begin(), seen.end(), neighbour) != seen.end()) continue;
      seen.push_back(neighbour);
      if (seen.size() > limit) return true;
    }
  }
  return false;
}

// The mean area of the live faces into *mean and, when `areas` is given, every face's area into
// it, by face index (0 for a deleted one).
void FaceAreas(const Mesh& mesh, double* mean, std::vector<double>* areas) {
  // A face's corners are a chain of loads (its half-edge, the next one, three points) that
  // miss on a large mesh, so each face's links start loading some faces ahead: Step 4 then
  // takes 0.3 of its time at 100K vertices (15 against 43-56 million cycles a call).
  constexpr int kLinksAhead = 24;
  constexpr int kCornersAhead = 12;
  const int num_faces = static_cast<int>(mesh.n_faces());
  if (areas != nullptr) areas->assign(mesh.n_faces(), 0.0);
  double total = 0;
  size_t count = 0;
  // Only live faces' links are followed: a deleted face's may name a half-edge that is gone.
  auto live = [&mesh, num_faces](int f) {
    return f < num_faces && !mesh.status(Mesh::FaceHandle(f)).deleted();
  };
  for (auto fh : mesh.faces()) {
    if (live(fh.idx() + kLinksAhead)) {
      const Mesh::FaceHandle ahead(fh.idx() + kLinksAhead);
      __builtin_prefetch(&mesh.halfedge(mesh.halfedge_handle(ahead)));
    }
    if (live(fh.idx() + kCornersAhead)) {
      const Mesh::HalfedgeHandle h =
          mesh.halfedge_handle(Mesh::FaceHandle(fh.idx() + kCornersAhead));
      __builtin_prefetch(&mesh.point(mesh.to_vertex_handle(h)));
      __builtin_prefetch(&mesh.point(mesh.from_vertex_handle(h)));
      __builtin_prefetch(&mesh.halfedge(mesh.next_halfedge_handle(h)));
    }
    const double area = TriangleArea(mesh, fh);
    if (areas != nullptr) (*areas)[static_cast<size_t>(fh.idx())] = area;
    total += area;
    ++count;
  }
  *mean = count == 0 ? 0.0 : total / static_cast<double>(count);
}

}  // namespace

absl::Status TriangleRemovalOptions::Validate() const {
  if (!std::isfinite(alpha_r) || alpha_r <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("alpha_r (Eq. 2) must be finite and positive, got ", alpha_r));
  }
  return absl::OkStatus();
}

double MeanTriangleArea(const Mesh& mesh) {
  double mean;
  FaceAreas(mesh, &mean, nullptr);
  return mean;
}

bool IsTriangleRemovalOk(const Mesh& mesh, Mesh::FaceHandle fh) {
  if (!fh.is_valid() || mesh.status(fh).deleted()) return false;
  for (auto h : mesh.fh_range(fh)) {
    // Corner v = to(h); its two edges in the face are edge(h) and edge(next(h)).
    const bool in_is_boundary = mesh.is_boundary(mesh.opposite_halfedge_handle(h));
    const bool out_is_boundary =
        mesh.is_boundary(mesh.opposite_halfedge_handle(mesh.next_halfedge_handle(h)));
    if (!in_is_boundary && !out_is_boundary && mesh.is_boundary(mesh.to_vertex_handle(h))) {
      return false;  // The face is in the middle of a boundary vertex's fan: a pinch.
    }
  }
  return true;
}

void RemoveTriangle(Mesh& mesh, Mesh::FaceHandle fh,
                    std::vector<Mesh::VertexHandle>* removed_vertices) {
  std::array<Mesh::VertexHandle, 3> corners;
  int k = 0;
  for (auto vh : mesh.fv_range(fh)) corners[k++] = vh;
  mesh.delete_face(fh, /*_delete_isolated_vertices=*/true);
  for (auto vh : corners) {
    if (mesh.status(vh).deleted()) {
      if (removed_vertices != nullptr) removed_vertices->push_back(vh);
    } else {
      // OpenMesh 9's delete_face happens to do this too, but does not document it, and
      // ValidateMesh (and every later add_face) relies on it.
      mesh.adjust_outgoing_halfedge(vh);
    }
  }
}

TriangleRemovalResult RemoveLargeTriangles(Mesh& mesh, const TriangleRemovalOptions& options) {
  return RemoveLargeTriangles(mesh, options, nullptr);
}

TriangleRemovalResult RemoveLargeTriangles(
    Mesh& mesh, const TriangleRemovalOptions& options,
    const std::function<bool(Mesh::FaceHandle)>& spared) {
  TriangleRemovalResult result;
  // Every face's area once: Eq. 2's mean and the comparisons with it read the same numbers.
  std::vector<double> areas;
  FaceAreas(mesh, &result.mean_area, &areas);
  const double threshold = options.alpha_r * result.mean_area;

  // Each large face is in one state; the heaps hold (area, face index), largest first, ties
  // by index so runs are reproducible. Heap entries whose face has changed state since are
  // stale and skipped when popped.
  enum class State { kSeed, kFrontier, kParked, kRemoved };
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry> frontier;  // Large faces with a boundary edge: they grow a hole.
  std::priority_queue<Entry> seeds;     // Large faces away from any boundary: they open one.
  std::unordered_map<int, std::pair<State, double>> large;  // Face index -> (state, area).
  auto enqueue = [&](int index, double area) {
    const State state = mesh.is_boundary(Mesh::FaceHandle(index)) ? State::kFrontier : State::kSeed;
    large[index] = {state, area};
    (state == State::kFrontier ? frontier : seeds).emplace(area, index);
  };
  for (auto fh : mesh.faces()) {
    const double area = areas[static_cast<size_t>(fh.idx())];
    if (area > threshold && !(spared && spared(fh))) enqueue(fh.idx(), area);
  }

  while (!frontier.empty() || !seeds.empty()) {
    const bool from_frontier = !frontier.empty();
    auto& heap = from_frontier ? frontier : seeds;
    const int index = heap.top().second;
    heap.pop();
    State& state = large[index].first;
    if (state != (from_frontier ? State::kFrontier : State::kSeed)) continue;
    const Mesh::FaceHandle fh(index);
    if (!IsTriangleRemovalOk(mesh, fh) ||
        !ComponentHasMoreFacesThan(mesh, fh, kMinComponentFaces)) {
      state = State::kParked;
      continue;
    }
    state = State::kRemoved;
    std::array<Mesh::VertexHandle, 3> corners;
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) corners[k++] = vh;
    RemoveTriangle(mesh, fh, &result.removed_vertices);
    ++result.removed_faces;

    // The removal changed which edges and corners lie on a boundary only for the faces
    // around f's corners: parked ones may have become legal, and seeds next to the new
    // boundary now grow it.
    for (auto vh : corners) {
      if (mesh.status(vh).deleted()) continue;
      result.touched_vertices.push_back(vh);
      for (auto neighbour : mesh.vf_range(vh)) {
        auto it = large.find(neighbour.idx());
        if (it == large.end()) continue;
        const State neighbour_state = it->second.first;
        if (neighbour_state == State::kParked ||
            (neighbour_state == State::kSeed && mesh.is_boundary(neighbour))) {
          enqueue(it->first, it->second.second);
        }
      }
    }
  }
  return result;
}

}  // namespace neuralmesh
