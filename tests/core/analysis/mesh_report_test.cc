#include "core/analysis/mesh_report.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "gtest/gtest.h"
#include "core/analysis/json_reader.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using ::neuralmesh::testing::GridPatch;
using ::neuralmesh::testing::Icosphere;
using ::neuralmesh::testing::MustToMesh;

// Appends `b` to `a`, renumbering its vertices.
void Append(TriangleMesh& a, const TriangleMesh& b, const Vec3f& offset) {
  const uint32_t base = static_cast<uint32_t>(a.positions.size());
  for (const Vec3f& p : b.positions) a.positions.push_back(p + offset);
  for (const auto& f : b.faces) a.faces.push_back({f[0] + base, f[1] + base, f[2] + base});
}

// An n x m grid on a torus (both directions wrap): closed, genus 1, every vertex of valence 6.
TriangleMesh TorusGrid(int n, int m, double major = 2.0, double minor = 0.5) {
  TriangleMesh mesh;
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < n; ++i) {
      const double u = 2.0 * M_PI * i / n, v = 2.0 * M_PI * j / m;
      mesh.positions.emplace_back((major + minor * std::cos(v)) * std::cos(u),
                                  (major + minor * std::cos(v)) * std::sin(u), minor * std::sin(v));
    }
  }
  auto id = [&](int i, int j) { return static_cast<uint32_t>((j % m) * n + (i % n)); };
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < n; ++i) {
      mesh.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return mesh;
}

// An open cylinder of n segments around and m rows: an annulus with two boundary loops of n.
TriangleMesh OpenCylinder(int n, int m) {
  TriangleMesh mesh;
  for (int j = 0; j <= m; ++j) {
    for (int i = 0; i < n; ++i) {
      const double u = 2.0 * M_PI * i / n;
      mesh.positions.emplace_back(std::cos(u), std::sin(u), static_cast<double>(j) / m);
    }
  }
  auto id = [&](int i, int j) { return static_cast<uint32_t>(j * n + (i % n)); };
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < n; ++i) {
      mesh.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return mesh;
}

// The outward-oriented boundary surface of a set of unit voxels, two triangles per exposed
// voxel face, vertices shared through their integer coordinates.
TriangleMesh VoxelSurface(const std::set<std::array<int, 3>>& cells) {
  TriangleMesh mesh;
  std::map<std::array<int, 3>, uint32_t> index;
  auto vertex = [&](std::array<int, 3> p) {
    auto [it, inserted] = index.emplace(p, static_cast<uint32_t>(mesh.positions.size()));
    if (inserted) mesh.positions.emplace_back(p[0], p[1], p[2]);
    return it->second;
  };
  for (const auto& cell : cells) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int dir : {-1, 1}) {
        std::array<int, 3> neighbour = cell;
        neighbour[axis] += dir;
        if (cells.count(neighbour)) continue;
        // Corners of the face in the (u, v) plane; e_u x e_v = e_axis, so this order is
        // counter-clockwise seen from +axis.
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        std::array<int, 3> base = cell;
        if (dir > 0) base[axis] += 1;
        std::array<uint32_t, 4> quad;
        const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
        for (int k = 0; k < 4; ++k) {
          std::array<int, 3> p = base;
          p[u] += du[k];
          p[v] += dv[k];
          quad[k] = vertex(p);
        }
        if (dir < 0) std::swap(quad[1], quad[3]);
        mesh.faces.push_back({quad[0], quad[1], quad[2]});
        mesh.faces.push_back({quad[0], quad[2], quad[3]});
      }
    }
  }
  return mesh;
}

// A 5 x 3 x 1 slab of voxels with two holes punched through it: a genus-2 closed surface.
TriangleMesh GenusTwoSlab() {
  std::set<std::array<int, 3>> cells;
  for (int x = 0; x < 5; ++x) {
    for (int y = 0; y < 3; ++y) {
      if (y == 1 && (x == 1 || x == 3)) continue;
      cells.insert({x, y, 0});
    }
  }
  return VoxelSurface(cells);
}

