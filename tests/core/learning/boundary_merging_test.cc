#include "core/learning/boundary_merging.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/learning/triangle_removal.h"
#include "core/mesh_validation.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using testing::Icosphere;
using testing::MustToMesh;
using testing::TorusWithBridgedHoles;

// Appends an open tube around the z axis: `rings` rings from z0 to z1 with radius `radius`,
// each with a vertex at every angle of `degrees` (increasing), faces counter-clockwise seen
// from outside.
void AppendTube(TriangleMesh& out, const std::vector<double>& degrees, int rings, double radius,
                double z0, double z1) {
  const uint32_t base = static_cast<uint32_t>(out.positions.size());
  const int around = static_cast<int>(degrees.size());
  for (int r = 0; r < rings; ++r) {
    const double z = z0 + (z1 - z0) * r / (rings - 1);
    for (const double d : degrees) {
      const double a = d * M_PI / 180;
      out.positions.emplace_back(static_cast<float>(radius * std::cos(a)),
                                 static_cast<float>(radius * std::sin(a)), static_cast<float>(z));
    }
  }
  auto id = [&](int r, int j) { return base + static_cast<uint32_t>(r * around + j % around); };
  for (int r = 0; r + 1 < rings; ++r) {
    for (int j = 0; j < around; ++j) {
      out.faces.push_back({id(r, j), id(r, j + 1), id(r + 1, j + 1)});
      out.faces.push_back({id(r, j), id(r + 1, j + 1), id(r + 1, j)});
    }
  }
}

// The same with `around` evenly spaced vertices per ring, the first at angle `phase` (radians).
void AppendTube(TriangleMesh& out, int around, int rings, double radius, double z0, double z1,
                double phase) {
  std::vector<double> degrees;
  for (int j = 0; j < around; ++j) degrees.push_back((phase + 2 * M_PI * j / around) * 180 / M_PI);
  AppendTube(out, degrees, rings, radius, z0, z1);
}

