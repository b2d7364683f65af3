#include "core/analysis/mesh_report.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <numeric>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "core/analysis/json_writer.h"

namespace neuralmesh {
namespace {

constexpr uint32_t kNoVertex = UINT32_MAX;
constexpr size_t kNone = SIZE_MAX;

using Face = std::array<uint32_t, 3>;

// Union-find with path halving and union by size: near-constant amortised operations.
class UnionFind {
 public:
  void Reset(size_t n) {
    parent_.resize(n);
    size_.assign(n, 1);
    std::iota(parent_.begin(), parent_.end(), size_t{0});
  }
  size_t Find(size_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void Union(size_t a, size_t b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
  }

 private:
  std::vector<size_t> parent_;
  std::vector<size_t> size_;
};

// Undirected edges numbered from their lower endpoint, with per-edge face and direction
// counts. Half-edge (f, k) runs from faces[f][k] to faces[f][(k + 1) % 3]; its id is 3f + k.
struct EdgeTable {
  std::vector<uint32_t> v0, v1;         // v0 < v1.
  std::vector<uint32_t> face_count;     // Faces containing the edge.
  std::vector<uint32_t> forward_count;  // Of those, the ones that run v0 -> v1.
  std::vector<size_t> of_halfedge;      // Half-edge id -> edge id.
};

// Corners grouped by vertex (counting sort): corners of v are
// corner[begin[v]] .. corner[begin[v + 1] - 1], each the id 3f + k of corner k of face f.
struct VertexCorners {
  std::vector<size_t> begin;
  std::vector<size_t> corner;
};

VertexCorners BucketCorners(const std::vector<Face>& faces, size_t num_vertices) {
  VertexCorners out;
  out.begin.assign(num_vertices + 1, 0);
  for (const Face& f : faces) {
    for (uint32_t v : f) ++out.begin[v + 1];
  }
  std::partial_sum(out.begin.begin(), out.begin.end(), out.begin.begin());
  out.corner.resize(3 * faces.size());
  std::vector<size_t> cursor(out.begin.begin(), out.begin.end() - 1);
  for (size_t f = 0; f < faces.size(); ++f) {
    for (size_t k = 0; k < 3; ++k) out.corner[cursor[faces[f][k]]++] = 3 * f + k;
  }
  return out;
}

// Every half-edge is seen exactly once from its edge's lower endpoint: as the outgoing side
// of a corner there, or as the incoming side. A stamp per neighbour replaces a hash map.
EdgeTable BuildEdges(const std::vector<Face>& faces, const VertexCorners& corners,
                     std::vector<uint32_t>& stamp, std::vector<size_t>& local) {
  EdgeTable edges;
  edges.of_halfedge.resize(3 * faces.size());
  const size_t n = stamp.size();
  for (size_t v = 0; v < n; ++v) {
    const uint32_t v32 = static_cast<uint32_t>(v);
    auto visit = [&](uint32_t w, size_t halfedge, bool forward) {
      if (w < v32) return;
      if (stamp[w] != v32) {
        stamp[w] = v32;
        local[w] = edges.v0.size();
        edges.v0.push_back(v32);
        edges.v1.push_back(w);
        edges.face_count.push_back(0);
        edges.forward_count.push_back(0);
      }
      const size_t e = local[w];
      edges.of_halfedge[halfedge] = e;
      ++edges.face_count[e];
      if (forward) ++edges.forward_count[e];
    };
    for (size_t i = corners.begin[v]; i < corners.begin[v + 1]; ++i) {
      const size_t c = corners.corner[i];
      const size_t f = c / 3, k = c % 3;
      visit(faces[f][(k + 1) % 3], c, /*forward=*/true);
      visit(faces[f][(k + 2) % 3], 3 * f + (k + 2) % 3, /*forward=*/false);
    }
  }
  return edges;
}

// Duplicates share the edge between their two lowest vertices; within the faces grouped by
// that edge, a stamp on the third vertex finds repeats.
size_t CountDuplicateFaces(const std::vector<Face>& faces, const EdgeTable& edges,
                           std::vector<uint32_t>& stamp) {
  const size_t num_edges = edges.v0.size();
  std::vector<size_t> key(faces.size());
  std::vector<uint32_t> third(faces.size());
  std::vector<size_t> begin(num_edges + 1, 0);
  for (size_t f = 0; f < faces.size(); ++f) {
    const Face& t = faces[f];
    // The side opposite the largest vertex joins the two lowest ones.
    const size_t top = t[0] > t[1] ? (t[0] > t[2] ? 0 : 2) : (t[1] > t[2] ? 1 : 2);
    key[f] = edges.of_halfedge[3 * f + (top + 1) % 3];
    third[f] = t[top];
    ++begin[key[f] + 1];
  }
  std::partial_sum(begin.begin(), begin.end(), begin.begin());
  std::vector<uint32_t> grouped(faces.size());
  std::vector<size_t> cursor(begin.begin(), begin.end() - 1);
  for (size_t f = 0; f < faces.size(); ++f) grouped[cursor[key[f]]++] = third[f];

  std::fill(stamp.begin(), stamp.end(), kNoVertex);
  size_t duplicates = 0;
  for (size_t e = 0; e < num_edges; ++e) {
    const uint32_t e_stamp = static_cast<uint32_t>(e);
    for (size_t i = begin[e]; i < begin[e + 1]; ++i) {
      if (stamp[grouped[i]] == e_stamp) {
        ++duplicates;
      } else {
        stamp[grouped[i]] = e_stamp;
      }
    }
  }
  return duplicates;
}

int ValenceColumn(int valence) {
  return valence >= 4 && valence <= 9 ? valence - 4 : kValenceShareColumns - 1;
}

}  // namespace

MeshReport ComputeMeshReport(const TriangleMesh& mesh) {
  MeshReport report;
  report.colored = !mesh.colors.empty() && mesh.colors.size() == mesh.positions.size();
  const size_t n = mesh.positions.size();

  std::vector<Face> faces;
  faces.reserve(mesh.faces.size());
  for (const Face& f : mesh.faces) {
    if (f[0] >= n || f[1] >= n || f[2] >= n) {
      ++report.invalid_faces;
    } else if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) {
      ++report.degenerate_faces;
    } else {
      faces.push_back(f);
    }
  }
  report.faces = faces.size();

