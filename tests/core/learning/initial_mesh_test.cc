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

TEST(InitialMeshTest, TheTetrahedronIsClosedOrientedOutwardAndHoldsTheWholeBox) {
  BoundingBox box;
  box.Extend(Vec3(-1, 2, 0.5));
  box.Extend(Vec3(3, 2.5, 4));
  const Mesh mesh = MakeInitialTetrahedron(box);
  ASSERT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  ASSERT_EQ(mesh.n_vertices(), 4u);
  ASSERT_EQ(mesh.n_faces(), 4u);
  for (auto v : mesh.vertices()) EXPECT_FALSE(mesh.is_boundary(v));
  // Every corner of the box is inside every face's plane, the box's centre most of all.
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p((corner & 1) ? box.max[0] : box.min[0], (corner & 2) ? box.max[1] : box.min[1],
                 (corner & 4) ? box.max[2] : box.min[2]);
    for (auto f : mesh.faces()) EXPECT_LE(OutsideDistance(mesh, f, p), 1e-9) << corner;
  }
  // Its inscribed sphere is the sphere through the box's corners: centred on the box.
  for (auto f : mesh.faces()) {
    EXPECT_NEAR(OutsideDistance(mesh, f, box.center()), -box.diagonal() / 2, 1e-9);
  }
}

TEST(InitialMeshTest, AOnePointBoxGetsAUnitSizeTetrahedronAroundIt) {
  BoundingBox box;
  box.Extend(Vec3(5, 6, 7));
  const Mesh mesh = MakeInitialTetrahedron(box);
  for (auto f : mesh.faces()) EXPECT_NEAR(OutsideDistance(mesh, f, Vec3(5, 6, 7)), -1, 1e-9);
}

}  // namespace
}  // namespace neuralmesh
