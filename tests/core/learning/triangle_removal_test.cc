#include "core/learning/triangle_removal.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/mesh_validation.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using testing::BoundaryLoopSizes;
using testing::GridPatch;
using testing::Icosphere;
using testing::MustToMesh;

size_t LiveFaces(const Mesh& mesh) {
  size_t n = 0;
  for (auto fh : mesh.faces()) {
    (void)fh;
    ++n;
  }
  return n;
}

double FaceArea(const Mesh& mesh, Mesh::FaceHandle fh) {
  std::vector<Vec3> p;
  for (auto vh : mesh.fv_range(fh)) p.push_back(mesh.point(vh));
  return 0.5 * OpenMesh::cross(p[1] - p[0], p[2] - p[0]).norm();
}

std::vector<Mesh::FaceHandle> FacesAround(const Mesh& mesh, Mesh::VertexHandle vh) {
  std::vector<Mesh::FaceHandle> faces;
  for (auto fh : mesh.vf_range(vh)) faces.push_back(fh);
  return faces;
}

TriangleMesh Tetrahedron() {
  TriangleMesh m;
  m.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  m.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

TEST(TriangleRemovalTest, OptionsValidate) {
  EXPECT_TRUE(TriangleRemovalOptions{}.Validate().ok()) << "the paper's alpha_r = 7 is valid";
  EXPECT_FALSE(TriangleRemovalOptions{0}.Validate().ok()) << "alpha_r = 0 must be rejected";
  EXPECT_FALSE(TriangleRemovalOptions{-1}.Validate().ok()) << "negative alpha_r accepted";
  EXPECT_FALSE(TriangleRemovalOptions{NAN}.Validate().ok()) << "NaN alpha_r accepted";
}

TEST(TriangleRemovalTest, MeanTriangleAreaOfAGrid) {
  Mesh mesh = MustToMesh(GridPatch(4, 5));
  EXPECT_NEAR(MeanTriangleArea(mesh), 1.0 / 40, 1e-12) << "40 equal triangles on the unit square";
  EXPECT_EQ(MeanTriangleArea(Mesh()), 0) << "an empty mesh has mean area 0";
}

TEST(TriangleRemovalTest, UniformIcosphereLosesNothing) {
  Mesh mesh = MustToMesh(Icosphere(2));
  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, TriangleRemovalOptions{});
  EXPECT_EQ(result.removed_faces, 0u) << "no face of a uniform sphere is 7 times the mean";
  EXPECT_TRUE(result.removed_vertices.empty()) << "no vertex may go";
  EXPECT_NEAR(result.mean_area, 4 * M_PI / 320, 0.1 * 4 * M_PI / 320)
      << "E(Area) of a level-2 unit icosphere is about 4 pi / 320";
  EXPECT_EQ(LiveFaces(mesh), 320u) << "faces disappeared";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(TriangleRemovalTest, SpikeFacesGoWithTheSpikeVertex) {
  Mesh mesh = MustToMesh(Icosphere(2));
  const Mesh::VertexHandle spike(0);
  mesh.set_point(spike, mesh.point(spike) * 10.0);
  const std::vector<Mesh::FaceHandle> spike_faces = FacesAround(mesh, spike);
  ASSERT_EQ(spike_faces.size(), 5u) << "vertex 0 is an icosahedron corner of valence 5";

  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, TriangleRemovalOptions{});
  EXPECT_EQ(result.removed_faces, 5u) << "exactly the five stretched faces are large";
  for (auto fh : spike_faces) {
    EXPECT_TRUE(mesh.status(fh).deleted()) << "stretched face " << fh.idx() << " survived";
  }
  EXPECT_EQ(LiveFaces(mesh), 315u) << "only the stretched faces may be removed";
  ASSERT_EQ(result.removed_vertices.size(), 1u) << "the spike vertex lost all its faces";
  EXPECT_EQ(result.removed_vertices[0], spike) << "the reported vertex is not the spike";
  EXPECT_TRUE(mesh.status(spike).deleted()) << "the spike vertex must be marked deleted";
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>{5})
      << "the hole must be bounded by the spike's five neighbours";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(TriangleRemovalTest, SecondCallOnAMeshWithDeletedElements) {
  Mesh mesh = MustToMesh(Icosphere(2));
  mesh.set_point(Mesh::VertexHandle(0), mesh.point(Mesh::VertexHandle(0)) * 10.0);
  ASSERT_EQ(RemoveLargeTriangles(mesh, TriangleRemovalOptions{}).removed_faces, 5u)
      << "first spike";

  // Vertex 3 is the antipode of vertex 0: its fan is untouched by the first removal.
  mesh.set_point(Mesh::VertexHandle(3), mesh.point(Mesh::VertexHandle(3)) * 10.0);
  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, TriangleRemovalOptions{});
  EXPECT_EQ(result.removed_faces, 5u) << "the second spike's five faces must go";
  EXPECT_EQ(result.removed_vertices.size(), 1u) << "the second spike vertex must go";
  EXPECT_EQ(LiveFaces(mesh), 310u) << "only spike faces may be removed";
  EXPECT_EQ(BoundaryLoopSizes(mesh), (std::vector<size_t>{5, 5})) << "two pentagonal holes";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);

  const TriangleRemovalResult again = RemoveLargeTriangles(mesh, TriangleRemovalOptions{});
  EXPECT_EQ(again.removed_faces, 0u) << "a third call must find nothing large";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(TriangleRemovalTest, FacesDeletedByCollapsesAreSkipped) {
  // Step 4 runs right after Step 3's collapses, before the deleted faces are collected; their
  // links may name half-edges that are gone, and neither the mean nor the removal may read them.
  Mesh mesh = MustToMesh(Icosphere(3));
  Random rng(5);
  int collapsed = 0;
  for (int tries = 0; tries < 2000 && collapsed < 60; ++tries) {
    const Mesh::HalfedgeHandle h(static_cast<int>(rng.NextIndex(mesh.n_halfedges())));
    if (mesh.status(mesh.edge_handle(h)).deleted() || !mesh.is_collapse_ok(h)) continue;
    mesh.collapse(h);
    ++collapsed;
  }
  ASSERT_EQ(collapsed, 60);
  ASSERT_LT(LiveFaces(mesh), mesh.n_faces()) << "no face was deleted";
  double total = 0;
  for (auto f : mesh.faces()) total += FaceArea(mesh, f);
  const double mean = total / static_cast<double>(LiveFaces(mesh));
  EXPECT_NEAR(MeanTriangleArea(mesh), mean, 1e-15 * mean) << "the mean of the live faces";
  const size_t before = LiveFaces(mesh);
  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, TriangleRemovalOptions{});
  EXPECT_NEAR(result.mean_area, mean, 1e-15 * mean);
  EXPECT_EQ(LiveFaces(mesh), before - result.removed_faces);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// A wheel of six faces around an interior centre, where two opposite faces are huge and the
