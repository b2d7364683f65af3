#include "core/learning/initial_mesh.h"

#include <cmath>
#include <string>
#include <vector>

#include "core/mesh_validation.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

// Signed distance of `p` to the plane of face `f`, positive outside (faces point outward).
double OutsideDistance(const Mesh& mesh, Mesh::FaceHandle f, const Vec3& p) {
  std::vector<Vec3> corners;
  for (auto v : mesh.fv_range(f)) corners.push_back(mesh.point(v));
  const Vec3 normal = ((corners[1] - corners[0]) % (corners[2] - corners[0])).normalized();
  return (p - corners[0]) | normal;
}

TEST(InitialMeshTest, ARegularTetrahedronOrientedOutwardOnTheSphereThroughTheBoxCorners) {
  BoundingBox box;
  box.Extend(Vec3(-1, 2, 0.5));
  box.Extend(Vec3(3, 2.5, 4));
  const Mesh mesh = MakeInitialTetrahedron(box);
  ASSERT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  ASSERT_EQ(mesh.n_vertices(), 4u);
  ASSERT_EQ(mesh.n_faces(), 4u);
  for (auto v : mesh.vertices()) {
    EXPECT_FALSE(mesh.is_boundary(v));
    EXPECT_NEAR((mesh.point(v) - box.center()).norm(), box.diagonal() / 2, 1e-9);
  }
  for (auto e : mesh.edges()) {  // Regular: every edge sqrt(8/3) times the circumradius.
    EXPECT_NEAR(mesh.calc_edge_length(e), std::sqrt(8.0 / 3.0) * box.diagonal() / 2, 1e-9);
  }
  // Outward: the centre is behind every face, at the inscribed radius, a third of the
  // circumradius.
  for (auto f : mesh.faces()) {
    EXPECT_NEAR(OutsideDistance(mesh, f, box.center()), -box.diagonal() / 6, 1e-9);
  }
}

TEST(InitialMeshTest, AOnePointBoxGetsAUnitSizeTetrahedronThere) {
  BoundingBox box;
  box.Extend(Vec3(5, 6, 7));
  const Mesh mesh = MakeInitialTetrahedron(box);
  for (auto v : mesh.vertices()) EXPECT_NEAR((mesh.point(v) - Vec3(5, 6, 7)).norm(), 1, 1e-9);
}

BestFitPlane TiltedPlane(double radius) {
  BestFitPlane plane;
  plane.center = Vec3(1, 2, 3);
  plane.u = Vec3(1, 1, 0).normalized();
  plane.normal = Vec3(1, -1, 1).normalized();
  plane.v = OpenMesh::cross(plane.normal, plane.u);
  plane.radius = radius;
  return plane;
}

TEST(InitialMeshTest, ADiscIsAHexagonInThePlaneFacingAlongItsNormal) {
  const BestFitPlane plane = TiltedPlane(2.5);
  const Mesh mesh = MakeInitialDisc(plane);
  ASSERT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  ASSERT_EQ(mesh.n_vertices(), 7u);
  ASSERT_EQ(mesh.n_faces(), 6u);
  int interior = 0;
  for (auto v : mesh.vertices()) {
    const Vec3 d = mesh.point(v) - plane.center;
    EXPECT_NEAR(OpenMesh::dot(d, plane.normal), 0, 1e-12) << "off the plane";
    if (mesh.is_boundary(v)) {
      EXPECT_NEAR(d.norm(), 2.5, 1e-12) << "a corner off the circle of the data's radius";
    } else {
      ++interior;
      EXPECT_NEAR(d.norm(), 0, 1e-12) << "the interior vertex is the centre";
      EXPECT_EQ(mesh.valence(v), 6u);
    }
  }
  EXPECT_EQ(interior, 1) << "one interior vertex, which Step 2 can split";
  EXPECT_NEAR(OpenMesh::dot(mesh.point(Mesh::VertexHandle(1)) - plane.center, plane.u), 2.5, 1e-12)
      << "the first corner lies along u";
  for (auto f : mesh.faces()) {
    EXPECT_NEAR(OpenMesh::dot(mesh.calc_face_normal(f), plane.normal), 1, 1e-12)
        << "a face turned away from the plane's normal";
  }
}