  const VertexCorners corners = BucketCorners(faces, n);
  std::vector<uint32_t> stamp(n, kNoVertex);
  std::vector<size_t> local(n, 0);
  const EdgeTable edges = BuildEdges(faces, corners, stamp, local);
  const size_t num_edges = edges.v0.size();
  report.edges = num_edges;
  report.duplicate_faces = CountDuplicateFaces(faces, edges, stamp);

  // Boundary edges get dense ids; partner[2 b + s] is the boundary edge paired with b at its
  // endpoint s (0: v0, 1: v1).
  std::vector<size_t> boundary_id(num_edges, kNone);
  std::vector<size_t> boundary_edge;
  for (size_t e = 0; e < num_edges; ++e) {
    const uint32_t count = edges.face_count[e];
    if (count == 1) {
      boundary_id[e] = boundary_edge.size();
      boundary_edge.push_back(e);
    } else if (count == 2) {
      if (edges.forward_count[e] != 1) ++report.misoriented_edges;
    } else {
      ++report.non_manifold_edges;
    }
  }
  report.boundary_edges = boundary_edge.size();
  std::vector<size_t> partner(2 * boundary_edge.size(), kNone);
  auto pair_at = [&](uint32_t v, size_t e1, size_t e2) {
    const size_t b1 = boundary_id[e1], b2 = boundary_id[e2];
    partner[2 * b1 + (edges.v0[e1] == v ? 0 : 1)] = b2;
    partner[2 * b2 + (edges.v0[e2] == v ? 0 : 1)] = b1;
  };