// A torus (radii 3 and 1 around the z axis) with a slice cut out: `rings` rings of `around`
// vertices at angles 0 .. 2 pi - gap around the axis, faces counter-clockwise from outside.
TriangleMesh BentTube(int rings, int around, double gap) {
  TriangleMesh out;
  for (int i = 0; i < rings; ++i) {
    const double u = (2 * M_PI - gap) * i / (rings - 1);
    for (int j = 0; j < around; ++j) {
      const double v = 2 * M_PI * j / around;
      const double w = 3 + std::cos(v);
      out.positions.emplace_back(static_cast<float>(w * std::cos(u)),
                                 static_cast<float>(w * std::sin(u)),
                                 static_cast<float>(std::sin(v)));
    }
  }
  auto id = [&](int i, int j) { return static_cast<uint32_t>(i * around + j % around); };
  for (int i = 0; i + 1 < rings; ++i) {
    for (int j = 0; j < around; ++j) {
      out.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      out.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return out;
}

BoundaryMergingOptions AlphaM(double alpha_m) {
  BoundaryMergingOptions options;
  options.alpha_m = alpha_m;
  return options;
}

struct Counts {
  size_t vertices = 0;
  size_t edges = 0;
  size_t faces = 0;
  size_t boundary_loops = 0;
  size_t components = 0;
  long euler() const {
    return static_cast<long>(vertices) - static_cast<long>(edges) + static_cast<long>(faces);
  }
};

Counts Count(const Mesh& mesh) {
  Counts c;
  for (auto vh : mesh.vertices()) (void)vh, ++c.vertices;
  for (auto eh : mesh.edges()) (void)eh, ++c.edges;
  for (auto fh : mesh.faces()) (void)fh, ++c.faces;
  std::vector<bool> seen(mesh.n_halfedges(), false);
  for (auto start : mesh.halfedges()) {
    if (seen[start.idx()] || !mesh.is_boundary(start)) continue;
    ++c.boundary_loops;
    auto h = start;
    do {
      seen[h.idx()] = true;
      h = mesh.next_halfedge_handle(h);
    } while (h != start);
  }
  std::vector<bool> reached(mesh.n_faces(), false);
  for (auto seed : mesh.faces()) {
    if (reached[seed.idx()]) continue;
    ++c.components;
    std::vector<Mesh::FaceHandle> stack = {seed};
    reached[seed.idx()] = true;
    while (!stack.empty()) {
      const auto fh = stack.back();
      stack.pop_back();
      for (auto neighbour : mesh.ff_range(fh)) {
        if (reached[neighbour.idx()]) continue;
        reached[neighbour.idx()] = true;
        stack.push_back(neighbour);
      }
    }
  }
  return c;
}

// Independent of the half-edge structure: in the exported triangles no directed edge may
// appear twice, and every edge with two faces must be used in both directions.
std::string OrientationProblem(const Mesh& mesh) {
  const TriangleMesh triangles = ToTriangleMesh(mesh);
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& f : triangles.faces) {
    for (int k = 0; k < 3; ++k) ++directed[{f[k], f[(k + 1) % 3]}];
  }
  for (const auto& [edge, count] : directed) {
    if (count > 1) return "a directed edge is used by two faces";
  }
  return "";
}

// Whether every face's normal points away from the z axis (tubes built by AppendTube).
bool FacesPointAwayFromTheAxis(const Mesh& mesh) {
  for (auto fh : mesh.faces()) {
    std::vector<Vec3> p;
    for (auto vh : mesh.fv_range(fh)) p.push_back(mesh.point(vh));
    const Vec3 normal = OpenMesh::cross(p[1] - p[0], p[2] - p[0]);
    const Vec3 centre = (p[0] + p[1] + p[2]) / 3.0;
    if (normal[0] * centre[0] + normal[1] * centre[1] <= 0) return false;
  }
  return true;
}

TEST(BoundaryMergingTest, OptionsValidate) {
  EXPECT_TRUE(BoundaryMergingOptions{}.Validate().ok()) << "the paper's alpha_m = 5 is valid";
  EXPECT_TRUE(AlphaM(0).Validate().ok()) << "alpha_m = 0 (never merge) is valid";
  EXPECT_FALSE(AlphaM(-1).Validate().ok()) << "negative alpha_m accepted";
  EXPECT_FALSE(AlphaM(INFINITY).Validate().ok()) << "infinite alpha_m accepted";
  BoundaryMergingOptions two;
  two.min_loop_vertices = 2;
  EXPECT_FALSE(two.Validate().ok()) << "a loop has at least 3 vertices";
}

TEST(BoundaryMergingTest, FacingTubesBecomeOneTube) {
  TriangleMesh shape;
  AppendTube(shape, 12, 7, 1.0, 0.0, 3.0, 0.0);
  AppendTube(shape, 12, 7, 1.0, 3.2, 6.2, 0.1);
  Mesh mesh = MustToMesh(shape);
  const Counts before = Count(mesh);
  ASSERT_EQ(before.boundary_loops, 4u) << "two open tubes have four rims";
  ASSERT_EQ(before.components, 2u) << "two tubes";

  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0);
  EXPECT_EQ(result.merges, 1u) << "only the facing rims are close";
  EXPECT_EQ(result.added_faces, 24u) << "a strip between two 12-gons has 24 faces";
  const Counts after = Count(mesh);
  EXPECT_EQ(after.boundary_loops, 2u) << "the merged tube keeps its two outer rims";
  EXPECT_EQ(after.components, 1u) << "the tubes must be joined";
  EXPECT_EQ(after.vertices, before.vertices) << "merging adds no vertex";
  EXPECT_EQ(OrientationProblem(mesh), "") << "the strip must be oriented like both tubes";
  EXPECT_TRUE(FacesPointAwayFromTheAxis(mesh)) << "the strip must face outward, not twist";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(BoundaryMergingTest, LoopsWithDifferentVertexCountsMerge) {
  TriangleMesh shape;
  AppendTube(shape, 12, 7, 1.0, 0.0, 3.0, 0.0);
  AppendTube(shape, 17, 7, 1.0, 3.2, 6.2, 0.3);
  Mesh mesh = MustToMesh(shape);

  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0);
  EXPECT_EQ(result.merges, 1u) << "the facing 12- and 17-gon rims must merge";
  EXPECT_EQ(result.added_faces, 29u) << "the strip uses each of the 12 + 17 rim edges once";
  EXPECT_EQ(result.sewn_vertices.size(), 29u) << "both rims' vertices are reported as sewn";
  for (auto vh : result.sewn_vertices) {
    int strip_faces = 0;
    for (auto f : mesh.vf_range(vh)) {
      int rim_corners = 0;
      for (auto c : mesh.fv_range(f)) {
        rim_corners += std::count(result.sewn_vertices.begin(), result.sewn_vertices.end(), c) > 0;
      }
      strip_faces += rim_corners == 3;
    }
    EXPECT_GE(strip_faces, 1) << "a sewn vertex is a corner of the strip";
  }
  const Counts after = Count(mesh);
  EXPECT_EQ(after.boundary_loops, 2u) << "two outer rims must remain";
  EXPECT_EQ(after.components, 1u) << "the tubes must be joined";
  EXPECT_EQ(OrientationProblem(mesh), "") << "the strip must be oriented like both tubes";
  EXPECT_TRUE(FacesPointAwayFromTheAxis(mesh)) << "the strip must face outward, not twist";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// The smallest quality (4 sqrt(3) area / sum of squared sides, 1 when equilateral) among the
// faces whose three corners are all in `corners`.
double WorstQualityAmong(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& corners) {
  double worst = 1;
  for (auto f : mesh.faces()) {
    std::vector<Vec3> p;
    for (auto c : mesh.fv_range(f)) {
      if (std::count(corners.begin(), corners.end(), c) == 0) break;
      p.push_back(mesh.point(c));
    }
    if (p.size() != 3) continue;
    const double squares =
        (p[1] - p[0]).sqrnorm() + (p[2] - p[1]).sqrnorm() + (p[0] - p[2]).sqrnorm();
    worst = std::min(
        worst, 2 * std::sqrt(3.0) * OpenMesh::cross(p[1] - p[0], p[2] - p[0]).norm() / squares);
  }
  return worst;
}

// Appends a funnel-shaped annulus whose inner rim is `rim` (counter-clockwise seen from +z)
// and whose outer rim is the same points scaled by 1.5 about the z axis and moved 0.3 along
// z, up and with its faces looking up when `up`, down and looking down otherwise.
void AppendAnnulus(TriangleMesh& out, const std::vector<Vec3>& rim, bool up) {
  const uint32_t base = static_cast<uint32_t>(out.positions.size());
  const uint32_t n = static_cast<uint32_t>(rim.size());
  for (const Vec3& p : rim) out.positions.emplace_back(p[0], p[1], p[2]);
  const double lift = up ? 0.3 : -0.3;
  for (const Vec3& p : rim) out.positions.emplace_back(1.5 * p[0], 1.5 * p[1], p[2] + lift);
  for (uint32_t j = 0; j < n; ++j) {
    const uint32_t i0 = base + j, i1 = base + (j + 1) % n, o0 = i0 + n, o1 = i1 + n;
    if (up) {
      out.faces.push_back({i0, o0, o1});
      out.faces.push_back({i0, o1, i1});
    } else {
      out.faces.push_back({i0, o1, o0});
      out.faces.push_back({i0, i1, o1});
    }
  }
}

// The two holes that Step 4 had cut in the membranes over a torus's hole (R = 1, r = 0.4) in
// a reconstruction, at the moment Step 5 merged them, as the rims of two funnels facing each
// other. Adding the locally best triangle from the closest pair on (the paper's rule) met a
// short edge on the upper rim right after a long one: every triangle over the short edge was
// a sliver, so the walk went all the way round the lower rim first and sewed the strip as two
// fans (valences 19 and 21 in that reconstruction, whose strip then tore into holes and an
// extra handle). The strip is now the best over all walks.
TEST(BoundaryMergingTest, UnevenRimsAreSewnWithoutAFan) {
  const std::vector<Vec3> upper = {
      // Counter-clockwise seen from +z.
      {0.168, 0.262, 0.054},   {0.121, 0.294, 0.091},   {-0.350, 0.469, 0.122},
      {-0.516, 0.296, 0.072},  {-0.592, 0.061, 0.075},  {-0.572, -0.178, 0.022},
      {-0.450, -0.390, 0.007}, {-0.265, -0.521, 0.104}, {-0.025, -0.501, 0.060},
      {0.196, -0.389, 0.077},  {0.434, -0.380, 0.007},  {0.567, -0.177, 0.014},
      {0.575, 0.060, 0.026}};
  const std::vector<Vec3> lower = {
      // Counter-clockwise seen from +z.
      {0.433, 0.231, -0.010},   {0.144, 0.549, 0.008},    {-0.037, 0.527, -0.017},
      {-0.198, 0.444, -0.041},  {-0.339, 0.292, -0.060},  {-0.464, -0.125, -0.050},
      {-0.469, -0.338, -0.035}, {-0.157, -0.518, -0.048}, {0.042, -0.530, -0.062},
      {0.219, -0.449, -0.068},  {0.516, -0.319, -0.087},  {0.569, -0.213, -0.059},
      {0.598, -0.085, -0.029},  {0.580, 0.083, -0.030}};
  TriangleMesh shape;
  AppendAnnulus(shape, upper, /*up=*/true);
  AppendAnnulus(shape, lower, /*up=*/false);
  Mesh mesh = MustToMesh(shape);

  // E(Area) = 0.01: the threshold 5 sqrt(E) = 0.5 reaches across (the rims' Hausdorff
  // distance is about 0.2), not to the outer rims (0.6 farther apart).
  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0.01);
  ASSERT_EQ(result.merges, 1u) << "the facing rims must merge";
  EXPECT_EQ(result.added_faces, 27u) << "a strip between a 13-gon and a 14-gon has 27 faces";
  size_t most_strip_faces = 0;
  for (auto vh : result.sewn_vertices) {
    size_t strip_faces = 0;
    for (auto f : mesh.vf_range(vh)) {
      size_t corners = 0;
      for (auto c : mesh.fv_range(f)) {
        corners += std::count(result.sewn_vertices.begin(), result.sewn_vertices.end(), c);
      }
      strip_faces += corners == 3;
    }
    most_strip_faces = std::max(most_strip_faces, strip_faces);
  }
  EXPECT_LE(most_strip_faces, 6u) << "no rim vertex may become the hub of a fan (greedy: 15)";
  EXPECT_GT(WorstQualityAmong(mesh, result.sewn_vertices), 0.2) << "no sliver (greedy: 0.09)";
  EXPECT_EQ(OrientationProblem(mesh), "") << "the strip must be oriented like both tubes";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(BoundaryMergingTest, BentTubeClosesIntoATorus) {
  // 24 rings over 23/24 of the full turn: the cut is as wide as one ring spacing.
  Mesh mesh = MustToMesh(BentTube(24, 12, 2 * M_PI / 24));
  const Counts before = Count(mesh);
  ASSERT_EQ(before.boundary_loops, 2u) << "an open bent tube has two rims";
  ASSERT_EQ(before.euler(), 0) << "a tube is an annulus";

  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0);
  EXPECT_EQ(result.merges, 1u) << "the two ends of the tube must merge";
  EXPECT_EQ(result.added_faces, 24u) << "a strip between two 12-gons has 24 faces";
  const Counts after = Count(mesh);
  EXPECT_EQ(after.boundary_loops, 0u) << "the torus must be closed";
  EXPECT_EQ(after.euler(), 0) << "V - E + F of a torus is 0 (genus 1)";
  EXPECT_EQ(after.components, 1u) << "one torus";
  EXPECT_EQ(OrientationProblem(mesh), "") << "the strip must be oriented like the tube";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(BoundaryMergingTest, DistantLoopsAreLeftAlone) {
  TriangleMesh shape;
  AppendTube(shape, 12, 7, 1.0, 0.0, 3.0, 0.0);
  AppendTube(shape, 12, 7, 1.0, 8.0, 11.0, 0.0);
  Mesh mesh = MustToMesh(shape);
  const Counts before = Count(mesh);

  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0);
  EXPECT_EQ(result.merges, 0u) << "rims 5 apart exceed 5 sqrt(E(Area)) ~ 1.8";
  EXPECT_EQ(result.added_faces, 0u) << "nothing may be added";
  const Counts after = Count(mesh);
  EXPECT_EQ(after.faces, before.faces) << "faces changed";
  EXPECT_EQ(after.boundary_loops, 4u) << "boundaries changed";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(BoundaryMergingTest, ThresholdFollowsTheGivenMeanArea) {
  TriangleMesh shape;
  AppendTube(shape, 12, 7, 1.0, 0.0, 3.0, 0.0);
  AppendTube(shape, 12, 7, 1.0, 3.2, 6.2, 0.0);
  Mesh mesh = MustToMesh(shape);
  // The rims are 0.2 apart; with E(Area) = 1e-4 the threshold is 5 * 0.01 = 0.05.
  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 1e-4);
  EXPECT_EQ(result.merges, 0u) << "the caller's E(Area) must set the threshold";
  EXPECT_EQ(Count(mesh).boundary_loops, 4u) << "boundaries changed";
}

