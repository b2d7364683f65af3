#include "core/learning/vertex_split.h"

#include <algorithm>
#include <cmath>

#include "absl/container/inlined_vector.h"
#include "absl/types/span.h"

namespace neuralmesh {
namespace {

// Neighbours in rotation order (WalkNeighbours, VertexRingCache): a copy that stays valid
// while other rings are read (which may move where a cached ring is kept).
using Neighbours = absl::InlinedVector<int32_t, 16>;

Neighbours WalkedNeighbours(const Mesh& mesh, Mesh::VertexHandle v) {
  Neighbours out;
  WalkNeighbours(mesh, v, out);
  return out;
}

absl::Span<const int32_t> Span(const VertexRingCache::RingView& ring) {
  return absl::MakeConstSpan(ring.neighbours, static_cast<size_t>(ring.size));
}

// F_v = l_v^2 (Eq. 5-6) from v's neighbours.
double SquaredMeanEdgeLength(const Mesh& mesh, Mesh::VertexHandle v,
                             absl::Span<const int32_t> neighbours) {
  if (neighbours.empty()) return 0;
  double sum = 0;
  const Vec3& p = mesh.point(v);
  for (const int32_t u : neighbours) sum += (mesh.point(Mesh::VertexHandle(u)) - p).norm();
  const double l = sum / static_cast<double>(neighbours.size());
  return l * l;
}

// Section 2.2: no split of a boundary vertex of valence 4 or less.
bool SplittableStar(bool boundary, int valence) { return !boundary || valence > 4; }

// Whether `v` is a live vertex with at least one edge.
bool HasEdges(const Mesh& mesh, Mesh::VertexHandle v) {
  return v.is_valid() && !mesh.status(v).deleted() && mesh.halfedge_handle(v).is_valid();
}

// The valence of a vertex and whether it is on the boundary.
struct StarShape {
  int valence;
  bool boundary;
};

// SplitVertex of a splittable `v` with neighbours `u` (in rotation order), on the
// boundary or not; shape_of(w) gives the StarShape of a neighbour w.
template <typename ShapeOf>
Mesh::VertexHandle SplitStar(Mesh& mesh, Mesh::VertexHandle v, const Neighbours& u, bool boundary,
                             const ShapeOf& shape_of) {
  const int n = static_cast<int>(u.size());
  const Vec3& p = mesh.point(v);

  int longest = 0;
  double longest_len2 = -1;
  for (int i = 0; i < n; ++i) {
    const double l2 = (mesh.point(Mesh::VertexHandle(u[i])) - p).sqrnorm();
    if (l2 > longest_len2) {
      longest_len2 = l2;
      longest = i;
    }
  }
  const Vec3 midpoint = (p + mesh.point(Mesh::VertexHandle(u[longest]))) * 0.5;
  auto neighbour = [&](int i) { return Mesh::VertexHandle(u[((i % n) + n) % n]); };

  if (!boundary) {
    // The new vertex takes the arc u[e-k2] .. u[e+k1] around e; k1 and k2 differ by at most
    // one ("traverse both directions from e equally"), and k1 + k2 - 1 neighbours lie strictly
    // inside the arc, (n-2)/2 of them so that the star is halved: valences become
    // inner+3 and n-inner+1. The cut neighbours vl = u[e+k1], vr = u[e-k2] gain an edge each;
    // of the admissible arcs, take the one that leaves the four affected valences most
    // regular ("distributing the valences as regularly as possible"). A cut neighbour on the
    // border costs nothing up to valence 5: a border vertex of valence 4 may not be split
    // (Section 2.2), so gaining an edge is the only way a border refines along with the
    // surface (valence 5 splits into 4 + 4); penalising it kept borders at their first, coarse
    // resolution, too sparse for Step 5 to see two facing borders as close. Above 5 it counts
    // again (from 5, not 4): free edges let border vertices that are never split themselves
    // grow into hubs of valence 20 and more.
    auto deviation = [](bool on_boundary, int valence) {
      const double d = on_boundary ? std::max(0, valence - 5) : valence - 6;
      return d * d;
    };
    int k1 = 1, k2 = 1;
    double best = 1e300;
    for (int inner = std::max(1, (n - 2) / 2); inner <= std::max(1, (n - 1) / 2); ++inner) {
      const int total = inner + 1;  // k1 + k2
      for (int a = total / 2; a <= (total + 1) / 2; ++a) {
        const int b = total - a;
        if (a < 1 || b < 1) continue;
        const auto wl = neighbour(longest + a), wr = neighbour(longest - b);
        const StarShape l = shape_of(wl), r = shape_of(wr);
        const double cost = deviation(false, n - inner + 1) + deviation(false, inner + 3) +
                            deviation(l.boundary, l.valence + 1) +
                            deviation(r.boundary, r.valence + 1);
        if (cost < best) {
          best = cost;
          k1 = a;
          k2 = b;
        }
      }
    }
    const auto vl = neighbour(longest + k1);
    const auto vr = neighbour(longest - k2);
    const auto v0 = mesh.add_vertex(midpoint);
    mesh.vertex_split(v0, v, vl, vr);
    return v0;
  }

  // Boundary fan u[0] .. u[n-1] (u[0] along the outgoing boundary edge). Cut at j: one vertex
  // keeps u[0..j], the other u[j..n-1], joined by a new boundary edge; valences j+2, n-j+1.
  const int j = (n - 1) / 2;
  const auto cut = neighbour(j);
  const auto v0 = mesh.add_vertex(midpoint);
  if (longest <= j) {
    mesh.vertex_split(v0, v, cut, Mesh::VertexHandle());  // v0 takes u[0..j].
  } else {
    mesh.vertex_split(v0, v, Mesh::VertexHandle(), cut);  // v0 takes u[j..n-1].
  }
  return v0;
}

}  // namespace

bool CanSplitVertex(const Mesh& mesh, Mesh::VertexHandle v) {
  return HasEdges(mesh, v) &&
         SplittableStar(mesh.is_boundary(v), static_cast<int>(mesh.valence(v)));
}

bool CanSplitVertex(const Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle v) {
  if (!HasEdges(mesh, v)) return false;
  const VertexRingCache::RingView ring = rings.Ring(mesh, v.idx());
  return SplittableStar(ring.boundary, ring.size);
}

double VoronoiAreaEstimate(const Mesh& mesh, Mesh::VertexHandle v) {
  if (!HasEdges(mesh, v)) return 0;
  return SquaredMeanEdgeLength(mesh, v, WalkedNeighbours(mesh, v));
}

double VoronoiAreaEstimate(const Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle v) {
  if (!HasEdges(mesh, v)) return 0;
  return SquaredMeanEdgeLength(mesh, v, Span(rings.Ring(mesh, v.idx())));
}

Mesh::VertexHandle LargestCellNear(const Mesh& mesh, VertexRingCache& rings,
                                   Mesh::VertexHandle center) {
  Mesh::VertexHandle best = center;
  double best_area = -1;
  if (!HasEdges(mesh, center)) return best;
  const VertexRingCache::RingView center_ring = rings.Ring(mesh, center.idx());
  const Neighbours neighbours(center_ring.neighbours, center_ring.neighbours + center_ring.size);
  if (SplittableStar(center_ring.boundary, center_ring.size)) {
    best_area = SquaredMeanEdgeLength(mesh, center, neighbours);
  }
  for (const int32_t u : neighbours) {
    // A neighbour is live and has an edge, to `center`.
    const VertexRingCache::RingView ring = rings.Ring(mesh, u);
    if (!SplittableStar(ring.boundary, ring.size)) continue;
    const double area = SquaredMeanEdgeLength(mesh, Mesh::VertexHandle(u), Span(ring));
    if (area > best_area) {
      best_area = area;
      best = Mesh::VertexHandle(u);
    }
  }
  return best;
}

void ShareSplitCounter(const Mesh& mesh, VertexRingCache& rings, SignalCounters& counters,
                       Mesh::VertexHandle v, Mesh::VertexHandle v0, double counter, uint64_t step) {
  const double f1 = VoronoiAreaEstimate(mesh, rings, v);
  const double f0 = VoronoiAreaEstimate(mesh, rings, v0);
  const double share0 = (f0 + f1) > 0 ? f0 / (f0 + f1) : 0.5;
  counters.Set(v.idx(), counter * (1 - share0), step);
  counters.Add(v0.idx(), counter * share0, step);
}

Mesh::VertexHandle ChooseSplitVertex(const Mesh& mesh, VertexRingCache& rings,
                                     SignalCounters& counters, bool largest_cell_near) {
  Mesh::VertexHandle chosen;
  // MostActive returns the last id its callback accepted.
  counters.MostActive([&](int id) {
    const Mesh::VertexHandle most_active(id);
    const Mesh::VertexHandle v =
        largest_cell_near ? LargestCellNear(mesh, rings, most_active) : most_active;
    if (!CanSplitVertex(mesh, rings, v)) return false;
    chosen = v;
    return true;
  });
  return chosen;
}

Mesh::VertexHandle SplitVertex(Mesh& mesh, Mesh::VertexHandle v) {
  if (!HasEdges(mesh, v)) return Mesh::VertexHandle();
  const Neighbours neighbours = WalkedNeighbours(mesh, v);
  const bool boundary = mesh.is_boundary(v);
  if (!SplittableStar(boundary, static_cast<int>(neighbours.size()))) return Mesh::VertexHandle();
  return SplitStar(mesh, v, neighbours, boundary, [&mesh](Mesh::VertexHandle w) {
    return StarShape{static_cast<int>(mesh.valence(w)), mesh.is_boundary(w)};
  });
}

Mesh::VertexHandle SplitVertex(Mesh& mesh, VertexRingCache& rings, Mesh::VertexHandle v) {
  if (!HasEdges(mesh, v)) return Mesh::VertexHandle();
  const VertexRingCache::RingView ring = rings.Ring(mesh, v.idx());
  if (!SplittableStar(ring.boundary, ring.size)) return Mesh::VertexHandle();
  const Neighbours neighbours(ring.neighbours, ring.neighbours + ring.size);
  return SplitStar(mesh, v, neighbours, ring.boundary, [&mesh, &rings](Mesh::VertexHandle w) {
    const VertexRingCache::RingView star = rings.Ring(mesh, w.idx());
    return StarShape{star.size, star.boundary};
  });
}

}  // namespace neuralmesh