// others tiny, next to a sphere of ordinary faces that sets the mean area. Removing one huge
// face puts the centre on a boundary; the other huge face then sits in the middle of the
// centre's fan, and removing it would pinch the centre.
TEST(TriangleRemovalTest, RemovalThatWouldPinchAVertexIsSkipped) {
  TriangleMesh shape = Icosphere(2);
  const uint32_t base = static_cast<uint32_t>(shape.positions.size());
  auto ring = [](double degrees, double radius) {
    const double a = degrees * M_PI / 180;
    return Vec3f(static_cast<float>(radius * std::cos(a)), static_cast<float>(radius * std::sin(a)),
                 0.f) +
           Vec3f(0, 0, 5);
  };
  shape.positions.push_back(Vec3f(0, 0, 5));  // Centre.
  shape.positions.push_back(ring(0, 11));     // r0: tri0 is the largest face.
  shape.positions.push_back(ring(60, 10));
  shape.positions.push_back(ring(120, 0.1));
  shape.positions.push_back(ring(180, 10));
  shape.positions.push_back(ring(240, 10));
  shape.positions.push_back(ring(300, 0.1));
  for (uint32_t i = 0; i < 6; ++i) {
    shape.faces.push_back({base, base + 1 + i, base + 1 + (i + 1) % 6});
  }
  Mesh mesh = MustToMesh(shape);
  const Mesh::FaceHandle tri0(320);
  const Mesh::FaceHandle tri3(323);
  ASSERT_GT(FaceArea(mesh, tri0), FaceArea(mesh, tri3)) << "tri0 must be removed first";

  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, TriangleRemovalOptions{});
  EXPECT_EQ(result.removed_faces, 1u) << "only the first huge face can go";
  EXPECT_TRUE(mesh.status(tri0).deleted()) << "the largest face must be removed";
  EXPECT_FALSE(mesh.status(tri3).deleted()) << "the opposite face would pinch the centre";
  EXPECT_TRUE(result.removed_vertices.empty()) << "no vertex lost all its faces";
  EXPECT_FALSE(IsTriangleRemovalOk(mesh, tri3)) << "the skipped removal must still be illegal";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// Lifting an interior vertex of the regular grid stretches its six faces; the two across