// The learner calls Step 5 with mean_area 0 right after Step 4, whose removed faces are still in
// the mesh, marked deleted (the largest ones: Eq. 2). E(Area) of Eq. 3 must then be the mean of
// the faces that are left. A far tetrahedron of side 100 raises the mean face area from about
// 0.13 to about 60 (threshold 5 sqrt(60) ~ 39), so rims 5 apart merge while it is live, and must
// not once its faces are deleted.
TEST(BoundaryMergingTest, MeasuredMeanAreaLeavesOutDeletedFaces) {
  TriangleMesh shape;
  AppendTube(shape, 12, 7, 1.0, 0.0, 3.0, 0.0);
  AppendTube(shape, 12, 7, 1.0, 8.0, 11.0, 0.0);
  const uint32_t base = static_cast<uint32_t>(shape.positions.size());
  const double side = 100, far = 1000;
  const double h = side / std::sqrt(2.0);  // Corners of a cube of side h: a regular tetrahedron.
  shape.positions.emplace_back(far, 0, 0);
  shape.positions.emplace_back(far + h, h, 0);
  shape.positions.emplace_back(far + h, 0, h);
  shape.positions.emplace_back(far, h, h);
  for (const auto& f :
       std::vector<std::array<uint32_t, 3>>{{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}}) {
    shape.faces.push_back({base + f[0], base + f[1], base + f[2]});
  }

  Mesh live = MustToMesh(shape);
  EXPECT_GE(MergeCloseBoundaries(live, BoundaryMergingOptions{}, 0).merges, 1u)
      << "with the tetrahedron's faces live the threshold is about 39: the rims 5 apart merge";

  Mesh removed = MustToMesh(shape);
  for (auto fh : removed.faces()) {
    if (removed.point(removed.to_vertex_handle(removed.halfedge_handle(fh)))[0] > far / 2) {
      removed.delete_face(fh, /*delete_isolated_vertices=*/true);
    }
  }
  const BoundaryMergingResult result = MergeCloseBoundaries(removed, BoundaryMergingOptions{}, 0);
  EXPECT_EQ(result.merges, 0u) << "deleted faces must not count in E(Area)";
  EXPECT_EQ(Count(removed).boundary_loops, 4u) << "boundaries changed";
  EXPECT_EQ(Count(removed).faces, 2u * 12 * 6 * 2) << "only the tubes' faces are left";
  EXPECT_TRUE(ValidateMesh(removed).ok()) << ValidateMesh(removed);
}

