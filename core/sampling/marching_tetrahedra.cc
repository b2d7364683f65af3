#include "core/sampling/marching_tetrahedra.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

using Offset = std::array<int, 3>;
using Tet = std::array<Offset, 4>;
using TetEdge = std::pair<int, int>;  // Local corner indices of a tetrahedron edge.
using TetTriangle = std::array<TetEdge, 3>;

int Det(const Offset& a, const Offset& b, const Offset& c) {
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
}

Offset Minus(const Offset& a, const Offset& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

// The 6 tetrahedra of a unit cube along its diagonal (0,0,0)-(1,1,1), one per order in which
// the axes are stepped, each positively oriented.
std::array<Tet, 6> KuhnTetrahedra() {
  std::array<Tet, 6> tets;
  std::array<int, 3> axes = {0, 1, 2};
  int t = 0;
  do {
    Tet tet;
    Offset p = {0, 0, 0};
    tet[0] = p;
    for (int k = 0; k < 3; ++k) {
      p[axes[k]] = 1;
      tet[k + 1] = p;
    }
    if (Det(Minus(tet[1], tet[0]), Minus(tet[2], tet[0]), Minus(tet[3], tet[0])) < 0) {
      std::swap(tet[2], tet[3]);
    }
    tets[t++] = tet;
  } while (std::next_permutation(axes.begin(), axes.end()));
  return tets;
}

// Triangles per inside-mask (bit i set: corner i inside) of a positively oriented
// tetrahedron, oriented so their normals point from the inside corners to the outside ones.
// An even permutation of the corners keeps the orientation, so each case is brought to a
// canonical one where the lone inside corner, the lone outside corner or the inside pair
// comes first:
//   1 inside  (0):    triangle (01, 02, 03)
//   3 inside  (0 out): triangle (01, 03, 02)
//   2 inside  (0, 1): quad (02, 03, 13, 12) as two triangles
std::array<std::vector<TetTriangle>, 16> TetCases() {
  std::vector<std::array<int, 4>> even;
  std::array<int, 4> p = {0, 1, 2, 3};
  do {
    int inversions = 0;
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) inversions += p[i] > p[j];
    }
    if (inversions % 2 == 0) even.push_back(p);
  } while (std::next_permutation(p.begin(), p.end()));

  std::array<std::vector<TetTriangle>, 16> cases;
  for (int mask = 1; mask < 15; ++mask) {
    auto inside = [&](int corner) { return ((mask >> corner) & 1) != 0; };
    const int count = inside(0) + inside(1) + inside(2) + inside(3);
    for (const auto& q : even) {
      auto e = [&](int a, int b) { return TetEdge(q[a], q[b]); };
      if (count == 1 && inside(q[0])) {
        cases[mask] = {{e(0, 1), e(0, 2), e(0, 3)}};
      } else if (count == 3 && !inside(q[0])) {
        cases[mask] = {{e(0, 1), e(0, 3), e(0, 2)}};
      } else if (count == 2 && inside(q[0]) && inside(q[1])) {
        cases[mask] = {{e(0, 2), e(0, 3), e(1, 3)}, {e(0, 2), e(1, 3), e(1, 2)}};
      } else {
        continue;
      }
      break;
    }
  }
  return cases;
}

}  // namespace