TEST(InitialMeshTest, ADiscOfRadiusZeroGetsRadiusOne) {
  const Mesh mesh = MakeInitialDisc(TiltedPlane(0));
  for (auto v : mesh.vertices()) {
    if (mesh.is_boundary(v)) {
      EXPECT_NEAR((mesh.point(v) - Vec3(1, 2, 3)).norm(), 1, 1e-12);
    }
  }
}

// A regular octahedron, faces counter-clockwise seen from outside.
TriangleMesh Octahedron() {
  TriangleMesh mesh;
  mesh.positions = {Vec3f(1, 0, 0), Vec3f(-1, 0, 0), Vec3f(0, 1, 0),
                    Vec3f(0, -1, 0), Vec3f(0, 0, 1), Vec3f(0, 0, -1)};
  mesh.faces = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return mesh;
}

TEST(InitialMeshTest, AStartMeshKeepsItsVerticesFacesAndOrientation) {
  const TriangleMesh octahedron = Octahedron();
  absl::StatusOr<Mesh> mesh = MakeStartMesh(octahedron);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  ASSERT_TRUE(ValidateMesh(*mesh).ok()) << ValidateMesh(*mesh);
  ASSERT_EQ(mesh->n_vertices(), 6u);
  ASSERT_EQ(mesh->n_faces(), 8u);
  for (auto v : mesh->vertices()) {
    const Vec3f& p = octahedron.positions[v.idx()];
    EXPECT_EQ(mesh->point(v), Vec3(p[0], p[1], p[2]));
  }
  for (auto f : mesh->faces()) {
    EXPECT_LT(OutsideDistance(*mesh, f, Vec3(0, 0, 0)), 0) << "face " << f.idx() << " turned";
  }
}

TEST(InitialMeshTest, AStartMeshThatLearningCannotGoOnFromIsRejectedWithTheReason) {
  struct Case {
    const char* what;
    TriangleMesh mesh;
    const char* message;
  };
  std::vector<Case> cases;
  {
    TriangleMesh triangle;
    triangle.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
    triangle.faces = {{0, 1, 2}};
    cases.push_back({"one triangle", triangle, "has 3 vertices; learning needs at least 4"});
  }
  TriangleMesh nan = Octahedron();
  nan.positions[3][1] = std::nanf("");
  cases.push_back({"a NaN", nan, "vertex 3 of the start mesh has a coordinate that is not finite"});
  TriangleMesh beyond = Octahedron();
  beyond.faces[2][1] = 6;
  cases.push_back({"an index past the end", beyond, "face 2 refers to a vertex index beyond"});
  TriangleMesh repeated = Octahedron();
  repeated.faces[5][2] = repeated.faces[5][0];
  cases.push_back({"a repeated index", repeated, "face 5 repeats a vertex"});
  TriangleMesh fin = Octahedron();
  fin.positions.push_back(Vec3f(2, 2, 0));
  fin.faces.push_back({0, 2, 6});  // A third face on the edge 0-2.
  cases.push_back({"three faces on an edge", fin, "non-manifold or inconsistently oriented"});
  TriangleMesh unused = Octahedron();
  unused.positions.push_back(Vec3f(3, 3, 3));
  cases.push_back({"an unused vertex", unused, "vertex 6 is isolated"});
  TriangleMesh flat = Octahedron();
  flat.positions[4] = Vec3f(0.5f, 0.5f, 0);  // On the segment from vertex 0 to vertex 2.
  cases.push_back({"a face of zero area", flat, "face 0 of the start mesh has zero area"});
  for (const Case& c : cases) {
    absl::StatusOr<Mesh> mesh = MakeStartMesh(c.mesh);
    ASSERT_FALSE(mesh.ok()) << c.what;
    EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument) << c.what;
    EXPECT_NE(mesh.status().message().find(c.message), std::string::npos)
        << c.what << ": " << mesh.status();
  }
}

}  // namespace
}  // namespace neuralmesh
