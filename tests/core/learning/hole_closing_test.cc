#include "core/learning/hole_closing.h"

#include <algorithm>
#include <functional>
#include <vector>

#include "core/learning/initial_mesh.h"
#include "core/learning/triangle_removal.h"
#include "core/mesh_validation.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using testing::BoundaryLoopSizes;
using testing::GridPatch;
using testing::Icosphere;
using testing::MustToMesh;
using testing::TorusWithBridgedHoles;

long EulerCharacteristic(const Mesh& mesh) {
  long chi = 0;
  for (auto vh : mesh.vertices()) (void)vh, ++chi;
  for (auto eh : mesh.edges()) (void)eh, --chi;
  for (auto fh : mesh.faces()) (void)fh, ++chi;
  return chi;
}

TEST(HoleClosingTest, OptionsValidate) {
  EXPECT_TRUE(HoleClosingOptions{}.Validate().ok()) << "the defaults must be valid";
  EXPECT_FALSE((HoleClosingOptions{0, 5, 6}).Validate().ok()) << "alpha_r = 0 accepted";
  EXPECT_FALSE((HoleClosingOptions{7, 0, 6}).Validate().ok()) << "alpha_m = 0 accepted";
  EXPECT_FALSE((HoleClosingOptions{7, 5, 2}).Validate().ok()) << "loops of 2 vertices accepted";
}

TEST(HoleClosingTest, OneTriangleHoleOfOrdinarySizeIsClosed) {
  Mesh mesh = MustToMesh(Icosphere(2));
  const double mean_area = MeanTriangleArea(mesh);
  RemoveTriangle(mesh, Mesh::FaceHandle(5), nullptr);
  ASSERT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({3}));
  const HoleClosingResult result = CloseSmallHoles(mesh, HoleClosingOptions{}, mean_area);
  EXPECT_EQ(result.closed_holes, 1u);
  EXPECT_EQ(result.added_faces, 1u) << "a 3-vertex hole takes one triangle";
  EXPECT_TRUE(BoundaryLoopSizes(mesh).empty()) << "the sphere must be closed again";
  EXPECT_EQ(EulerCharacteristic(mesh), 2) << "and stay genus 0";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(HoleClosingTest, HoleWhoseFillingStepFourWouldRemoveStaysOpen) {
  Mesh mesh = MustToMesh(Icosphere(2));
  const double mean_area = MeanTriangleArea(mesh);
  RemoveTriangle(mesh, Mesh::FaceHandle(5), nullptr);
  HoleClosingOptions options;
  options.alpha_r = 0.5;  // The filling triangle (about E(Area)) is now "large".
  const HoleClosingResult result = CloseSmallHoles(mesh, options, mean_area);
  EXPECT_EQ(result.closed_holes, 0u) << "a filling that Step 4 would cut again was added";
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({3}));
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(HoleClosingTest, HoleLeftByAVertexFanIsClosedEarByEar) {
  Mesh mesh = MustToMesh(Icosphere(2));
  const double mean_area = MeanTriangleArea(mesh);
  // Remove every face around vertex 20 (valence 6): a hexagonal hole, the vertex goes too.
  const Mesh::VertexHandle centre(20);
  std::vector<Mesh::FaceHandle> fan;
  for (auto fh : mesh.vf_range(centre)) fan.push_back(fh);
  ASSERT_EQ(fan.size(), 6u);
  // Around the fan, each removal is legal when it starts next to the growing hole.
  std::vector<Mesh::VertexHandle> removed;
  while (!fan.empty()) {
    auto it = std::find_if(fan.begin(), fan.end(),
                           [&](Mesh::FaceHandle fh) { return IsTriangleRemovalOk(mesh, fh); });
    ASSERT_NE(it, fan.end());
    RemoveTriangle(mesh, *it, &removed);
    fan.erase(it);
  }
  ASSERT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({6}));
  const HoleClosingResult result = CloseSmallHoles(mesh, HoleClosingOptions{}, mean_area);
  EXPECT_EQ(result.closed_holes, 1u);
  EXPECT_EQ(result.added_faces, 4u) << "a hexagon takes four triangles";
  EXPECT_TRUE(BoundaryLoopSizes(mesh).empty());
  EXPECT_EQ(EulerCharacteristic(mesh), 2) << "the sphere must stay genus 0";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);

  HoleClosingOptions five;
  five.max_loop_vertices = 5;
  Mesh again = MustToMesh(Icosphere(2));
  fan.clear();
  for (auto fh : again.vf_range(centre)) fan.push_back(fh);
  while (!fan.empty()) {
    auto it = std::find_if(fan.begin(), fan.end(),
                           [&](Mesh::FaceHandle fh) { return IsTriangleRemovalOk(again, fh); });
    RemoveTriangle(again, *it, nullptr);
    fan.erase(it);
  }
  EXPECT_EQ(CloseSmallHoles(again, five, mean_area).closed_holes, 0u)
      << "a loop above max_loop_vertices was closed";
}