// Two closed cones (n-gon base with a centre vertex) sharing their apex, vertex 0.
TriangleMesh DoubleCone(int n) {
  TriangleMesh mesh;
  mesh.positions.emplace_back(0.f, 0.f, 0.f);
  for (int side : {1, -1}) {
    const uint32_t ring = static_cast<uint32_t>(mesh.positions.size());
    for (int i = 0; i < n; ++i) {
      const double u = 2.0 * M_PI * i / n;
      mesh.positions.emplace_back(std::cos(u), std::sin(u), side);
    }
    const uint32_t centre = static_cast<uint32_t>(mesh.positions.size());
    mesh.positions.emplace_back(0.f, 0.f, 2.f * side);
    for (int i = 0; i < n; ++i) {
      const uint32_t a = ring + i, b = ring + (i + 1) % n;
      if (side > 0) {
        mesh.faces.push_back({0, b, a});
        mesh.faces.push_back({centre, a, b});
      } else {
        mesh.faces.push_back({0, a, b});
        mesh.faces.push_back({centre, b, a});
      }
    }
  }
  return mesh;
}

size_t HistogramTotal(const MeshReport& r) {
  size_t total = 0;
  for (const auto& [valence, count] : r.valence_histogram) total += count;
  return total;
}

TEST(MeshReportTest, IcosphereIsClosedGenusZeroWithTwelveValenceFive) {
  const TriangleMesh sphere = Icosphere(2);
  const MeshReport r = ComputeMeshReport(sphere);
  EXPECT_EQ(r.vertices, 162u) << "icosphere(2) has 162 vertices";
  EXPECT_EQ(r.faces, 320u) << "icosphere(2) has 320 faces";
  EXPECT_EQ(r.edges, 480u) << "icosphere(2) has 480 edges";
  EXPECT_EQ(r.isolated_vertices, 0u) << "no isolated vertex expected";
  EXPECT_EQ(r.euler_characteristic, 2) << "a sphere has chi = 2";
  EXPECT_EQ(r.genus, 0) << "a sphere has genus 0";
  EXPECT_EQ(r.components, 1u) << "one connected sphere";
  EXPECT_TRUE(r.closed) << "the icosphere has no boundary";
  EXPECT_EQ(r.boundary_loops, 0u) << "no boundary loop expected";
  EXPECT_TRUE(r.manifold()) << "the icosphere is manifold";
  EXPECT_TRUE(r.oriented) << "the icosphere is consistently oriented";
  EXPECT_EQ(r.duplicate_faces, 0u) << "no duplicate faces expected";
  EXPECT_EQ(r.valence_histogram.size(), 2u) << "only valences 5 and 6 expected";
  EXPECT_EQ(r.valence_histogram.count(5) ? r.valence_histogram.at(5) : 0, 12u)
      << "exactly the 12 original icosahedron vertices have valence 5";
  EXPECT_EQ(r.valence_histogram.count(6) ? r.valence_histogram.at(6) : 0, 150u)
      << "every other vertex has valence 6";
  EXPECT_EQ(r.interior_vertices, 162u) << "every vertex of a closed mesh is interior";
  EXPECT_NEAR(r.valence_share[1], 100.0 * 12 / 162, 1e-9) << "valence-5 share wrong";
  EXPECT_NEAR(r.valence_share[2], 100.0 * 150 / 162, 1e-9) << "valence-6 share wrong";
  EXPECT_EQ(r.valence6_share, r.valence_share[2]) << "valence6_share must mirror column 6";
  for (int i : {0, 3, 4, 5, 6}) {
    EXPECT_EQ(r.valence_share[i], 0.0) << "unexpected share in column " << i;
  }
}

TEST(MeshReportTest, GridPatchHasOneBoundaryLoopOfPerimeterLength) {
  const int nx = 7, ny = 4;
  const MeshReport r = ComputeMeshReport(GridPatch(nx, ny));
  EXPECT_EQ(r.vertices, static_cast<size_t>((nx + 1) * (ny + 1))) << "grid vertex count";
  EXPECT_EQ(r.faces, static_cast<size_t>(2 * nx * ny)) << "grid face count";
  EXPECT_EQ(r.boundary_loops, 1u) << "a disc has one boundary loop";
  ASSERT_EQ(r.boundary_loop_lengths.size(), 1u) << "one loop length expected";
  EXPECT_EQ(r.boundary_loop_lengths[0], static_cast<size_t>(2 * (nx + ny)))
      << "the loop runs around the perimeter";
  EXPECT_EQ(r.boundary_edges, static_cast<size_t>(2 * (nx + ny))) << "perimeter edges";
  EXPECT_EQ(r.euler_characteristic, 1) << "a disc has chi = 1";
  EXPECT_EQ(r.genus, 0) << "a disc has genus 0";
  EXPECT_FALSE(r.closed) << "a grid patch has a boundary";
  EXPECT_TRUE(r.manifold()) << "a grid patch is manifold";
  EXPECT_TRUE(r.oriented) << "a grid patch is consistently oriented";
  EXPECT_EQ(r.interior_vertices, static_cast<size_t>((nx - 1) * (ny - 1)))
      << "shares must be taken over interior vertices only";
  EXPECT_DOUBLE_EQ(r.valence6_share, 100.0) << "all interior grid vertices have valence 6";
  EXPECT_EQ(HistogramTotal(r), r.vertices) << "the histogram covers every vertex";
}

