#include "core/learning/morton_vertex_order.h"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/mesh_validation.h"
#include "core/morton_code.h"
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

// A position as a key: the test meshes' vertices have distinct positions, so a position names a
// vertex however the mesh numbers it.
std::vector<double> Key(const Vec3& p) { return {p[0], p[1], p[2]}; }

// The positions of a face's corners in the order its half-edge walk gives them.
std::vector<std::vector<double>> FaceCorners(const Mesh& mesh, Mesh::FaceHandle f) {
  std::vector<std::vector<double>> corners;
  for (auto v : mesh.fv_range(f)) corners.push_back(Key(mesh.point(v)));
  return corners;
}

// The end points of a half-edge.
std::vector<double> HalfedgeKey(const Mesh& mesh, Mesh::HalfedgeHandle h) {
  std::vector<double> key = Key(mesh.point(mesh.from_vertex_handle(h)));
  const std::vector<double> to = Key(mesh.point(mesh.to_vertex_handle(h)));
  key.insert(key.end(), to.begin(), to.end());
  return key;
}

// `mesh` with deleted elements in the middle of every kind: faces deleted (opening holes, their
// isolated vertices deleted too, or kept isolated, then isolated twins added) and edges
// collapsed.
Mesh WithDeletions(Mesh mesh, bool keep_isolated_vertices) {
  Random rng(17);
  for (int i = 0; i < 6; ++i) {
    const Mesh::FaceHandle f(static_cast<int>(rng.NextIndex(mesh.n_faces())));
    if (!mesh.status(f).deleted()) mesh.delete_face(f, !keep_isolated_vertices);
  }
  int collapsed = 0;
  for (int tries = 0; tries < 200 && collapsed < 8; ++tries) {
    const Mesh::HalfedgeHandle h(static_cast<int>(rng.NextIndex(mesh.n_halfedges())));
    if (mesh.status(mesh.edge_handle(h)).deleted() || mesh.is_boundary(mesh.edge_handle(h)) ||
        mesh.is_boundary(mesh.from_vertex_handle(h)) || !mesh.is_collapse_ok(h)) {
      continue;
    }
    mesh.collapse(h);
    ++collapsed;
  }
  if (keep_isolated_vertices) {
    // Twins of a few vertices, in the same Morton cell: the collection's order decides where
    // they go (it moves them from the end into the first free slots).
    for (int i = 0; i < 4; ++i) {
      const Mesh::VertexHandle v(static_cast<int>(rng.NextIndex(mesh.n_vertices())));
      if (!mesh.status(v).deleted()) mesh.add_vertex(mesh.point(v) + Vec3(1e-12, 0, 0));
    }
  }
  return mesh;
}