// Tube A's top rim is close to both tube B's bottom rim (0.1) and to the bottom rim of the
// wider, longer tube C around B (about 0.32), and B's bottom rim is close to C's (about 0.22):
// only the closest pair merges, and each of its rims only once.
TEST(BoundaryMergingTest, ClosestPairFirstAndEachLoopOnce) {
  TriangleMesh shape;
  AppendTube(shape, 12, 7, 1.0, 0.0, 3.0, 0.0);  // A
  AppendTube(shape, 12, 7, 1.0, 3.1, 6.1, 0.0);  // B
  AppendTube(shape, 12, 7, 1.1, 3.3, 9.3, 0.2);  // C, around B
  Mesh mesh = MustToMesh(shape);
  const Counts before = Count(mesh);

  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0);
  EXPECT_EQ(result.merges, 1u) << "A's top rim may merge once, with the closest rim (B's)";
  const Counts after = Count(mesh);
  EXPECT_EQ(after.boundary_loops, before.boundary_loops - 2) << "one merge removes two rims";
  EXPECT_EQ(after.components, 2u) << "A and B joined, C alone";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// Two holes cut into one sphere by Step 4, merged by Step 5 on the same mesh with its
// deleted elements: the sphere gains a handle.
TEST(BoundaryMergingTest, TwoHolesOfOneSphereMakeAHandle) {
  Mesh mesh = MustToMesh(Icosphere(2));
  mesh.set_point(Mesh::VertexHandle(0), mesh.point(Mesh::VertexHandle(0)) * 10.0);
  mesh.set_point(Mesh::VertexHandle(3), mesh.point(Mesh::VertexHandle(3)) * 10.0);
  const TriangleRemovalResult removal = RemoveLargeTriangles(mesh, TriangleRemovalOptions{});
  ASSERT_EQ(removal.removed_faces, 10u) << "both spikes must be removed";
  ASSERT_EQ(Count(mesh).boundary_loops, 2u) << "two holes";
  ASSERT_EQ(Count(mesh).euler(), 0) << "a sphere with two holes";

  // The holes are on opposite sides, about 2 apart: alpha_m = 20 reaches across.
  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, AlphaM(20), removal.mean_area);
  EXPECT_EQ(result.merges, 1u) << "the two holes must merge";
  EXPECT_EQ(result.added_faces, 10u) << "a strip between two pentagons has 10 faces";
  const Counts after = Count(mesh);
  EXPECT_EQ(after.boundary_loops, 0u) << "the surface must be closed";
  EXPECT_EQ(after.euler(), 0) << "a sphere with a handle has V - E + F = 0";
  EXPECT_EQ(after.components, 1u) << "still one surface";
  EXPECT_EQ(OrientationProblem(mesh), "") << "the strip must be oriented like the sphere";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// A thin annulus: every triangle joins the outer and the inner triangle, so each inner vertex
