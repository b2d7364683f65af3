#include "proto/packing.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

namespace neuralmesh {
namespace {

TEST(PackingTest, PointsOfARangeAreLittleEndianFloatsWithTheirWeights) {
  PointCloud cloud;
  cloud.positions = {Vec3f(1, 2, 3), Vec3f(4, 5, 6), Vec3f(7, 8, 9)};
  cloud.weights = {0.5f, 1.5f, 2.5f};
  const v1::PointBatch batch = PackPointBatch(cloud, 1, 3);
  ASSERT_TRUE(batch.has_first_point());
  EXPECT_EQ(batch.first_point().value(), 1u);
  ASSERT_TRUE(batch.has_packed());
  ASSERT_EQ(batch.packed().positions().size(), 2 * 12u);
  ASSERT_EQ(batch.packed().weights().size(), 2 * 4u);
  EXPECT_TRUE(batch.packed().normals().empty());
  float first[3];
  std::memcpy(first, batch.packed().positions().data(), sizeof(first));
  EXPECT_EQ(first[0], 4.0f);
  EXPECT_EQ(first[2], 6.0f);
  float weight;
  std::memcpy(&weight, batch.packed().weights().data() + 4, sizeof(weight));
  EXPECT_EQ(weight, 2.5f);

  cloud.normals = {Vec3f(0, 0, 1), Vec3f(0, 1, 0), Vec3f(1, 0, 0)};
  const v1::PackedPoints all = PackPoints(cloud, 0, 3);
  ASSERT_EQ(all.normals().size(), 3 * 12u);
  float normal[3];
  std::memcpy(normal, all.normals().data() + 24, sizeof(normal));
  EXPECT_EQ(normal[0], 1.0f);
  EXPECT_TRUE(PackPoints(cloud, 2, 2).positions().empty());
}

TEST(PackingTest, AMeshIsItsPositionsAndItsFacesExactly) {
  TriangleMesh mesh;
  mesh.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 0, 0.1f)};
  mesh.faces = {{0, 1, 2}, {0, 3, 1}};
  const v1::PackedMesh packed = PackMesh(mesh);
  ASSERT_EQ(packed.positions().size(), 4 * 12u);
  ASSERT_EQ(packed.faces().size(), 2 * 12u);
  float z;
  std::memcpy(&z, packed.positions().data() + 3 * 12 + 8, sizeof(z));
  EXPECT_EQ(z, 0.1f);
  uint32_t second[3];
  std::memcpy(second, packed.faces().data() + 12, sizeof(second));
  EXPECT_EQ(second[0], 0u);
  EXPECT_EQ(second[1], 3u);
  EXPECT_EQ(second[2], 1u);
}

}  // namespace
}  // namespace neuralmesh