TEST(MeshReportTest, TorusGridIsClosedGenusOne) {
  const TriangleMesh torus = TorusGrid(12, 8);
  MustToMesh(torus);  // OpenMesh agrees it is an oriented manifold.
  const MeshReport r = ComputeMeshReport(torus);
  EXPECT_EQ(r.euler_characteristic, 0) << "a torus has chi = 0";
  EXPECT_EQ(r.genus, 1) << "a torus has genus 1";
  EXPECT_TRUE(r.closed) << "the torus grid wraps in both directions";
  EXPECT_TRUE(r.manifold() && r.oriented) << "the torus grid is an oriented manifold";
  EXPECT_EQ(r.components, 1u) << "one torus";
  EXPECT_DOUBLE_EQ(r.valence6_share, 100.0) << "a regular torus grid is all valence 6";
}

TEST(MeshReportTest, SlabWithTwoHolesIsGenusTwo) {
  const TriangleMesh slab = GenusTwoSlab();
  MustToMesh(slab);  // OpenMesh agrees it is an oriented manifold.
  const MeshReport r = ComputeMeshReport(slab);
  EXPECT_EQ(r.euler_characteristic, -2) << "a genus-2 surface has chi = -2";
  EXPECT_EQ(r.genus, 2) << "two holes through a slab give genus 2";
  EXPECT_TRUE(r.closed) << "the voxel surface is closed";
  EXPECT_TRUE(r.manifold()) << "the voxel surface has no diagonal-only contacts";
  EXPECT_TRUE(r.oriented) << "the voxel faces are all oriented outwards";
  EXPECT_EQ(r.components, 1u) << "one connected slab";
}

TEST(MeshReportTest, TwoDisjointSpheresAreTwoComponents) {
  TriangleMesh mesh = Icosphere(1);
  Append(mesh, Icosphere(2), Vec3f(5.f, 0.f, 0.f));
  const MeshReport r = ComputeMeshReport(mesh);
  EXPECT_EQ(r.components, 2u) << "two spheres far apart";
  EXPECT_EQ(r.euler_characteristic, 4) << "chi adds over components";
  EXPECT_EQ(r.genus, 0) << "genus adds over components";
  EXPECT_TRUE(r.closed && r.manifold() && r.oriented) << "each sphere is a closed manifold";
}

TEST(MeshReportTest, ThreeFacesOnOneEdgeIsNonManifoldEdge) {
  TriangleMesh mesh = Icosphere(1);
  // A fin: a third face on the edge of face 0, towards a new vertex.
  const auto f0 = mesh.faces[0];
  mesh.positions.push_back(mesh.positions[f0[0]] * 2.f);
  mesh.faces.push_back({f0[1], f0[0], static_cast<uint32_t>(mesh.positions.size() - 1)});
  const MeshReport r = ComputeMeshReport(mesh);
  EXPECT_FALSE(r.edge_manifold) << "an edge in three faces must be flagged";
  EXPECT_EQ(r.non_manifold_edges, 1u) << "exactly one edge has three faces";
  EXPECT_FALSE(r.vertex_manifold) << "the fin's edge endpoints have no single fan";
  EXPECT_EQ(r.non_manifold_vertices, 2u) << "both endpoints of the fin's edge";
  EXPECT_FALSE(r.manifold()) << "manifold() must be false";
  EXPECT_EQ(r.genus, -1) << "genus is -1 for a non-manifold mesh";
  EXPECT_EQ(r.boundary_edges, 2u) << "the fin's two free edges";
  EXPECT_EQ(r.boundary_loops, 1u) << "the fin's free edges form one chain";
  EXPECT_FALSE(r.closed) << "the fin has free edges";
}