// Removes the faces of `mesh` whose centroid satisfies `cut`, growing one hole from the face
// nearest to `start` so that every removal is legal.
void CutFaces(Mesh& mesh, const Vec3& start, const std::function<bool(const Vec3&)>& cut) {
  std::vector<Mesh::FaceHandle> faces;
  for (auto fh : mesh.faces()) {
    if (cut(mesh.calc_face_centroid(fh))) faces.push_back(fh);
  }
  std::sort(faces.begin(), faces.end(), [&](Mesh::FaceHandle a, Mesh::FaceHandle b) {
    return (mesh.calc_face_centroid(a) - start).sqrnorm() <
           (mesh.calc_face_centroid(b) - start).sqrnorm();
  });
  while (!faces.empty()) {
    auto it = std::find_if(faces.begin(), faces.end(),
                           [&](Mesh::FaceHandle fh) { return IsTriangleRemovalOk(mesh, fh); });
    ASSERT_NE(it, faces.end()) << "no legal removal left";
    RemoveTriangle(mesh, *it, nullptr);
    faces.erase(it);
  }
}

// A 20 x 20 grid is one valid disc again: its 80-edge border is the only loop left.
void ExpectWholeGrid(const Mesh& mesh) {
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({80})) << "only the border is left";
  EXPECT_EQ(EulerCharacteristic(mesh), 1) << "a disc again";
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(HoleClosingTest, LongThinSlitIsZipped) {
  // A row of faces cut across most of a 20 x 20 grid: one loop of 36 vertices, one edge wide.
  // Step 5 cannot merge it (it joins two loops); closing zips it with ordinary triangles.
  Mesh mesh = MustToMesh(GridPatch(20, 20));
  const double mean_area = MeanTriangleArea(mesh);
  CutFaces(mesh, Vec3(0, 0.5, 0),
           [](const Vec3& c) { return c[1] > 0.5 && c[1] < 0.55 && c[0] > 0.1 && c[0] < 0.9; });
  ASSERT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({34, 80}));
  const HoleClosingResult result = CloseSmallHoles(mesh, HoleClosingOptions{}, mean_area);
  EXPECT_EQ(result.closed_holes, 1u);
  EXPECT_EQ(result.added_faces, 32u) << "a loop of k vertices takes k - 2 triangles";
  ExpectWholeGrid(mesh);
  for (auto fh : mesh.faces()) {
    EXPECT_LE(mesh.calc_face_area(fh), 7 * mean_area) << "a filling triangle Step 4 would cut";
  }
}

TEST(HoleClosingTest, HoleWiderThanStepFiveBridgesStaysOpen) {
  // A round hole of radius 0.25 in a 20 x 20 grid (edge 0.05): sqrt(E(Area)) is about 0.035,
  // so alpha_m = 5 bridges 0.18, less than any triangulation of the hole needs.
  Mesh mesh = MustToMesh(GridPatch(20, 20));
  const double mean_area = MeanTriangleArea(mesh);
  auto disc = [](const Vec3& c) { return (c - Vec3(0.5, 0.5, 0)).norm() < 0.25; };
  CutFaces(mesh, Vec3(0.5, 0.5, 0), disc);
  const std::vector<size_t> loops = BoundaryLoopSizes(mesh);
  ASSERT_EQ(loops.size(), 2u);
  HoleClosingOptions options;
  options.alpha_r = 1e9;  // Only the edge-length rule can keep it open.
  EXPECT_EQ(CloseSmallHoles(mesh, options, mean_area).closed_holes, 0u);
  EXPECT_EQ(BoundaryLoopSizes(mesh), loops);

  options.alpha_m = 20;  // Bridging 0.7: now the hole may be filled.
  EXPECT_EQ(CloseSmallHoles(mesh, options, mean_area).closed_holes, 1u);
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({80}));
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(HoleClosingTest, BorderOfAnOpenSurfaceIsNeverClosed) {
  Mesh mesh = MustToMesh(GridPatch(4, 4));
  const HoleClosingResult result = CloseSmallHoles(mesh, HoleClosingOptions{}, 0);
  EXPECT_EQ(result.closed_holes, 0u) << "a 16-vertex border is not a small hole";
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({16}));
}