  // Per-vertex link analysis. Scratch arrays are indexed by the neighbour's local number.
  std::fill(stamp.begin(), stamp.end(), kNoVertex);
  std::vector<uint32_t> degree;  // Link degree = faces around v containing the neighbour.
  std::vector<size_t> edge_of;   // Edge joining v and the neighbour.
  std::vector<size_t> pending;   // Per link component: an unpaired boundary edge.
  std::vector<size_t> leftover;
  UnionFind link;
  size_t interior_count[kValenceShareColumns] = {0, 0, 0, 0, 0, 0, 0};
  for (size_t v = 0; v < n; ++v) {
    if (corners.begin[v] == corners.begin[v + 1]) continue;
    ++report.vertices;
    const uint32_t v32 = static_cast<uint32_t>(v);
    const size_t max_neighbours = 2 * (corners.begin[v + 1] - corners.begin[v]);
    degree.clear();
    edge_of.clear();
    link.Reset(max_neighbours);
    auto local_of = [&](uint32_t w, size_t halfedge) {
      if (stamp[w] != v32) {
        stamp[w] = v32;
        local[w] = degree.size();
        degree.push_back(0);
        edge_of.push_back(edges.of_halfedge[halfedge]);
      }
      return local[w];
    };
    for (size_t i = corners.begin[v]; i < corners.begin[v + 1]; ++i) {
      const size_t c = corners.corner[i];
      const size_t f = c / 3, k = c % 3;
      const size_t a = local_of(faces[f][(k + 1) % 3], c);
      const size_t b = local_of(faces[f][(k + 2) % 3], 3 * f + (k + 2) % 3);
      ++degree[a];
      ++degree[b];
      link.Union(a, b);
    }
    const size_t valence = degree.size();
    ++report.valence_histogram[static_cast<int>(valence)];

    size_t link_components = 0;
    bool branching = false, on_boundary = false;
    for (size_t i = 0; i < valence; ++i) {
      if (link.Find(i) == i) ++link_components;
      branching |= degree[i] > 2;
      on_boundary |= degree[i] == 1;
    }
    // One path (half-disc) or one cycle (disc); a branching link means a non-manifold edge.
    if (link_components != 1 || branching) ++report.non_manifold_vertices;
    if (!on_boundary) {
      ++report.interior_vertices;
      ++interior_count[ValenceColumn(static_cast<int>(valence))];
      continue;
    }

    // The two ends of a fan's path are the boundary edges that meet at v within that fan.
    pending.assign(valence, kNone);
    leftover.clear();
    for (size_t i = 0; i < valence; ++i) {
      if (degree[i] != 1) continue;
      const size_t root = link.Find(i);
      if (pending[root] == kNone) {
        pending[root] = edge_of[i];
      } else {
        pair_at(v32, pending[root], edge_of[i]);
        pending[root] = kNone;
      }
    }
    for (size_t i = 0; i < valence; ++i) {
      if (pending[i] != kNone) leftover.push_back(pending[i]);
    }
    for (size_t i = 0; i + 1 < leftover.size(); i += 2) pair_at(v32, leftover[i], leftover[i + 1]);
  }
  report.isolated_vertices = n - report.vertices;
  report.edge_manifold = report.non_manifold_edges == 0;
  report.vertex_manifold = report.non_manifold_vertices == 0;
  report.oriented = report.misoriented_edges == 0;
  report.closed = report.boundary_edges == 0;

  if (report.interior_vertices > 0) {
    for (int i = 0; i < kValenceShareColumns; ++i) {
      report.valence_share[i] =
          100.0 * static_cast<double>(interior_count[i]) / report.interior_vertices;
    }
  }
  report.valence6_share = report.valence_share[2];

  // Components over the vertices, then per-component V, E, F and boundary loops.
  UnionFind components;
  components.Reset(n);
  for (const Face& f : faces) {
    components.Union(f[0], f[1]);
    components.Union(f[1], f[2]);
  }
  std::vector<size_t> component_of(n, kNone);
  for (size_t v = 0; v < n; ++v) {
    if (corners.begin[v] == corners.begin[v + 1]) continue;
    const size_t root = components.Find(v);
    if (component_of[root] == kNone) component_of[root] = report.components++;
    component_of[v] = component_of[root];
  }
  std::vector<int64_t> chi(report.components, 0);
  std::vector<int64_t> loops(report.components, 0);
  for (size_t v = 0; v < n; ++v) {
    if (component_of[v] != kNone) ++chi[component_of[v]];
  }
  for (size_t e = 0; e < num_edges; ++e) --chi[component_of[edges.v0[e]]];
  for (const Face& f : faces) ++chi[component_of[f[0]]];