// diagonal grid edges are the largest and are opposite, so the second one would pinch the
// vertex until the hole opened by the first has reached it. Both must go, and the lifted
// vertex with its last face.
TEST(TriangleRemovalTest, OppositeLargeFacesBothGoOnceTheHoleReachesThem) {
  Mesh mesh = MustToMesh(GridPatch(8, 8));
  const Mesh::VertexHandle lifted(4 * 9 + 4);
  mesh.set_point(lifted, mesh.point(lifted) + Vec3(0, 0, 5));
  const std::vector<Mesh::FaceHandle> lifted_faces = FacesAround(mesh, lifted);
  ASSERT_EQ(lifted_faces.size(), 6u) << "interior grid vertices have valence 6";

  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, TriangleRemovalOptions{});
  EXPECT_EQ(result.removed_faces, 6u) << "every stretched face must eventually go";
  for (auto fh : lifted_faces) {
    EXPECT_TRUE(mesh.status(fh).deleted()) << "stretched face " << fh.idx() << " survived";
  }
  ASSERT_EQ(result.removed_vertices.size(), 1u) << "the lifted vertex lost all its faces";
  EXPECT_EQ(result.removed_vertices[0], lifted) << "wrong vertex reported";
  EXPECT_EQ(BoundaryLoopSizes(mesh), (std::vector<size_t>{6, 32}))
      << "a hexagonal hole inside the grid's outer boundary";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// Figure 4 of the paper: a whole region of large faces must go as one hole, leaving no large
// face behind. A 40 x 40 grid whose 6 x 6 central cells are 8 times wider in x and y (64
// times the area) is jittered so that the areas, hence the removal order, are scattered over
// the region.
TEST(TriangleRemovalTest, LargeRegionBecomesOneHole) {
  constexpr int kCells = 40;
  std::vector<double> coordinate = {0};
  for (int i = 0; i < kCells; ++i) {
    coordinate.push_back(coordinate.back() + (i >= 17 && i < 23 ? 8 : 1));
  }
  Random random(7);
  Mesh mesh = MustToMesh(GridPatch(kCells, kCells));
  for (int j = 0; j <= kCells; ++j) {
    for (int i = 0; i <= kCells; ++i) {
      const bool inside = i > 17 && i < 23 && j > 17 && j < 23;
      const double jitter = inside ? 2 : 0;
      mesh.set_point(Mesh::VertexHandle(j * (kCells + 1) + i),
                     Vec3(coordinate[i] + jitter * (random.NextDouble() - 0.5),
                          coordinate[j] + jitter * (random.NextDouble() - 0.5), 0));
    }
  }
  const TriangleRemovalOptions options;
  const double threshold = options.alpha_r * MeanTriangleArea(mesh);
  size_t large = 0;
  for (auto fh : mesh.faces()) large += FaceArea(mesh, fh) > threshold;
  ASSERT_EQ(large, 72u) << "exactly the 6 x 6 central cells must be large";

  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, options);
  EXPECT_EQ(result.removed_faces, large) << "every large face of the region must be removed";
  for (auto fh : mesh.faces()) {
    EXPECT_LE(FaceArea(mesh, fh), threshold) << "large face " << fh.idx() << " was left";
  }
  EXPECT_EQ(result.removed_vertices.size(), 25u)
      << "the 5 x 5 vertices inside the region lose all their faces";
  EXPECT_EQ(BoundaryLoopSizes(mesh), (std::vector<size_t>{24, 4 * kCells}))
      << "the region must become one square hole inside the grid's boundary";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(TriangleRemovalTest, TetrahedronIsNeverRemoved) {
  Mesh mesh = MustToMesh(Tetrahedron());
  mesh.set_point(Mesh::VertexHandle(0), Vec3(30, 30, 30));
  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, TriangleRemovalOptions{1e-9});
  EXPECT_EQ(result.removed_faces, 0u) << "a 4-face component is the minimum and must stay";
  EXPECT_EQ(LiveFaces(mesh), 4u) << "faces disappeared";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(TriangleRemovalTest, RemovingEverythingStopsAtTheMinimum) {
  Mesh mesh = MustToMesh(Icosphere(1));
  // Every face exceeds 1e-9 times the mean: all 80 are candidates.
  const TriangleRemovalResult result = RemoveLargeTriangles(mesh, TriangleRemovalOptions{1e-9});
  EXPECT_EQ(result.removed_faces, 76u) << "all but a tetrahedron-like minimum of 4 faces";
  EXPECT_EQ(LiveFaces(mesh), 4u) << "the component must keep 4 faces";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  size_t live_vertices = 0;
  for (auto vh : mesh.vertices()) {
    (void)vh;
    ++live_vertices;
  }
  EXPECT_EQ(live_vertices + result.removed_vertices.size(), 42u)
      << "every vertex is either live or reported removed";
}