// The learner's disc start: a hexagon of six triangles whose border is the sheet's own. Filled
// (it passes every test of a small hole), it made the sheet a closed pancake of two layers.
TEST(HoleClosingTest, KeepLongestLoopOpenLeavesTheOnlyBorderOfADiscOpen) {
  BestFitPlane plane;
  plane.center = Vec3(0, 0, 0);
  plane.u = Vec3(1, 0, 0);
  plane.v = Vec3(0, 1, 0);
  plane.normal = Vec3(0, 0, 1);
  plane.radius = 1;
  Mesh disc = MakeInitialDisc(plane);
  Mesh filled = disc;
  EXPECT_EQ(CloseSmallHoles(filled, HoleClosingOptions{}, 0).closed_holes, 1u)
      << "without the option the border is a small hole like any other";
  EXPECT_TRUE(BoundaryLoopSizes(filled).empty());

  HoleClosingOptions options;
  options.keep_longest_loop_open = true;
  EXPECT_EQ(CloseSmallHoles(disc, options, 0).closed_holes, 0u);
  EXPECT_EQ(BoundaryLoopSizes(disc), std::vector<size_t>({6}));
  EXPECT_EQ(disc.n_faces(), 6u);
}

// A hole inside a sheet is still filled; only the border, the loop of greatest perimeter, stays.
TEST(HoleClosingTest, KeepLongestLoopOpenStillFillsAHoleInside) {
  Mesh mesh = MustToMesh(GridPatch(6, 6));
  // Vertex (3, 3), inside, valence 6: remove its faces, starting next to the growing hole.
  const Mesh::VertexHandle centre(3 * 7 + 3);
  std::vector<Mesh::FaceHandle> fan;
  for (auto fh : mesh.vf_range(centre)) fan.push_back(fh);
  ASSERT_EQ(fan.size(), 6u);
  while (!fan.empty()) {
    auto it = std::find_if(fan.begin(), fan.end(),
                           [&](Mesh::FaceHandle fh) { return IsTriangleRemovalOk(mesh, fh); });
    ASSERT_NE(it, fan.end());
    RemoveTriangle(mesh, *it, nullptr);
    fan.erase(it);
  }
  ASSERT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({6, 24}));
  HoleClosingOptions options;
  options.keep_longest_loop_open = true;
  options.max_loop_vertices = 32;  // The border would be closable by its size alone.
  const HoleClosingResult result = CloseSmallHoles(mesh, options, 0);
  EXPECT_EQ(result.closed_holes, 1u);
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({24}));
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(HoleClosingTest, LoopAroundASingleTriangleIsNotDoubled) {
  // A lone triangle (a component of one face) has a 3-vertex border; closing it would put a
  // second face on the same three vertices, leaving vertices of valence 2.
  TriangleMesh triangle;
  triangle.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  triangle.faces = {{0, 1, 2}};
  Mesh mesh = MustToMesh(triangle);
  EXPECT_EQ(CloseSmallHoles(mesh, HoleClosingOptions{}, 0).closed_holes, 0u);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(HoleClosingTest, SlitInABorderIsZipped) {
  // A slit one edge wide and ten deep, cut into the bottom border of a 20 x 20 grid (edge
  // 0.05): part of the one border loop, so CloseSmallHoles cannot fill it, but its mouth is
  // one edge across while the border runs 21 edges round it.
  Mesh mesh = MustToMesh(GridPatch(20, 20));
  const double mean_area = MeanTriangleArea(mesh);
  CutFaces(mesh, Vec3(0.525, 0, 0),
           [](const Vec3& c) { return c[0] > 0.5 && c[0] < 0.55 && c[1] < 0.5; });
  ASSERT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({100}));
  EXPECT_EQ(CloseSmallHoles(mesh, HoleClosingOptions{}, mean_area).closed_holes, 0u);

  const HoleClosingResult result = ZipBorderSlits(mesh, HoleClosingOptions{}, mean_area);

  EXPECT_GE(result.closed_holes, 1u);
  EXPECT_EQ(result.added_faces, 20u) << "the slit's 22 vertices take 20 triangles";
  ExpectWholeGrid(mesh);
  for (auto fh : mesh.faces()) {
    EXPECT_GT(mesh.calc_face_normal(fh)[2], 0) << "every face keeps the grid's orientation";
  }
}