TEST(MeshReportTest, DoubleConeTipToTipIsPinchedVertex) {
  const MeshReport r = ComputeMeshReport(DoubleCone(6));
  EXPECT_TRUE(r.edge_manifold) << "every edge of the double cone is in two faces";
  EXPECT_FALSE(r.vertex_manifold) << "the shared apex has two fans";
  EXPECT_EQ(r.non_manifold_vertices, 1u) << "only the apex is pinched";
  EXPECT_FALSE(r.manifold()) << "manifold() must be false with a pinched vertex";
  EXPECT_TRUE(r.closed) << "both cones are closed";
  EXPECT_TRUE(r.oriented) << "both cones are oriented outwards";
  EXPECT_EQ(r.components, 1u) << "the apex joins the cones into one component";
  EXPECT_EQ(r.euler_characteristic, 3) << "two spheres sharing a point: 2 + 2 - 1";
  EXPECT_EQ(r.genus, -1) << "genus is -1 for a non-manifold mesh";
}

TEST(MeshReportTest, BoundaryLoopsThroughAPinchStaySeparate) {
  {
    // Two triangles sharing only vertex 0 (a bow tie).
    TriangleMesh bowtie;
    bowtie.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1, 1, 0), Vec3f(-1, 0, 0),
                        Vec3f(-1, -1, 0)};
    bowtie.faces = {{0, 1, 2}, {0, 3, 4}};
    const MeshReport r = ComputeMeshReport(bowtie);
    EXPECT_EQ(r.boundary_loops, 2u) << "each triangle of the bow tie keeps its own loop";
    EXPECT_EQ(r.boundary_loop_lengths, (std::vector<size_t>{3, 3})) << "two loops of 3";
    EXPECT_EQ(r.non_manifold_vertices, 1u) << "the shared corner is pinched";
    EXPECT_TRUE(r.edge_manifold) << "no edge is shared at all";
  }
  {
    // Two grid patches touching corner to corner: loops of 8 and 12 through one vertex.
    TriangleMesh mesh = GridPatch(2, 2);
    const TriangleMesh other = GridPatch(3, 3);
    const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    // Vertex 0 of `other` becomes the last vertex (corner (1, 1)) of the first patch.
    const uint32_t shared = base - 1;
    std::vector<uint32_t> remap(other.positions.size());
    for (size_t v = 0; v < other.positions.size(); ++v) {
      if (v == 0) {
        remap[v] = shared;
      } else {
        remap[v] = static_cast<uint32_t>(mesh.positions.size());
        mesh.positions.push_back(other.positions[v] + Vec3f(1.f, 1.f, 0.f));
      }
    }
    for (const auto& f : other.faces) mesh.faces.push_back({remap[f[0]], remap[f[1]], remap[f[2]]});
    const MeshReport r = ComputeMeshReport(mesh);
    EXPECT_EQ(r.boundary_loops, 2u) << "corner-touching patches keep two loops";
    EXPECT_EQ(r.boundary_loop_lengths, (std::vector<size_t>{12, 8}))
        << "loops of 2(3+3) and 2(2+2) edges, longest first";
    EXPECT_EQ(r.non_manifold_vertices, 1u) << "the touching corner is pinched";
    EXPECT_EQ(r.components, 1u) << "the shared corner connects the patches";
  }
}

TEST(MeshReportTest, FlippedFaceBreaksOrientation) {
  TriangleMesh mesh = Icosphere(1);
  std::swap(mesh.faces[3][1], mesh.faces[3][2]);
  const MeshReport r = ComputeMeshReport(mesh);
  EXPECT_FALSE(r.oriented) << "a flipped face must be detected";
  EXPECT_EQ(r.misoriented_edges, 3u) << "all three edges of the flipped face disagree";
  EXPECT_TRUE(r.manifold()) << "flipping a face does not change manifoldness";
  EXPECT_EQ(r.genus, -1) << "genus is -1 when not oriented";
  EXPECT_EQ(r.euler_characteristic, 2) << "chi does not depend on orientation";
}

TEST(MeshReportTest, OpenCylinderHasTwoBoundaryLoops) {
  const int n = 10, m = 3;
  const MeshReport r = ComputeMeshReport(OpenCylinder(n, m));
  EXPECT_EQ(r.boundary_loops, 2u) << "an annulus has two boundary loops";
  EXPECT_EQ(r.boundary_loop_lengths, (std::vector<size_t>{10, 10})) << "both rims have n edges";
  EXPECT_EQ(r.boundary_edges, 20u) << "two rims of 10 edges";
  EXPECT_EQ(r.euler_characteristic, 0) << "an annulus has chi = 0";
  EXPECT_EQ(r.genus, 0) << "chi = 2 - 2g - b gives g = 0";
  EXPECT_TRUE(r.manifold() && r.oriented) << "the cylinder is an oriented manifold";
}