TEST(TriangleRemovalTest, SparedFacesStay) {
  // As above every face is a candidate, but the faces around vertex 0 are spared: they all
  // stay, and the rest still goes down to what legality allows.
  Mesh mesh = MustToMesh(Icosphere(1));
  const Mesh::VertexHandle spared_vertex(0);
  const std::vector<Mesh::FaceHandle> spared = FacesAround(mesh, spared_vertex);
  const TriangleRemovalResult result =
      RemoveLargeTriangles(mesh, TriangleRemovalOptions{1e-9}, [&](Mesh::FaceHandle f) {
        return std::find(spared.begin(), spared.end(), f) != spared.end();
      });
  for (auto f : spared) EXPECT_FALSE(mesh.status(f).deleted()) << "spared face " << f.idx();
  EXPECT_GT(result.removed_faces, 60u) << "the faces that are not spared still go";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

// The legality rule is exact: a removal it allows keeps the mesh valid, and a removal it
// refuses breaks it. Random legal faces are removed until none is left, with ValidateMesh
// after every single removal; at each step a random refused face is deleted from a copy.
TEST(TriangleRemovalTest, LegalityRuleIsExactUnderRandomRemovals) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    Random random(seed);
    Mesh mesh = MustToMesh(Icosphere(1 + static_cast<int>(seed % 2)));
    size_t live_vertices = mesh.n_vertices();
    size_t refused_checked = 0;
    while (true) {
      std::vector<Mesh::FaceHandle> legal;
      std::vector<Mesh::FaceHandle> refused;
      for (auto fh : mesh.faces()) (IsTriangleRemovalOk(mesh, fh) ? legal : refused).push_back(fh);
      if (!refused.empty()) {
        const Mesh::FaceHandle fh = refused[random.NextIndex(refused.size())];
        Mesh copy = mesh;
        copy.delete_face(fh, true);
        EXPECT_FALSE(ValidateMesh(copy).ok()) << "seed " << seed << ": the refused removal of face "
                                              << fh.idx() << " would have left a valid mesh";
        ++refused_checked;
      }
      if (legal.empty()) break;
      std::vector<Mesh::VertexHandle> removed;
      RemoveTriangle(mesh, legal[random.NextIndex(legal.size())], &removed);
      live_vertices -= removed.size();
      for (auto vh : removed) {
        ASSERT_TRUE(mesh.status(vh).deleted()) << "reported vertex not deleted, seed " << seed;
      }
      const absl::Status status = ValidateMesh(mesh);
      ASSERT_TRUE(status.ok()) << "seed " << seed << ": " << status;
    }
    size_t counted_vertices = 0;
    for (auto vh : mesh.vertices()) {
      (void)vh;
      ++counted_vertices;
    }
    EXPECT_EQ(counted_vertices, live_vertices)
        << "seed " << seed << ": a vertex was deleted without being reported";
    EXPECT_GT(refused_checked, 0u) << "seed " << seed << ": the pinch rule was never exercised";
  }
}

// 200 jittered spheres with a few random spikes: every result is valid, every removed face
// was large, and every reported vertex is deleted.
TEST(TriangleRemovalTest, RandomSpikesKeepTheMeshValid) {
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    Random random(seed);
    Mesh mesh = MustToMesh(Icosphere(1 + static_cast<int>(seed % 2)));
    for (auto vh : mesh.vertices()) {
      const Vec3 jitter(random.NextDouble() - 0.5, random.NextDouble() - 0.5,
                        random.NextDouble() - 0.5);
      mesh.set_point(vh, mesh.point(vh) + 0.1 * jitter);
    }
    const int spikes = 1 + static_cast<int>(random.NextIndex(6));
    for (int s = 0; s < spikes; ++s) {
      const Mesh::VertexHandle vh(static_cast<int>(random.NextIndex(mesh.n_vertices())));
      mesh.set_point(vh, mesh.point(vh) * (2 + 8 * random.NextDouble()));
    }
    const TriangleRemovalOptions options{2 + 8 * random.NextDouble()};
    const double threshold = options.alpha_r * MeanTriangleArea(mesh);
    std::vector<double> area_before(mesh.n_faces());
    for (auto fh : mesh.faces()) area_before[fh.idx()] = FaceArea(mesh, fh);

    const TriangleRemovalResult result = RemoveLargeTriangles(mesh, options);
    const absl::Status status = ValidateMesh(mesh);
    ASSERT_TRUE(status.ok()) << "seed " << seed << ": " << status;
    size_t deleted_faces = 0;
    for (auto fh : mesh.all_faces()) {
      if (!mesh.status(fh).deleted()) continue;
      ++deleted_faces;
      EXPECT_GT(area_before[fh.idx()], threshold)
          << "seed " << seed << ": removed face " << fh.idx() << " was not large";
    }
    EXPECT_EQ(deleted_faces, result.removed_faces) << "seed " << seed << ": miscounted";
    for (auto vh : result.removed_vertices) {
      EXPECT_TRUE(mesh.status(vh).deleted()) << "seed " << seed << ": reported vertex is live";
    }
  }
}

}  // namespace
}  // namespace neuralmesh