// is already joined to two of the three outer ones. A strip needs 5 distinct edges between
// the loops but only 3 pairs are free: the merge must be refused and the mesh left as it was.
TEST(BoundaryMergingTest, MergeThatWouldDuplicateEdgesIsRefused) {
  TriangleMesh shape;
  for (int k = 0; k < 3; ++k) {
    const double a = 2 * M_PI * k / 3;
    shape.positions.emplace_back(static_cast<float>(2 * std::cos(a)),
                                 static_cast<float>(2 * std::sin(a)), 0.f);
  }
  for (int k = 0; k < 3; ++k) {
    const double a = 2 * M_PI * k / 3 + M_PI / 3;
    shape.positions.emplace_back(static_cast<float>(0.5 * std::cos(a)),
                                 static_cast<float>(0.5 * std::sin(a)), 0.f);
  }
  for (uint32_t k = 0; k < 3; ++k) {
    shape.faces.push_back({k, (k + 1) % 3, 3 + k});
    shape.faces.push_back({3 + k, (k + 1) % 3, 3 + (k + 1) % 3});
  }
  Mesh mesh = MustToMesh(shape);
  ASSERT_EQ(Count(mesh).boundary_loops, 2u) << "an annulus has two boundary loops";

  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0);
  EXPECT_EQ(result.merges, 0u) << "no strip exists without duplicating an edge";
  EXPECT_EQ(result.added_faces, 0u) << "nothing may be added";
  EXPECT_EQ(Count(mesh).faces, 6u) << "faces changed";
  EXPECT_EQ(Count(mesh).boundary_loops, 2u) << "boundaries changed";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// 200 seeds of three kinds of jittered cases; every result must pass ValidateMesh.
