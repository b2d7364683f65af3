#include "core/learning/initial_mesh.h"

#include <cmath>
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

}  // namespace
}  // namespace neuralmesh
