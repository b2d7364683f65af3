// Several point clouds as one (core/io/point_cloud_merge.h): positions kept exactly where the
// clouds share an origin, each point where its own origin put it otherwise, and normals,
// weights and colours kept only where every cloud has them.
#include "core/io/point_cloud_merge.h"

#include <cmath>
#include <vector>

#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

PointCloud Cloud(const std::vector<Vec3f>& positions, const Origin& origin, bool colored) {
  PointCloud cloud;
  cloud.positions = positions;
  cloud.origin = origin;
  for (size_t i = 0; i < positions.size(); ++i) {
    cloud.normals.emplace_back(0, 0, 1);
    if (colored) cloud.colors.push_back({static_cast<uint8_t>(10 * i), 20, 30});
  }
  return cloud;
}

TEST(PointCloudMergeTest, CloudsOfOneOriginAreJoinedAsTheyAre) {
  const Origin utm = {500000, 4100000, 0};
  const std::vector<PointCloud> clouds = {
      Cloud({Vec3f(1.25f, 2, 3), Vec3f(4, 5, 6)}, utm, true),
      Cloud({Vec3f(-7.5f, 8, 9)}, utm, true)};
  const PointCloud merged = MergePointClouds(clouds);
  EXPECT_EQ(merged.origin, utm);
  EXPECT_EQ(merged.positions,
            (std::vector<Vec3f>{Vec3f(1.25f, 2, 3), Vec3f(4, 5, 6), Vec3f(-7.5f, 8, 9)}));
  EXPECT_EQ(merged.normals.size(), 3u);
  EXPECT_EQ(merged.colors, (std::vector<Rgb>{{0, 20, 30}, {10, 20, 30}, {0, 20, 30}}));
  EXPECT_TRUE(merged.weights.empty());
}

TEST(PointCloudMergeTest, CloudsOfOtherOriginsKeepTheirPlacesAndDropWhatOneLacks) {
  // Two tiles whose readers chose origins 1 km apart, and a cloud without an origin.
  const std::vector<PointCloud> clouds = {
      Cloud({Vec3f(100.5f, 200.25f, 3), Vec3f(900, 950, 4)}, {500000, 4100000, 0}, true),
      Cloud({Vec3f(10.125f, 20, 5)}, {501000, 4100000, 0}, false),
      Cloud({Vec3f(1, 2, 3)}, kNoOrigin, true)};
  const PointCloud merged = MergePointClouds(clouds);
  const double expected[4][3] = {{500100.5, 4100200.25, 3},
                                 {500900, 4100950, 4},
                                 {501010.125, 4100020, 5},
                                 {1, 2, 3}};
  ASSERT_EQ(merged.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    for (int c = 0; c < 3; ++c) {
      // A float's step where the merged origin puts the point: the box spans 4.1e6 m here.
      EXPECT_NEAR(merged.origin[c] + merged.positions[i][c], expected[i][c], 0.5)
          << "point " << i << " axis " << c;
    }
  }
  EXPECT_EQ(merged.normals.size(), 4u);
  EXPECT_TRUE(merged.colors.empty()) << "the second cloud has none";

  // Without the far cloud, the tiles keep their centimetres.
  const PointCloud tiles = MergePointClouds({clouds[0], clouds[1]});
  EXPECT_EQ(tiles.origin, (Origin{500000, 4100000, 0}));
  for (int i = 0; i < 3; ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(tiles.origin[c] + tiles.positions[i][c], expected[i][c], 1e-4) << i;
    }
  }
}

}  // namespace
}  // namespace neuralmesh