//  0: two coaxial tubes of 4..20 vertices around, radii and gap (even overlap) at random:
//     the facing rims must merge into one tube.
//  1: a bent tube with a random cut: it must close into a torus.
//  2: a sphere with random spikes, cut by Step 4, then merged by Step 5 with a random alpha_m.
TEST(BoundaryMergingTest, RandomCasesStayValid) {
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    Random random(seed);
    auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * random.NextDouble(); };
    auto jitter = [&](Mesh& mesh, double amount) {
      for (auto vh : mesh.vertices()) {
        mesh.set_point(
            vh, mesh.point(vh) + amount * Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)));
      }
    };
    const int kind = static_cast<int>(seed % 3);
    Mesh mesh;
    if (kind == 0) {
      const int n1 = 4 + static_cast<int>(random.NextIndex(17));
      const int n2 = 4 + static_cast<int>(random.NextIndex(17));
      const double length = 6;
      const double gap = uniform(-0.3, 0.5);
      TriangleMesh shape;
      AppendTube(shape, n1, 13, uniform(0.8, 1.2), 0, length, uniform(0, 2 * M_PI));
      AppendTube(shape, n2, 13, uniform(0.8, 1.2), length + gap, 2 * length + gap,
                 uniform(0, 2 * M_PI));
      mesh = MustToMesh(shape);
      jitter(mesh, 0.05);
      // A threshold below the tube length: only the facing rims can be close enough.
      const double alpha_m = 0.9 * length / std::sqrt(MeanTriangleArea(mesh));
      const BoundaryMergingResult result = MergeCloseBoundaries(mesh, AlphaM(alpha_m), 0);
      EXPECT_EQ(result.merges, 1u) << "seed " << seed << ": facing rims did not merge";
      EXPECT_EQ(result.added_faces, static_cast<size_t>(n1 + n2))
          << "seed " << seed << ": a strip uses each rim edge once";
      const Counts after = Count(mesh);
      EXPECT_EQ(after.components, 1u) << "seed " << seed << ": tubes not joined";
      EXPECT_EQ(after.boundary_loops, 2u) << "seed " << seed << ": rims left";
    } else if (kind == 1) {
      const int rings = 8 + static_cast<int>(random.NextIndex(23));
      const int around = 3 + static_cast<int>(random.NextIndex(10));
      mesh = MustToMesh(BentTube(rings, around, 2 * M_PI / rings * uniform(0.3, 1.5)));
      jitter(mesh, 0.03);
      const BoundaryMergingResult result = MergeCloseBoundaries(mesh, AlphaM(100), 0);
      EXPECT_EQ(result.merges, 1u) << "seed " << seed << ": the tube ends did not merge";
      const Counts after = Count(mesh);
      EXPECT_EQ(after.boundary_loops, 0u) << "seed " << seed << ": torus not closed";
      EXPECT_EQ(after.euler(), 0) << "seed " << seed << ": not a torus";
    } else {
      mesh = MustToMesh(Icosphere(1 + static_cast<int>(random.NextIndex(2))));
      jitter(mesh, 0.02);
      const int spikes = 1 + static_cast<int>(random.NextIndex(6));
      for (int s = 0; s < spikes; ++s) {
        const Mesh::VertexHandle vh(static_cast<int>(random.NextIndex(mesh.n_vertices())));
        mesh.set_point(vh, mesh.point(vh) * uniform(2, 10));
      }
      const TriangleRemovalResult removal =
          RemoveLargeTriangles(mesh, TriangleRemovalOptions{uniform(2, 8)});
      const absl::Status removed_status = ValidateMesh(mesh);
      ASSERT_TRUE(removed_status.ok()) << "seed " << seed << " after removal: " << removed_status;
      const Counts before = Count(mesh);
      const BoundaryMergingResult result =
          MergeCloseBoundaries(mesh, AlphaM(uniform(1, 100)), removal.mean_area);
      const Counts after = Count(mesh);
      EXPECT_EQ(after.boundary_loops, before.boundary_loops - 2 * result.merges)
          << "seed " << seed << ": each merge must close two loops";
      EXPECT_EQ(after.euler(), before.euler())
          << "seed " << seed << ": a strip adds as many edges as faces";
      EXPECT_EQ(after.faces, before.faces + result.added_faces)
          << "seed " << seed << ": added faces miscounted";
    }
    const absl::Status status = ValidateMesh(mesh);
    ASSERT_TRUE(status.ok()) << "seed " << seed << " (kind " << kind << "): " << status;
    EXPECT_EQ(OrientationProblem(mesh), "") << "seed " << seed << ": inconsistent orientation";
  }
}

}  // namespace
}  // namespace neuralmesh