absl::StatusOr<TriangleMesh> MarchingTetrahedra(const std::function<double(const Vec3&)>& f,
                                                const BoundingBox& box,
                                                const std::array<int, 3>& cells) {
  for (int a = 0; a < 3; ++a) {
    if (cells[a] < 1) {
      return absl::InvalidArgumentError(absl::StrCat("cell count ", a, " is ", cells[a]));
    }
  }
  if (box.empty() ||
      !(box.min[0] < box.max[0] && box.min[1] < box.max[1] && box.min[2] < box.max[2])) {
    return absl::InvalidArgumentError("the grid's box is empty or flat");
  }
  const std::array<int64_t, 3> n = {int64_t{cells[0]} + 1, int64_t{cells[1]} + 1,
                                    int64_t{cells[2]} + 1};
  if (n[0] * n[1] * n[2] > (int64_t{1} << 31)) {
    return absl::InvalidArgumentError(
        absl::StrCat("the grid has ", n[0] * n[1] * n[2], " points; at most 2^31 are supported"));
  }
  const Vec3 spacing((box.max[0] - box.min[0]) / cells[0], (box.max[1] - box.min[1]) / cells[1],
                     (box.max[2] - box.min[2]) / cells[2]);
  auto id = [&](int64_t i, int64_t j, int64_t k) { return i + n[0] * (j + n[1] * k); };
  auto point = [&](int64_t i, int64_t j, int64_t k) {
    return Vec3(box.min[0] + i * spacing[0], box.min[1] + j * spacing[1],
                box.min[2] + k * spacing[2]);
  };

  std::vector<double> values(n[0] * n[1] * n[2]);
  for (int64_t k = 0; k < n[2]; ++k) {
    for (int64_t j = 0; j < n[1]; ++j) {
      for (int64_t i = 0; i < n[0]; ++i) {
        const double v = f(point(i, j, k));
        if (!std::isfinite(v)) {
          return absl::InvalidArgumentError(
              absl::StrCat("f is not finite at grid point (", i, ", ", j, ", ", k, ")"));
        }
        const bool on_boundary =
            i == 0 || j == 0 || k == 0 || i == n[0] - 1 || j == n[1] - 1 || k == n[2] - 1;
        if (on_boundary && v < 0) {
          return absl::InvalidArgumentError(
              absl::StrCat("f < 0 at boundary grid point (", i, ", ", j, ", ", k,
                           "): the surface leaves the box and would not be closed"));
        }
        values[id(i, j, k)] = v;
      }
    }
  }

  static const std::array<Tet, 6> kTets = KuhnTetrahedra();
  static const std::array<std::vector<TetTriangle>, 16> kCases = TetCases();
  TriangleMesh mesh;
  std::unordered_map<uint64_t, uint32_t> edge_vertex;
  // One vertex per grid edge, shared by every tetrahedron around that edge; computed from the
  // inside end so that it does not depend on which tetrahedron asks first.
  auto vertex_on = [&](int64_t in, const Vec3& p_in, int64_t out, const Vec3& p_out) {
    const uint64_t key =
        (static_cast<uint64_t>(std::min(in, out)) << 32) | static_cast<uint64_t>(std::max(in, out));
    const auto [it, inserted] =
        edge_vertex.emplace(key, static_cast<uint32_t>(mesh.positions.size()));
    if (inserted) {
      const double t = values[in] / (values[in] - values[out]);  // in < 0 <= out.
      mesh.positions.emplace_back(p_in + (p_out - p_in) * t);
    }
    return it->second;
  };

  for (int64_t k = 0; k < cells[2]; ++k) {
    for (int64_t j = 0; j < cells[1]; ++j) {
      for (int64_t i = 0; i < cells[0]; ++i) {
        for (const Tet& tet : kTets) {
          std::array<int64_t, 4> ids;
          std::array<Vec3, 4> points;
          int mask = 0;
          for (int c = 0; c < 4; ++c) {
            const Offset& o = tet[c];
            ids[c] = id(i + o[0], j + o[1], k + o[2]);
            points[c] = point(i + o[0], j + o[1], k + o[2]);
            if (values[ids[c]] < 0) mask |= 1 << c;
          }
          for (const TetTriangle& triangle : kCases[mask]) {
            std::array<uint32_t, 3> face;
            for (int v = 0; v < 3; ++v) {
              int a = triangle[v].first;
              int b = triangle[v].second;
              if (values[ids[a]] >= 0) std::swap(a, b);
              face[v] = vertex_on(ids[a], points[a], ids[b], points[b]);
            }
            mesh.faces.push_back(face);
          }
        }
      }
    }
  }
  return mesh;
}

}  // namespace neuralmesh