TEST(HoleClosingTest, StraightBordersAndTonguesAreNotZipped) {
  Mesh square = MustToMesh(GridPatch(4, 4));
  EXPECT_EQ(ZipBorderSlits(square, HoleClosingOptions{}, 0).closed_holes, 0u)
      << "a border whose path is never 3 times its chord has no slit";
  EXPECT_EQ(BoundaryLoopSizes(square), std::vector<size_t>({16}));

  // A tongue one edge wide standing out of the upper half of the grid: the border runs round
  // it as round a slit, but the chain's empty side is outside it, and filling the chain
  // would fold triangles back over the tongue.
  const TriangleMesh grid = GridPatch(20, 20);
  TriangleMesh with_tongue;
  with_tongue.positions = grid.positions;
  for (const auto& f : grid.faces) {
    Vec3 c(0, 0, 0);
    for (uint32_t v : f) c += Vec3(grid.positions[v][0], grid.positions[v][1], 0) / 3.0;
    if (c[1] < 0.5 || (c[0] > 0.5 && c[0] < 0.55)) with_tongue.faces.push_back(f);
  }
  Mesh mesh = MustToMesh(with_tongue);
  const double mean_area = MeanTriangleArea(mesh);
  const std::vector<size_t> loops = BoundaryLoopSizes(mesh);
  ASSERT_EQ(loops.size(), 1u);
  const size_t faces = mesh.n_faces();
  // Only the two right-angled corners at the tongue's foot are closed, as crack tips
  // (CloseCrackTips): one triangle each, and the tongue stands as it was.
  const HoleClosingResult result = ZipBorderSlits(mesh, HoleClosingOptions{}, mean_area);
  EXPECT_EQ(result.added_faces, 2u);
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({loops[0] - 2}));
  EXPECT_EQ(mesh.n_faces(), faces + 2) << "a rejected zip leaves no face behind";
  for (auto fh : mesh.faces()) EXPECT_GT(mesh.calc_face_normal(fh)[2], 0);
}

// A crack one edge wide and 30 deep in a 40 x 40 grid (edge 0.025), longer than the chains
// ZipBorderSlits fills (48 edges): closing its tip makes the next one, up to the mouth.
TEST(HoleClosingTest, CrackLongerThanAChainIsClosedFromItsTip) {
  Mesh mesh = MustToMesh(GridPatch(40, 40));
  const double mean_area = MeanTriangleArea(mesh);
  CutFaces(mesh, Vec3(0.5125, 0, 0),
           [](const Vec3& c) { return c[0] > 0.5 && c[0] < 0.525 && c[1] < 0.75; });
  ASSERT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({220}));

  const HoleClosingResult result = CloseCrackTips(mesh, HoleClosingOptions{}, mean_area);

  EXPECT_EQ(result.added_faces, 60u) << "the crack's 62 vertices take 60 triangles";
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({160})) << "only the border is left";
  EXPECT_EQ(EulerCharacteristic(mesh), 1);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  for (auto fh : mesh.faces()) EXPECT_GT(mesh.calc_face_normal(fh)[2], 0);
}

// The corners of a square (270 degrees on the empty side) and its straight sides (180) are no
// crack tips; an inner corner of a staircase (90) is.
TEST(HoleClosingTest, CornersWiderThanARightAngleAreNoCrackTips) {
  Mesh square = MustToMesh(GridPatch(10, 10));
  EXPECT_EQ(CloseCrackTips(square, HoleClosingOptions{}, 0).added_faces, 0u);
  EXPECT_EQ(BoundaryLoopSizes(square), std::vector<size_t>({40}));

  // The grid's top right corner cut away square by square along the diagonal: a staircase of
  // 9 inner corners, each closed by one triangle into a straight diagonal border.
  Mesh stairs = MustToMesh(GridPatch(20, 20));
  const double mean_area = MeanTriangleArea(stairs);
  CutFaces(stairs, Vec3(1, 1, 0), [](const Vec3& c) { return c[0] + c[1] > 1.5; });
  const std::vector<size_t> loops = BoundaryLoopSizes(stairs);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(CloseCrackTips(stairs, HoleClosingOptions{}, mean_area).added_faces, 9u);
  EXPECT_EQ(BoundaryLoopSizes(stairs), std::vector<size_t>({loops[0] - 9}));
  EXPECT_TRUE(ValidateMesh(stairs).ok()) << ValidateMesh(stairs);
  for (auto fh : stairs.faces()) EXPECT_GT(stairs.calc_face_normal(fh)[2], 0);
}

// 48 rings of 16 round a tube of radius 1 (edges about 0.39, sqrt(E(Area)) about 0.28, so
// alpha_m = 5 bridges 1.4): two loops of 15 round the tube, split by a bridge of two faces.
Mesh BridgedHoles() { return MustToMesh(TorusWithBridgedHoles(48, 16, 3.0, 1.0)); }