TEST(MeshReportTest, CountsIsolatedDegenerateDuplicateAndInvalid) {
  TriangleMesh mesh = GridPatch(2, 2);         // 9 vertices, 8 faces.
  mesh.positions.emplace_back(5.f, 5.f, 5.f);  // Isolated.
  mesh.faces.push_back({0, 0, 1});             // Degenerate.
  mesh.faces.push_back({mesh.faces[0][2], mesh.faces[0][1], mesh.faces[0][0]});  // Duplicate.
  mesh.faces.push_back({0, 1, 999});                                             // Invalid.
  const MeshReport r = ComputeMeshReport(mesh);
  EXPECT_EQ(r.vertices, 9u) << "vertices counts referenced vertices only";
  EXPECT_EQ(r.isolated_vertices, 1u) << "the extra position is isolated";
  EXPECT_EQ(r.faces, 9u) << "faces excludes degenerate and invalid ones, keeps duplicates";
  EXPECT_EQ(r.degenerate_faces, 1u) << "one face repeats an index";
  EXPECT_EQ(r.duplicate_faces, 1u) << "one face repeats the vertex set of face 0";
  EXPECT_EQ(r.invalid_faces, 1u) << "one face is out of range";
  EXPECT_FALSE(r.manifold()) << "degenerate or invalid faces make manifold() false";
  EXPECT_EQ(r.genus, -1) << "genus is -1 when not manifold";
}

TEST(MeshReportTest, PillowOfTwoOppositeTrianglesIsASphere) {
  TriangleMesh pillow;
  pillow.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  pillow.faces = {{0, 1, 2}, {0, 2, 1}};
  const MeshReport r = ComputeMeshReport(pillow);
  EXPECT_EQ(r.duplicate_faces, 1u) << "the back face repeats the front face's vertices";
  EXPECT_TRUE(r.closed && r.manifold() && r.oriented) << "a pillow is a closed manifold";
  EXPECT_EQ(r.euler_characteristic, 2) << "3 - 3 + 2";
  EXPECT_EQ(r.genus, 0) << "a pillow is a sphere";
}

TEST(MeshReportTest, EmptyMeshReportsZeros) {
  const MeshReport r = ComputeMeshReport(TriangleMesh());
  EXPECT_EQ(r.vertices + r.faces + r.edges + r.components + r.boundary_loops, 0u)
      << "an empty mesh has no elements";
  EXPECT_EQ(r.genus, 0) << "no component contributes genus";
  EXPECT_TRUE(r.manifold()) << "an empty mesh is vacuously manifold";
}

TEST(MeshReportTest, TextContainsTableAndKeyFacts) {
  const std::string text = MeshReportToText(ComputeMeshReport(Icosphere(2)));
  for (const char* needle : {"vertices", "genus", "boundary loops", "manifold", "oriented", "other",
                             "share %", "92.6", "7.4"}) {
    EXPECT_NE(text.find(needle), std::string::npos) << "text report lacks \"" << needle << "\":\n"
                                                    << text;
  }
  const std::string open = MeshReportToText(ComputeMeshReport(OpenCylinder(10, 3)));
  EXPECT_NE(open.find("(lengths 10, 10)"), std::string::npos) << "loop lengths missing from:\n"
                                                              << open;
}

TEST(MeshReportTest, TextNamesWhyAMeshWithoutBadEdgesIsNotManifold) {
  TriangleMesh mesh = GridPatch(2, 2);
  mesh.faces.push_back({0, 0, 1});
  mesh.faces.push_back({0, 1, 999});
  const std::string text = MeshReportToText(ComputeMeshReport(mesh));
  EXPECT_NE(text.find("(edge: yes, vertex: yes, 0 non-manifold vertices, 1 degenerate faces, "
                      "1 invalid faces)"),
            std::string::npos)
      << text;
}

TEST(MeshReportTest, TextSaysWhenThereAreNoFaces) {
  TriangleMesh cloud;
  cloud.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
  EXPECT_NE(MeshReportToText(ComputeMeshReport(cloud)).find("no faces: a point cloud"),
            std::string::npos);
  EXPECT_EQ(MeshReportToText(ComputeMeshReport(Icosphere(1))).find("no faces"), std::string::npos);
}