TEST(CompactInMortonOrderTest, IsGarbageCollectionThenTheSortsElementForElement) {
  for (const bool keep_isolated : {false, true}) {
    const std::string context = keep_isolated ? "isolated vertices kept" : "none isolated";
    Mesh mesh = WithDeletions(Shuffled(MustToMesh(Icosphere(3)), 7), keep_isolated);
    // Properties of value types that move by one gather (int) and of others (strings), on
    // every kind of element, each naming its element by position.
    OpenMesh::VPropHandleT<int> vertex_number;
    OpenMesh::VPropHandleT<std::string> vertex_name;
    OpenMesh::EPropHandleT<std::vector<double>> edge_ends;
    OpenMesh::HPropHandleT<std::vector<double>> halfedge_ends;
    OpenMesh::HPropHandleT<int> halfedge_number;
    OpenMesh::FPropHandleT<std::vector<std::vector<double>>> face_corners;
    mesh.add_property(vertex_number);
    mesh.add_property(vertex_name);
    mesh.add_property(edge_ends);
    mesh.add_property(halfedge_ends);
    mesh.add_property(halfedge_number);
    mesh.add_property(face_corners);
    for (auto v : mesh.all_vertices()) {
      mesh.property(vertex_number, v) = v.idx();
      mesh.property(vertex_name, v) = "v" + std::to_string(v.idx());
    }
    for (auto e : mesh.edges()) {
      mesh.property(edge_ends, e) = HalfedgeKey(mesh, mesh.halfedge_handle(e, 0));
    }
    for (auto h : mesh.all_halfedges()) mesh.property(halfedge_number, h) = h.idx();
    for (auto h : mesh.halfedges()) mesh.property(halfedge_ends, h) = HalfedgeKey(mesh, h);
    for (auto f : mesh.faces()) mesh.property(face_corners, f) = FaceCorners(mesh, f);
    std::vector<std::vector<double>> old_positions;
    std::vector<bool> old_deleted;
    for (auto v : mesh.all_vertices()) {
      old_positions.push_back(Key(mesh.point(v)));
      old_deleted.push_back(mesh.status(v).deleted());
    }
    Mesh collected = mesh;
    collected.garbage_collection();
    std::map<std::vector<double>, int> collected_index;
    for (auto v : collected.vertices()) collected_index[Key(collected.point(v))] = v.idx();
    ASSERT_EQ(collected_index.size(), collected.n_vertices()) << context << ": positions repeat";

    const std::vector<int> new_index = CompactInMortonOrder(mesh);

    ASSERT_EQ(mesh.n_vertices(), collected.n_vertices()) << context;
    ASSERT_EQ(mesh.n_edges(), collected.n_edges()) << context;
    ASSERT_EQ(mesh.n_faces(), collected.n_faces()) << context;
    if (!keep_isolated) {
      ASSERT_TRUE(ValidateMesh(mesh).ok()) << context << ": " << ValidateMesh(mesh);
    }
    // Vertices: in Morton order, ties by their order after the collection; the returned map
    // names each old vertex's new index; properties and links follow.
    ASSERT_EQ(new_index.size(), old_positions.size()) << context;
    for (size_t old = 0; old < old_positions.size(); ++old) {
      if (old_deleted[old]) {
        EXPECT_EQ(new_index[old], -1) << context << ": deleted vertex " << old << " got an index";
        continue;
      }
      ASSERT_GE(new_index[old], 0) << context << ": live vertex " << old << " got none";
      const Mesh::VertexHandle v(new_index[old]);
      EXPECT_EQ(Key(mesh.point(v)), old_positions[old]) << context << ": vertex " << old;
      EXPECT_EQ(mesh.property(vertex_number, v), static_cast<int>(old)) << context;
      EXPECT_EQ(mesh.property(vertex_name, v), "v" + std::to_string(old)) << context;
    }
    Vec3 min = mesh.point(Mesh::VertexHandle(0)), max = min;
    for (auto v : mesh.vertices()) {
      min.minimize(mesh.point(v));
      max.maximize(mesh.point(v));
    }
    for (size_t i = 1; i < mesh.n_vertices(); ++i) {
      const Mesh::VertexHandle a(static_cast<int>(i - 1)), b(static_cast<int>(i));
      const auto key = [&](Mesh::VertexHandle v) {
        return std::make_pair(MortonCode(mesh.point(v), min, max),
                              collected_index.at(Key(mesh.point(v))));
      };
      ASSERT_LT(key(a), key(b)) << context << ": vertices " << i - 1 << " and " << i;
    }
    for (auto v : mesh.vertices()) {
      const Mesh::VertexHandle before(collected_index.at(Key(mesh.point(v))));
      ASSERT_EQ(mesh.halfedge_handle(v).is_valid(), collected.halfedge_handle(before).is_valid())
          << context << ": vertex " << v.idx();
      if (!mesh.halfedge_handle(v).is_valid()) continue;
      EXPECT_EQ(HalfedgeKey(mesh, mesh.halfedge_handle(v)),
                HalfedgeKey(collected, collected.halfedge_handle(before)))
          << context << ": vertex " << v.idx() << " starts its walks at another half-edge";
    }
    // Edges: by their new vertex indices; each keeps its half-edges, their properties, and the
    // links of those to the next and previous half-edge and to the face.
    std::pair<int, int> last(-1, -1);
    for (auto e : mesh.edges()) {
      const auto h = mesh.halfedge_handle(e, 0);
      const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      ASSERT_LT(last, key) << context << ": edge " << e.idx() << " is out of order";
      last = key;
      EXPECT_EQ(mesh.property(edge_ends, e), HalfedgeKey(mesh, h)) << context;
    }
    std::map<std::vector<double>, Mesh::HalfedgeHandle> collected_halfedge;
    for (auto h : collected.halfedges()) collected_halfedge[HalfedgeKey(collected, h)] = h;
    for (auto h : mesh.halfedges()) {
      const Mesh::HalfedgeHandle before = collected_halfedge.at(HalfedgeKey(mesh, h));
      EXPECT_EQ(mesh.property(halfedge_ends, h), HalfedgeKey(mesh, h)) << context;
      EXPECT_EQ(mesh.property(halfedge_number, h), collected.property(halfedge_number, before))
          << context << ": half-edge " << h.idx();
      EXPECT_EQ(HalfedgeKey(mesh, mesh.next_halfedge_handle(h)),
                HalfedgeKey(collected, collected.next_halfedge_handle(before)))
          << context << ": half-edge " << h.idx();
      EXPECT_EQ(mesh.prev_halfedge_handle(mesh.next_halfedge_handle(h)), h) << context;
      EXPECT_EQ(mesh.is_boundary(h), collected.is_boundary(before)) << context;
      if (!mesh.is_boundary(h)) {
        EXPECT_EQ(FaceCorners(mesh, mesh.face_handle(h)),
                  FaceCorners(collected, collected.face_handle(before)))
            << context << ": half-edge " << h.idx() << " lies in another face";
      }
    }
    // Faces: in the collection's order, each starting its walk where it did.
    for (auto f : mesh.faces()) {
      EXPECT_EQ(FaceCorners(mesh, f), FaceCorners(collected, f)) << context << ": face " << f.idx();
      EXPECT_EQ(mesh.property(face_corners, f), FaceCorners(mesh, f)) << context;
    }
    EXPECT_EQ(testing::BoundaryLoopSizes(mesh), testing::BoundaryLoopSizes(collected)) << context;
  }
}

