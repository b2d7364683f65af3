#include "core/learning/inactive_face_removal.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/analysis/mesh_report.h"
#include "core/mesh_validation.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using testing::BoundaryLoopSizes;
using testing::GridPatch;
using testing::MustToMesh;

constexpr int kColumns = 7;
constexpr int kRows = 3;

int VertexAt(int i, int j) { return j * (kColumns + 1) + i; }

// A 7 x 3 grid of squares on [0,1]^2 with two holes in the middle row: squares 1-2 (hole A)
// and 4-5 (hole B). Square 3 between them is the bridge: its two triangles share the diagonal
// from (3,1) on hole A to (4,2) on hole B, and every corner lies on one hole or the other.
Mesh GridWithTwoHoles() {
  TriangleMesh grid = GridPatch(kColumns, kRows);
  TriangleMesh holed;
  holed.positions = grid.positions;
  for (size_t k = 0; k < grid.faces.size(); ++k) {
    const int square = static_cast<int>(k / 2);
    const int i = square % kColumns;
    const int j = square / kColumns;
    const bool in_hole = j == 1 && (i == 1 || i == 2 || i == 4 || i == 5);
    if (!in_hole) holed.faces.push_back(grid.faces[k]);
  }
  return MustToMesh(holed);
}

std::vector<int> BridgeCorners() {
  return {VertexAt(3, 1), VertexAt(4, 1), VertexAt(4, 2), VertexAt(3, 2)};
}

auto InactiveIn(std::vector<int> vertices) {
  return [vertices](Mesh::VertexHandle v) {
    return std::find(vertices.begin(), vertices.end(), v.idx()) != vertices.end();
  };
}

// The two faces of the edge between vertices u and v: first the one on the left of u -> v.
std::vector<Mesh::FaceHandle> FacesOfEdge(const Mesh& mesh, int u, int v) {
  const auto h = mesh.find_halfedge(Mesh::VertexHandle(u), Mesh::VertexHandle(v));
  EXPECT_TRUE(h.is_valid()) << "no edge " << u << "-" << v;
  return {mesh.face_handle(h), mesh.opposite_face_handle(h)};
}

TEST(InactiveFaceRemovalTest, AnInactiveBridgeIsCutAndTheTwoHolesBecomeOne) {
  Mesh mesh = GridWithTwoHoles();
  ASSERT_EQ(BoundaryLoopSizes(mesh), (std::vector<size_t>{6, 6, 20}));
  const size_t faces_before = mesh.n_faces();

  const BridgeCuttingResult result = CutInactiveBridges(mesh, InactiveIn(BridgeCorners()));

  EXPECT_EQ(result.cut_bridges, 1u);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  mesh.garbage_collection();
  EXPECT_EQ(mesh.n_faces(), faces_before - 2) << "the bridge is exactly its two triangles";
  // Hole A (6 edges) and hole B (6) lose their sides of the bridge square and gain its top
  // and bottom edges: one hole of 12 edges.
  EXPECT_EQ(BoundaryLoopSizes(mesh), (std::vector<size_t>{12, 20}));
  const MeshReport report = ComputeMeshReport(ToTriangleMesh(mesh));
  EXPECT_TRUE(report.manifold());
  EXPECT_EQ(report.components, 1u);
  EXPECT_EQ(report.genus, 0) << "joining two holes of a disc changes no genus";
  for (int v : BridgeCorners()) {
    EXPECT_FALSE(mesh.status(Mesh::VertexHandle(v)).deleted()) << "corner " << v << " lost";
  }
}

TEST(InactiveFaceRemovalTest, ABridgeWithAnActiveCornerStays) {
  const std::vector<int> corners = BridgeCorners();
  for (size_t active = 0; active < corners.size(); ++active) {
    std::vector<int> inactive = corners;
    inactive.erase(inactive.begin() + static_cast<long>(active));
    Mesh mesh = GridWithTwoHoles();
    const BridgeCuttingResult result = CutInactiveBridges(mesh, InactiveIn(inactive));
    EXPECT_EQ(result.cut_bridges, 0u) << "cut although corner " << corners[active] << " won";
    EXPECT_EQ(BoundaryLoopSizes(mesh), (std::vector<size_t>{6, 6, 20}));
  }
}