namespace neuralmesh {
namespace {

TEST(BoundaryMergingTest, LoopsThatStepFourIsStillGrowingAreNotMerged) {
  TriangleMesh shape;
  AppendTube(shape, 12, 7, 1.0, 0.0, 3.0, 0.0);
  AppendTube(shape, 12, 7, 1.0, 3.2, 6.2, 0.1);
  Mesh mesh = MustToMesh(shape);
  // Vertex 6 * 12 is on the top rim of the first tube, one of the two facing rims.
  const std::vector<Mesh::VertexHandle> growing = {Mesh::VertexHandle(6 * 12)};
  ASSERT_TRUE(mesh.is_boundary(growing[0]));
  BoundaryMergingResult result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0, growing);
  EXPECT_EQ(result.merges, 0u) << "a rim that Step 4 has just cut into must wait";
  EXPECT_EQ(Count(mesh).boundary_loops, 4u);

  const std::vector<Mesh::VertexHandle> elsewhere = {Mesh::VertexHandle(0)};  // Bottom rim.
  result = MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0, elsewhere);
  EXPECT_EQ(result.merges, 1u) << "growing far rims must not stop the facing rims merging";
  EXPECT_EQ(Count(mesh).boundary_loops, 2u);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// Two facing rims of 3 vertices (the holes one removed triangle leaves): merged by the
// paper's rule, left alone when loops need at least 4 vertices.
TEST(BoundaryMergingTest, LoopsBelowTheMinimumSizeAreNotMerged) {
  TriangleMesh shape;
  AppendTube(shape, 3, 4, 1.0, 0.0, 3.0, 0.0);
  AppendTube(shape, 3, 4, 1.0, 3.2, 6.2, 0.0);
  BoundaryMergingOptions at_least_four;
  at_least_four.min_loop_vertices = 4;
  Mesh mesh = MustToMesh(shape);
  EXPECT_EQ(MergeCloseBoundaries(mesh, at_least_four, 0).merges, 0u) << "3-vertex rims merged";
  EXPECT_EQ(Count(mesh).boundary_loops, 4u);

  EXPECT_EQ(MergeCloseBoundaries(mesh, BoundaryMergingOptions{}, 0).merges, 1u)
      << "the paper's rule merges every loop";
  EXPECT_EQ(Count(mesh).boundary_loops, 2u);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// After a Step 5 call that must have closed every hole: nothing merged, no boundary left, the
// Euler characteristic `euler`, a valid mesh.
void ExpectClosedWithoutMerges(const Mesh& mesh, const BoundaryMergingResult& result, long euler,
                               const char* genus_kept) {
  EXPECT_EQ(result.merges, 0u) << "nothing is left to merge";
  const Counts after = Count(mesh);
  EXPECT_EQ(after.boundary_loops, 0u);
  EXPECT_EQ(after.euler(), euler) << genus_kept;
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(BoundaryMergingTest, SmallHolesAreClosedInsteadOfMergedWhenAsked) {
  // Two one-triangle holes next to each other on a sphere: close enough to merge into a
  // handle, but their triangles are of ordinary size, so they are noise, not boundaries.
  Mesh mesh = MustToMesh(Icosphere(3));
  const double mean_area = MeanTriangleArea(mesh);
  // f1: the face nearest to f0 that shares no vertex nor edge with it, so that removing both
  // is legal and a strip between the two holes can be planned.
  const Mesh::FaceHandle f0(0);
  Mesh::FaceHandle f1;
  double nearest = INFINITY;
  for (auto fh : mesh.faces()) {
    bool shares = false;  // A common vertex, or an edge between the two triangles.
    for (auto a : mesh.fv_range(fh)) {
      for (auto b : mesh.fv_range(f0)) {
        shares = shares || a == b || mesh.find_halfedge(a, b).is_valid();
      }
    }
    const double d = (mesh.calc_face_centroid(fh) - mesh.calc_face_centroid(f0)).norm();
    if (!shares && d < nearest) {
      nearest = d;
      f1 = fh;
    }
  }
  ASSERT_TRUE(f1.is_valid());
  RemoveTriangle(mesh, f0, nullptr);
  RemoveTriangle(mesh, f1, nullptr);
  ASSERT_EQ(Count(mesh).boundary_loops, 2u);

  Mesh merged_copy = mesh;
  EXPECT_EQ(MergeCloseBoundaries(merged_copy, BoundaryMergingOptions{}, mean_area).merges, 1u)
      << "the paper's Step 5 alone sews the two holes into a handle";

  BoundaryMergingOptions options;
  options.close_small_holes = true;
  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, options, mean_area);
  EXPECT_EQ(result.closed.closed_holes, 2u) << "both tiny holes must be closed";
  ExpectClosedWithoutMerges(mesh, result, 2, "the sphere must stay genus 0");
}

TEST(BoundaryMergingTest, HolesSplitByABridgeAreClosedInsteadOfSewnIntoAHandle) {
  // One hole round the tube of a torus, split in two by a bridge of two faces (shapes.h): two
  // loops of 15 side by side, each winding round the tube, already joined by the bridge's edge.
  // Sewn together, the strip and the bridge make a handle one edge across (genus-2 scenario of
  // topology_learning_test, seed 18).
  Mesh mesh = MustToMesh(TorusWithBridgedHoles(48, 16, 3.0, 1.0));
  const double mean_area = MeanTriangleArea(mesh);
  ASSERT_EQ(Count(mesh).boundary_loops, 2u);
  ASSERT_EQ(Count(mesh).euler(), -2);

  BoundaryMergingOptions options;
  options.close_small_holes = true;
  options.zip_border_slits = true;
  Mesh sewn = mesh;
  EXPECT_EQ(MergeCloseBoundaries(sewn, options, mean_area).merges, 1u)
      << "neither loop is a small hole: Step 5 sews them";
  EXPECT_EQ(Count(sewn).euler(), -2) << "into a closed genus 2";
  EXPECT_EQ(Count(sewn).boundary_loops, 0u);

  options.close_bridged_holes = true;
  const BoundaryMergingResult result = MergeCloseBoundaries(mesh, options, mean_area);
  EXPECT_EQ(result.bridged.closed_holes, 1u) << "the pair must be closed as one hole";
  ExpectClosedWithoutMerges(mesh, result, 0, "the torus must stay genus 1");
}

}  // namespace
}  // namespace neuralmesh