TEST(CompactInMortonOrderTest, NumbersAlongTheCurveAndBringsNeighboursClose) {
  Mesh mesh = Shuffled(MustToMesh(Icosphere(4)), 3);
  const double scattered = MeanIndexDistance(mesh);
  CompactInMortonOrder(mesh);
  EXPECT_LT(MeanIndexDistance(mesh), scattered / 5)
      << "neighbours are not much closer in index than in a random numbering";
  for (auto v : mesh.vertices()) {
    ASSERT_EQ(mesh.from_vertex_handle(mesh.halfedge_handle(v)), v)
        << "the outgoing half-edge of vertex " << v.idx() << " does not start at it";
  }
}

TEST(CompactInMortonOrderTest, KeepsBoundariesAndHandlesAnEmptyMesh) {
  Mesh mesh = Shuffled(MustToMesh(GridPatch(12, 9)), 5);
  const auto loops = testing::BoundaryLoopSizes(mesh);
  const auto faces = FacesByPosition(mesh);
  CompactInMortonOrder(mesh);
  ASSERT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  EXPECT_EQ(testing::BoundaryLoopSizes(mesh), loops) << "the border changed";
  EXPECT_EQ(FacesByPosition(mesh), faces) << "the faces changed";
  for (auto v : mesh.vertices()) {
    if (!mesh.is_boundary(v)) continue;
    EXPECT_TRUE(mesh.is_boundary(mesh.halfedge_handle(v)))
        << "border vertex " << v.idx() << " lost its outgoing boundary half-edge";
  }
  Mesh empty;
  EXPECT_TRUE(CompactInMortonOrder(empty).empty()) << "an empty mesh has no vertices";
  EXPECT_EQ(empty.n_edges(), 0u);
  // Everything deleted: nothing is left.
  Mesh gone = MustToMesh(Icosphere(1));
  for (auto f : gone.faces()) gone.delete_face(f, true);
  const std::vector<int> new_index = CompactInMortonOrder(gone);
  EXPECT_EQ(gone.n_vertices() + gone.n_edges() + gone.n_faces(), 0u);
  EXPECT_EQ(std::count(new_index.begin(), new_index.end(), -1),
            static_cast<long>(new_index.size()))
      << "a deleted vertex got an index";
}

}  // namespace
}  // namespace neuralmesh
