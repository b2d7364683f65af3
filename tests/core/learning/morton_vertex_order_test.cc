#include "core/learning/morton_vertex_order.h"

#include <algorithm>
#include <cstdlib>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/mesh_validation.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using testing::GridPatch;
using testing::Icosphere;
using testing::MustToMesh;

// The faces as sets of positions, and each boundary's length: what a renumbering must keep.
std::multiset<std::vector<std::vector<double>>> FacesByPosition(const Mesh& mesh) {
  std::multiset<std::vector<std::vector<double>>> faces;
  for (auto f : mesh.faces()) {
    std::vector<std::vector<double>> corners;
    for (auto v : mesh.fv_range(f)) {
      const Vec3& p = mesh.point(v);
      corners.push_back({p[0], p[1], p[2]});
    }
    // Rotate so that the smallest corner comes first: the same face, however numbered.
    std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()),
                corners.end());
    faces.insert(corners);
  }
  return faces;
}

// The mean of |i - j| over the edges (i, j).
double MeanIndexDistance(const Mesh& mesh) {
  double sum = 0;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    sum += std::abs(mesh.to_vertex_handle(h).idx() - mesh.from_vertex_handle(h).idx());
  }
  return sum / static_cast<double>(mesh.n_edges());
}

// A copy of `mesh` with its vertices numbered in a random order.
Mesh Shuffled(const Mesh& mesh, uint64_t seed) {
  std::vector<int> order(mesh.n_vertices());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  Random rng(seed);
  for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.NextIndex(i)]);
  std::vector<Mesh::VertexHandle> new_handle(order.size());
  Mesh out;
  for (const int old : order) new_handle[old] = out.add_vertex(mesh.point(Mesh::VertexHandle(old)));
  for (auto f : mesh.faces()) {
    std::vector<Mesh::VertexHandle> corners;
    for (auto v : mesh.fv_range(f)) corners.push_back(new_handle[v.idx()]);
    out.add_face(corners);
  }
  return out;
}

TEST(MortonCodeTest, InterleavesTheAxesAndClamps) {
  const Vec3 min(0, 0, 0), max(1, 1, 1);
  EXPECT_EQ(MortonCode(Vec3(0, 0, 0), min, max), 0u) << "the minimum corner is cell 0";
  const double cell = 1.0 / (1 << 21);
  EXPECT_EQ(MortonCode(Vec3(cell * 1.5, 0, 0), min, max), 1u) << "x is bit 0";
  EXPECT_EQ(MortonCode(Vec3(0, cell * 1.5, 0), min, max), 2u) << "y is bit 1";
  EXPECT_EQ(MortonCode(Vec3(0, 0, cell * 1.5), min, max), 4u) << "z is bit 2";
  EXPECT_EQ(MortonCode(Vec3(cell * 2.5, 0, 0), min, max), 8u) << "the next x bit is bit 3";
  EXPECT_EQ(MortonCode(Vec3(1, 1, 1), min, max), (uint64_t{1} << 63) - 1)
      << "the maximum corner is the last cell";
  EXPECT_EQ(MortonCode(Vec3(-5, 7, 0.5), min, max), MortonCode(Vec3(0, 1, 0.5), min, max))
      << "points outside the box are clamped to it";
}

TEST(MortonVertexOrderTest, KeepsTheMeshAndMovesPropertiesWithTheirVertices) {
  Mesh mesh = Shuffled(MustToMesh(Icosphere(3)), 7);
  OpenMesh::VPropHandleT<int> tag;
  mesh.add_property(tag);
  for (auto v : mesh.vertices()) mesh.property(tag, v) = v.idx() * 10;
  std::vector<Vec3> old_points;
  for (auto v : mesh.vertices()) old_points.push_back(mesh.point(v));
  const auto faces_before = FacesByPosition(mesh);

  const std::vector<int> new_index = SortVerticesInMortonOrder(mesh);

  ASSERT_EQ(new_index.size(), old_points.size());
  std::vector<int> sorted = new_index;
  std::sort(sorted.begin(), sorted.end());
  for (size_t i = 0; i < sorted.size(); ++i) {
    ASSERT_EQ(sorted[i], static_cast<int>(i)) << "new indices are not a permutation";
  }
  for (size_t old = 0; old < old_points.size(); ++old) {
    const Mesh::VertexHandle v(new_index[old]);
    EXPECT_EQ(mesh.point(v), old_points[old]) << "the point of old vertex " << old << " moved";
    EXPECT_EQ(mesh.property(tag, v), static_cast<int>(old) * 10)
        << "a caller's property did not follow old vertex " << old;
  }
  EXPECT_EQ(FacesByPosition(mesh), faces_before) << "the faces changed";
  for (auto v : mesh.vertices()) {
    EXPECT_EQ(mesh.from_vertex_handle(mesh.halfedge_handle(v)), v)
        << "the outgoing half-edge of vertex " << v.idx() << " does not start at it";
  }
}