TEST(InactiveFaceRemovalTest, EveryCutJoinsTwoLoopsAndKeepsADisc) {
  Mesh mesh = GridWithTwoHoles();
  std::vector<int> all(mesh.n_vertices());
  for (size_t v = 0; v < all.size(); ++v) all[v] = static_cast<int>(v);
  // With every vertex inactive, the strips between the holes and the outer border are dead
  // too: each cut joins two of the three loops, until one is left.
  const BridgeCuttingResult result = CutInactiveBridges(mesh, InactiveIn(all));
  EXPECT_EQ(result.cut_bridges, 2u);
  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  EXPECT_EQ(BoundaryLoopSizes(mesh).size(), 1u);
  const MeshReport report = ComputeMeshReport(ToTriangleMesh(mesh));
  EXPECT_TRUE(report.manifold());
  EXPECT_EQ(report.components, 1u) << "a cut between two loops never splits the surface";
  EXPECT_EQ(report.genus, 0);
}

TEST(InactiveFaceRemovalTest, RemovalThatWouldPinchACornerIsRejected) {
  const Mesh mesh = GridWithTwoHoles();
  const std::vector<Mesh::FaceHandle> bridge = FacesOfEdge(mesh, VertexAt(3, 1), VertexAt(4, 2));
  EXPECT_TRUE(IsFaceSetRemovalOk(mesh, bridge, Mesh::VertexHandle()))
      << "the bridge's two triangles";
  // Either bridge triangle alone pinches the corner across from its boundary edge.
  EXPECT_FALSE(IsFaceSetRemovalOk(mesh, {bridge[0]}, Mesh::VertexHandle()));
  EXPECT_FALSE(IsFaceSetRemovalOk(mesh, {bridge[1]}, Mesh::VertexHandle()));
  // The face (0,0), (1,1), (0,1) lies in the middle of the fan of (1,1), a corner of hole A:
  // without it, (1,1) would keep two fans.
  const Mesh::FaceHandle middle = FacesOfEdge(mesh, VertexAt(0, 0), VertexAt(1, 1))[0];
  EXPECT_FALSE(IsFaceSetRemovalOk(mesh, {middle}, Mesh::VertexHandle()));
  // A corner left without any face is rejected unless it is the one meant to be emptied:
  // the two faces of the grid's corner square, at the corner (0,0).
  const Mesh grid = MustToMesh(GridPatch(4, 4));
  const std::vector<Mesh::FaceHandle> corner = FacesOfEdge(grid, 0, 6);  // (0,0) - (1,1).
  EXPECT_FALSE(IsFaceSetRemovalOk(grid, corner, Mesh::VertexHandle()));
  EXPECT_TRUE(IsFaceSetRemovalOk(grid, corner, Mesh::VertexHandle(0)));
}

TEST(InactiveFaceRemovalTest, ABorderVertexIsCutOutWithItsFan) {
  Mesh mesh = MustToMesh(GridPatch(4, 4));
  const Mesh::VertexHandle v(2);  // (2, 0), in the middle of the bottom side.
  ASSERT_EQ(BoundaryLoopSizes(mesh), (std::vector<size_t>{16}));
  std::vector<Mesh::VertexHandle> removed, touched;

  ASSERT_TRUE(CutOutBorderVertex(mesh, v, &removed, &touched));

  EXPECT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  EXPECT_TRUE(mesh.status(v).deleted());
  EXPECT_EQ(removed, (std::vector<Mesh::VertexHandle>{v}));
  EXPECT_EQ(touched.size(), 4u) << "(1,0), (2,1), (3,1) and (3,0)";
  mesh.garbage_collection();
  EXPECT_EQ(mesh.n_faces(), 32u - 3u) << "its three faces";
  // The border goes round (2,0) through (2,1) and (3,1): two edges become three.
  EXPECT_EQ(BoundaryLoopSizes(mesh), (std::vector<size_t>{17}));
}

TEST(InactiveFaceRemovalTest, ACutThatWouldSplitTheSurfaceIsRefused) {
  // On a strip one square wide, the fan of (2,0) is all that joins the two ends.
  Mesh mesh = MustToMesh(GridPatch(4, 1));
  std::vector<Mesh::VertexHandle> removed;
  EXPECT_FALSE(CutOutBorderVertex(mesh, Mesh::VertexHandle(2), &removed, nullptr));
  EXPECT_TRUE(removed.empty());
  EXPECT_EQ(mesh.n_faces(), 8u) << "a refused cut changes nothing";
  EXPECT_TRUE(ValidateMesh(mesh).ok());
  // An interior vertex is not a border vertex to cut out.
  Mesh grid = MustToMesh(GridPatch(2, 2));
  EXPECT_FALSE(CutOutBorderVertex(grid, Mesh::VertexHandle(4), nullptr, nullptr));
}

}  // namespace
}  // namespace neuralmesh