size_t LiveFaces(const Mesh& mesh) {
  size_t n = 0;
  for (auto fh : mesh.faces()) (void)fh, ++n;
  return n;
}

TEST(HoleClosingTest, TwoHolesSplitByABridgeAreClosedAsOne) {
  Mesh mesh = BridgedHoles();
  const double mean_area = MeanTriangleArea(mesh);
  ASSERT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({15, 15}));
  ASSERT_EQ(EulerCharacteristic(mesh), -2) << "a torus with two holes";
  EXPECT_EQ(CloseSmallHoles(mesh, HoleClosingOptions{}, mean_area).closed_holes, 0u)
      << "each loop winds round the tube: a filling would span its diameter, 2";

  const HoleClosingResult result = CloseBridgedHoles(mesh, HoleClosingOptions{}, mean_area);

  EXPECT_EQ(result.closed_holes, 1u);
  EXPECT_EQ(result.added_faces, 28u) << "the two faces go, and the loop of 30 takes 28";
  EXPECT_TRUE(BoundaryLoopSizes(mesh).empty()) << "the torus must be closed again";
  EXPECT_EQ(EulerCharacteristic(mesh), 0) << "and stay genus 1: no handle through the bridge";
  EXPECT_EQ(LiveFaces(mesh), 2u * 48 * 16);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  for (auto fh : mesh.faces()) {
    EXPECT_LE(mesh.calc_face_area(fh), 7 * mean_area) << "a filling triangle Step 4 would cut";
  }
}

TEST(HoleClosingTest, KeepLongestLoopOpenKeepsTheLongestLoopOutOfBridgedPairs) {
  Mesh mesh = BridgedHoles();
  const double mean_area = MeanTriangleArea(mesh);
  HoleClosingOptions options;
  options.keep_longest_loop_open = true;
  EXPECT_EQ(CloseBridgedHoles(mesh, options, mean_area).closed_holes, 0u)
      << "one of the two loops is the longest: the pair must be left alone";
  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({15, 15}));
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
}

TEST(HoleClosingTest, BridgedHolesWiderThanStepFiveBridgesAreLeftAsTheyWere) {
  Mesh mesh = BridgedHoles();
  const double mean_area = MeanTriangleArea(mesh);
  const size_t faces = LiveFaces(mesh);
  HoleClosingOptions options;
  options.alpha_m = 1;  // Bridging 0.28: the cut's edges across the tube's outside are 0.52.

  EXPECT_EQ(CloseBridgedHoles(mesh, options, mean_area).closed_holes, 0u);

  EXPECT_EQ(BoundaryLoopSizes(mesh), std::vector<size_t>({15, 15}))
      << "the bridge's faces must be put back";
  EXPECT_EQ(LiveFaces(mesh), faces);
  EXPECT_EQ(EulerCharacteristic(mesh), -2);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  // Put back as they were: the same two triangles, in the same orientation.
  const Mesh::VertexHandle ring0_angle3(3), ring1_last(16 + 15);
  const Mesh::HalfedgeHandle h = mesh.find_halfedge(ring0_angle3, ring1_last);
  ASSERT_TRUE(h.is_valid());
  EXPECT_FALSE(mesh.is_boundary(mesh.edge_handle(h)));
  EXPECT_EQ(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)).idx(), 16) << "(3, 31, 16)";
  EXPECT_EQ(
      mesh.to_vertex_handle(mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h))).idx(), 2)
      << "(31, 3, 2)";
}

TEST(HoleClosingTest, LoopsNotJoinedByAnEdgeAreNotClosedAsAPair) {
  // Two round holes apart in a grid: no edge joins them, so neither is touched.
  Mesh mesh = MustToMesh(GridPatch(20, 20));
  const double mean_area = MeanTriangleArea(mesh);
  CutFaces(mesh, Vec3(0.3, 0.5, 0),
           [](const Vec3& c) { return (c - Vec3(0.3, 0.5, 0)).norm() < 0.1; });
  CutFaces(mesh, Vec3(0.7, 0.5, 0),
           [](const Vec3& c) { return (c - Vec3(0.7, 0.5, 0)).norm() < 0.1; });
  const std::vector<size_t> loops = BoundaryLoopSizes(mesh);
  ASSERT_EQ(loops.size(), 3u);
  EXPECT_EQ(CloseBridgedHoles(mesh, HoleClosingOptions{}, mean_area).closed_holes, 0u);
  EXPECT_EQ(BoundaryLoopSizes(mesh), loops);
}

}  // namespace
}  // namespace neuralmesh