TEST(MortonVertexOrderTest, NumbersAlongTheCurveAndBringsNeighboursClose) {
  Mesh mesh = Shuffled(MustToMesh(Icosphere(4)), 3);
  const double scattered = MeanIndexDistance(mesh);
  SortVerticesInMortonOrder(mesh);
  Vec3 min = mesh.point(Mesh::VertexHandle(0)), max = min;
  for (auto v : mesh.vertices()) {
    min.minimize(mesh.point(v));
    max.maximize(mesh.point(v));
  }
  for (size_t i = 1; i < mesh.n_vertices(); ++i) {
    const Mesh::VertexHandle a(static_cast<int>(i - 1)), b(static_cast<int>(i));
    ASSERT_LE(MortonCode(mesh.point(a), min, max), MortonCode(mesh.point(b), min, max))
        << "vertices " << i - 1 << " and " << i << " are out of Morton order";
  }
  EXPECT_LT(MeanIndexDistance(mesh), scattered / 5)
      << "neighbours are not much closer in index than in a random numbering";
}

TEST(MortonVertexOrderTest, KeepsBoundariesAndHandlesAnEmptyMesh) {
  Mesh mesh = Shuffled(MustToMesh(GridPatch(12, 9)), 5);
  const auto loops = testing::BoundaryLoopSizes(mesh);
  SortVerticesInMortonOrder(mesh);
  EXPECT_EQ(testing::BoundaryLoopSizes(mesh), loops) << "the border changed";
  for (auto v : mesh.vertices()) {
    if (!mesh.is_boundary(v)) continue;
    EXPECT_TRUE(mesh.is_boundary(mesh.halfedge_handle(v)))
        << "border vertex " << v.idx() << " lost its outgoing boundary half-edge";
  }
  Mesh empty;
  EXPECT_TRUE(SortVerticesInMortonOrder(empty).empty()) << "an empty mesh has no vertices";
}

// Edge tags that name an edge by its end points' positions, and half-edge tags by its start.
std::vector<double> EdgeKey(const Mesh& mesh, Mesh::HalfedgeHandle h) {
  const Vec3& a = mesh.point(mesh.from_vertex_handle(h));
  const Vec3& b = mesh.point(mesh.to_vertex_handle(h));
  return {a[0], a[1], a[2], b[0], b[1], b[2]};
}

TEST(SortEdgesByVertexIndexTest, KeepsTheMeshAndMovesPropertiesWithTheirEdges) {
  for (const bool with_border : {false, true}) {
    const std::string context = with_border ? "grid patch" : "icosphere";
    Mesh mesh = Shuffled(MustToMesh(with_border ? GridPatch(12, 9) : Icosphere(3)), 11);
    SortVerticesInMortonOrder(mesh);
    OpenMesh::EPropHandleT<std::vector<double>> edge_tag;
    OpenMesh::HPropHandleT<std::vector<double>> halfedge_tag;
    mesh.add_property(edge_tag);
    mesh.add_property(halfedge_tag);
    for (auto h : mesh.halfedges()) mesh.property(halfedge_tag, h) = EdgeKey(mesh, h);
    for (auto e : mesh.edges())
      mesh.property(edge_tag, e) = EdgeKey(mesh, mesh.halfedge_handle(e, 0));
    const auto faces_before = FacesByPosition(mesh);
    const auto loops_before = testing::BoundaryLoopSizes(mesh);
    std::vector<std::vector<int>> rings_before;
    for (auto v : mesh.vertices()) {
      std::vector<int> ring;
      for (auto u : mesh.vv_range(v)) ring.push_back(u.idx());
      rings_before.push_back(ring);
    }

    SortEdgesByVertexIndex(mesh);

    ASSERT_TRUE(ValidateMesh(mesh).ok()) << context << ": " << ValidateMesh(mesh);
    EXPECT_EQ(FacesByPosition(mesh), faces_before) << context << ": the faces changed";
    EXPECT_EQ(testing::BoundaryLoopSizes(mesh), loops_before) << context << ": the border changed";
    for (auto v : mesh.vertices()) {
      std::vector<int> ring;
      for (auto u : mesh.vv_range(v)) ring.push_back(u.idx());
      std::vector<int> expected = rings_before[v.idx()];
      // The same neighbours in the same rotation; the walk may start elsewhere.
      ASSERT_EQ(ring.size(), expected.size()) << context << ": vertex " << v.idx();
      auto start = std::find(expected.begin(), expected.end(), ring.front());
      ASSERT_NE(start, expected.end()) << context << ": vertex " << v.idx();
      std::rotate(expected.begin(), start, expected.end());
      EXPECT_EQ(ring, expected) << context << ": the ring of vertex " << v.idx() << " changed";
      if (mesh.is_boundary(v)) {
        EXPECT_TRUE(mesh.is_boundary(mesh.halfedge_handle(v)))
            << context << ": border vertex " << v.idx() << " lost its boundary half-edge";
      }
    }
    for (auto h : mesh.halfedges()) {
      ASSERT_EQ(mesh.property(halfedge_tag, h), EdgeKey(mesh, h))
          << context << ": a half-edge property did not follow half-edge " << h.idx();
    }
    std::pair<int, int> last(-1, -1);
    for (auto e : mesh.edges()) {
      const auto h = mesh.halfedge_handle(e, 0);
      ASSERT_EQ(mesh.property(edge_tag, e), EdgeKey(mesh, h))
          << context << ": an edge property did not follow edge " << e.idx();
      const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      ASSERT_LT(last, key) << context << ": edge " << e.idx() << " is out of order";
      last = key;
    }
  }
  Mesh empty;
  SortEdgesByVertexIndex(empty);
  EXPECT_EQ(empty.n_edges(), 0u);
}

}  // namespace
}  // namespace neuralmesh