  // Walks boundary edges through their pairings from `start`, leaving it through endpoint
  // `side`; returns the number of edges visited.
  std::vector<bool> visited(boundary_edge.size(), false);
  auto walk = [&](size_t start, int side) {
    size_t length = 0;
    size_t current = start;
    while (true) {
      visited[current] = true;
      ++length;
      const size_t e = boundary_edge[current];
      const uint32_t at = side == 0 ? edges.v0[e] : edges.v1[e];
      const size_t next = partner[2 * current + side];
      if (next == kNone || visited[next]) break;
      side = edges.v0[boundary_edge[next]] == at ? 1 : 0;  // Leave by the other endpoint.
      current = next;
    }
    return length;
  };
  auto add_loop = [&](size_t b, size_t length) {
    report.boundary_loop_lengths.push_back(length);
    ++loops[component_of[edges.v0[boundary_edge[b]]]];
  };
  // Open chains first (only around non-manifold edges), from their free end; then cycles.
  for (size_t b = 0; b < boundary_edge.size(); ++b) {
    if (visited[b]) continue;
    const bool free0 = partner[2 * b] == kNone, free1 = partner[2 * b + 1] == kNone;
    if (free0 || free1) add_loop(b, walk(b, free0 ? 1 : 0));
  }
  for (size_t b = 0; b < boundary_edge.size(); ++b) {
    if (!visited[b]) add_loop(b, walk(b, 1));
  }
  std::sort(report.boundary_loop_lengths.begin(), report.boundary_loop_lengths.end(),
            std::greater<size_t>());
  report.boundary_loops = report.boundary_loop_lengths.size();