TEST(MeshReportTest, TextValenceColumnsStayAlignedForLargeMeshes) {
  for (const size_t interior : {size_t{12}, size_t{1234567}, size_t{123456789012}}) {
    MeshReport r;
    r.interior_vertices = interior;
    const std::string text = MeshReportToText(r);
    const size_t header = text.find("valence (");
    const size_t shares = text.find("share %");
    ASSERT_NE(header, std::string::npos) << text;
    ASSERT_NE(shares, std::string::npos) << text;
    const size_t header_length = text.find('\n', header) - header;
    const size_t shares_length = text.find('\n', shares) - shares;
    EXPECT_EQ(header_length, shares_length) << "columns shifted:\n" << text;
  }
}

TEST(MeshReportTest, JsonIsValidAndMatchesReport) {
  const MeshReport r = ComputeMeshReport(OpenCylinder(10, 3));
  for (int indent : {0, 2}) {
    const std::string json = MeshReportToJson(r, indent);
    const absl::StatusOr<JsonValue> parsed = ParseJson(json);
    ASSERT_TRUE(parsed.ok()) << "report JSON does not parse (" << parsed.status() << "):\n" << json;
    auto number = [&](const char* key) {
      const JsonValue* v = parsed->Find(key);
      EXPECT_NE(v, nullptr) << "JSON lacks key " << key;
      return v ? v->number : -12345.0;
    };
    EXPECT_EQ(number("vertices"), static_cast<double>(r.vertices)) << "vertices differ";
    EXPECT_EQ(number("faces"), static_cast<double>(r.faces)) << "faces differ";
    EXPECT_EQ(number("edges"), static_cast<double>(r.edges)) << "edges differ";
    EXPECT_EQ(number("genus"), 0.0) << "genus differs";
    EXPECT_EQ(number("euler_characteristic"), 0.0) << "chi differs";
    EXPECT_EQ(number("boundary_loops"), 2.0) << "boundary loops differ";
    EXPECT_EQ(number("valence6_share"), r.valence6_share) << "valence-6 share differs";
    const JsonValue* lengths = parsed->Find("boundary_loop_lengths");
    ASSERT_NE(lengths, nullptr) << "JSON lacks boundary_loop_lengths";
    EXPECT_EQ(lengths->items.size(), 2u) << "two loop lengths expected";
    const JsonValue* shares = parsed->Find("valence_share");
    ASSERT_NE(shares, nullptr) << "JSON lacks valence_share";
    EXPECT_NE(shares->Find("other"), nullptr) << "valence_share lacks the other column";
    const JsonValue* manifold = parsed->Find("manifold");
    ASSERT_NE(manifold, nullptr) << "JSON lacks manifold";
    EXPECT_TRUE(manifold->boolean) << "manifold should be true";
  }
}

TEST(MeshReportTest, MillionFaceTorusIsFast) {
  const TriangleMesh torus = TorusGrid(1000, 500);
  const auto start = std::chrono::steady_clock::now();
  const MeshReport r = ComputeMeshReport(torus);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.faces, 1000000u) << "the torus grid should have 1M faces";
  EXPECT_EQ(r.genus, 1) << "the big torus is still genus 1";
  EXPECT_LT(seconds, 10.0) << "the report of 1M faces took too long";
  RecordProperty("seconds_for_1M_faces", std::to_string(seconds));
}

TEST(MeshReportTest, SaysWhetherEveryVertexHasAColour) {
  TriangleMesh mesh = Icosphere(1);
  MeshReport report = ComputeMeshReport(mesh);
  EXPECT_FALSE(report.colored);
  EXPECT_NE(MeshReportToText(report).find("colours                        no"), std::string::npos)
      << MeshReportToText(report);
  mesh.colors.assign(mesh.positions.size(), Rgb{1, 2, 3});
  report = ComputeMeshReport(mesh);
  EXPECT_TRUE(report.colored);
  const absl::StatusOr<JsonValue> json = ParseJson(MeshReportToJson(report));
  ASSERT_TRUE(json.ok()) << json.status();
  ASSERT_NE(json->Find("colored"), nullptr);
  EXPECT_TRUE(json->Find("colored")->boolean);
  mesh.colors.pop_back();  // Not one per vertex: not a coloured mesh.
  EXPECT_FALSE(ComputeMeshReport(mesh).colored);
}

}  // namespace
}  // namespace neuralmesh