  report.euler_characteristic = static_cast<int64_t>(report.vertices) -
                                static_cast<int64_t>(report.edges) +
                                static_cast<int64_t>(report.faces);
  report.genus = 0;
  if (!report.manifold() || !report.oriented) {
    report.genus = -1;
  } else {
    for (size_t i = 0; i < report.components; ++i) {
      const int64_t twice_genus = 2 - chi[i] - loops[i];
      // Cannot happen for an oriented manifold; kept so a bug never reports a bogus genus.
      if (twice_genus < 0 || twice_genus % 2 != 0) {
        report.genus = -1;
        break;
      }
      report.genus += static_cast<int>(twice_genus / 2);
    }
  }
  return report;
}

std::string MeshReportToText(const MeshReport& r) {
  auto yes_no = [](bool b) { return b ? "yes" : "no"; };
  std::string out;
  absl::StrAppendFormat(&out, "%-22s %10u  (%u isolated)\n", "vertices", r.vertices,
                        r.isolated_vertices);
  if (r.faces == 0 && r.isolated_vertices > 0) {
    out += "(no faces: a point cloud; the counts below describe an empty surface)\n";
  }
  absl::StrAppendFormat(&out, "%-22s %10u  (%u degenerate, %u duplicate, %u invalid)\n", "faces",
                        r.faces, r.degenerate_faces, r.duplicate_faces, r.invalid_faces);
  absl::StrAppendFormat(&out, "%-22s %10u  (%u boundary, %u non-manifold, %u misoriented)\n",
                        "edges", r.edges, r.boundary_edges, r.non_manifold_edges,
                        r.misoriented_edges);
  absl::StrAppendFormat(&out, "%-22s %10u\n", "components", r.components);
  absl::StrAppendFormat(&out, "%-22s %10d\n", "euler characteristic", r.euler_characteristic);
  if (r.genus >= 0) {
    absl::StrAppendFormat(&out, "%-22s %10d\n", "genus", r.genus);
  } else {
    absl::StrAppendFormat(&out, "%-22s %10s  (not an oriented manifold)\n", "genus", "-");
  }
  constexpr size_t kMaxLengths = 8;
  std::vector<size_t> shown(
      r.boundary_loop_lengths.begin(),
      r.boundary_loop_lengths.begin() + std::min(kMaxLengths, r.boundary_loop_lengths.size()));
  absl::StrAppendFormat(&out, "%-22s %10u", "boundary loops", r.boundary_loops);
  if (!shown.empty()) {
    absl::StrAppend(&out, "  (lengths ", absl::StrJoin(shown, ", "),
                    r.boundary_loop_lengths.size() > kMaxLengths ? ", ..." : "", ")");
  }
  out += "\n";
  // Every reason manifold() can be false is named, faces that are not triangles included.
  absl::StrAppendFormat(&out, "%-22s %10s  (edge: %s, vertex: %s, %u non-manifold vertices",
                        "manifold", yes_no(r.manifold()), yes_no(r.edge_manifold),
                        yes_no(r.vertex_manifold), r.non_manifold_vertices);
  if (r.degenerate_faces > 0) absl::StrAppend(&out, ", ", r.degenerate_faces, " degenerate faces");
  if (r.invalid_faces > 0) absl::StrAppend(&out, ", ", r.invalid_faces, " invalid faces");
  out += ")\n";
  absl::StrAppendFormat(&out, "%-22s %10s\n", "oriented", yes_no(r.oriented));
  absl::StrAppendFormat(&out, "%-22s %10s\n", "closed", yes_no(r.closed));
  absl::StrAppendFormat(&out, "%-22s %10s\n", "colours", yes_no(r.colored));
  // Both rows' labels get the width of the longer one, so the columns stay under each other.
  const std::string valence_label = absl::StrCat("valence (", r.interior_vertices, " interior)");
  const int label_width = std::max<int>(22, static_cast<int>(valence_label.size()));
  absl::StrAppendFormat(&out, "%-*s %7d %7d %7d %7d %7d %7d %7s\n", label_width, valence_label, 4,
                        5, 6, 7, 8, 9, "other");
  absl::StrAppendFormat(&out, "%-*s", label_width, "share %");
  for (double share : r.valence_share) absl::StrAppendFormat(&out, " %7.1f", share);
  out += "\n";
  return out;
}

std::string MeshReportToJson(const MeshReport& r, int indent) {
  static constexpr const char* kColumns[] = {"4", "5", "6", "7", "8", "9", "other"};
  static_assert(sizeof(kColumns) / sizeof(kColumns[0]) == kValenceShareColumns);
  JsonWriter json(indent);
  json.BeginObject();
  json.Key("vertices").Uint(r.vertices);
  json.Key("faces").Uint(r.faces);
  json.Key("edges").Uint(r.edges);
  json.Key("isolated_vertices").Uint(r.isolated_vertices);
  json.Key("degenerate_faces").Uint(r.degenerate_faces);
  json.Key("invalid_faces").Uint(r.invalid_faces);
  json.Key("duplicate_faces").Uint(r.duplicate_faces);
  json.Key("valence_histogram").BeginObject();
  for (const auto& [valence, count] : r.valence_histogram) {
    json.Key(absl::StrCat(valence)).Uint(count);
  }
  json.EndObject();
  json.Key("valence_share").BeginObject();
  for (int i = 0; i < kValenceShareColumns; ++i) json.Key(kColumns[i]).Double(r.valence_share[i]);
  json.EndObject();
  json.Key("valence6_share").Double(r.valence6_share);
  json.Key("interior_vertices").Uint(r.interior_vertices);
  json.Key("boundary_edges").Uint(r.boundary_edges);
  json.Key("boundary_loops").Uint(r.boundary_loops);
  json.Key("boundary_loop_lengths").BeginArray();
  for (size_t length : r.boundary_loop_lengths) json.Uint(length);
  json.EndArray();
  json.Key("components").Uint(r.components);
  json.Key("euler_characteristic").Int(r.euler_characteristic);
  json.Key("genus").Int(r.genus);
  json.Key("closed").Bool(r.closed);
  json.Key("manifold").Bool(r.manifold());
  json.Key("edge_manifold").Bool(r.edge_manifold);
  json.Key("vertex_manifold").Bool(r.vertex_manifold);
  json.Key("oriented").Bool(r.oriented);
  json.Key("non_manifold_edges").Uint(r.non_manifold_edges);
  json.Key("non_manifold_vertices").Uint(r.non_manifold_vertices);
  json.Key("misoriented_edges").Uint(r.misoriented_edges);
  json.Key("colored").Bool(r.colored);
  json.EndObject();
  // The calls above always form one complete object; Finish() cannot fail here.
  absl::StatusOr<std::string> text = json.Finish();
  return text.ok() ? *std::move(text) : std::string();
}

}  // namespace neuralmesh
