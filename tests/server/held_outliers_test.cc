#include "server/held_outliers.h"

#include <gtest/gtest.h>

#include <vector>

namespace neuralmesh::server {
namespace {

PointCloud Cloud(int n, bool weights, bool normals) {
  PointCloud cloud;
  for (int i = 0; i < n; ++i) {
    cloud.positions.push_back(Vec3f(static_cast<float>(i), 0, 0));
    if (weights) cloud.weights.push_back(0.5f * static_cast<float>(i));
    if (normals) cloud.normals.push_back(Vec3f(0, 0, static_cast<float>(i + 1)));
  }
  return cloud;
}

// Held points come back whole, in the order asked for, by arrival index.
TEST(HeldOutliersTest, ReleasedPointsKeepTheirWeightsAndNormals) {
  HeldOutliers held;
  held.Hold(Cloud(4, true, true), {false, true, false, true}, 100);  // Arrival 101 and 103.
  EXPECT_EQ(held.size(), 2u);
  PointCloud cloud = Cloud(1, true, true);
  held.AppendTo({103, 101}, &cloud);
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud.positions[1], Vec3f(3, 0, 0));
  EXPECT_EQ(cloud.positions[2], Vec3f(1, 0, 0));
  EXPECT_EQ(cloud.weights, (std::vector<float>{0, 1.5f, 0.5f}));
  EXPECT_EQ(cloud.normals[1], Vec3f(0, 0, 4));
  EXPECT_EQ(cloud.normals[2], Vec3f(0, 0, 2));
  EXPECT_EQ(held.size(), 2u) << "AppendTo keeps them";
  held.Forget({101, 103});
  EXPECT_EQ(held.size(), 0u);
}

// Where only one side has weights (normals), the other's points get weight 1 (a zero normal),
// as GrowingPointCloud gives them.
TEST(HeldOutliersTest, MissingWeightsAndNormalsGetTheDefaults) {
  HeldOutliers held;
  held.Hold(Cloud(2, true, false), {true, true}, 0);
  held.Hold(Cloud(1, false, true), {true}, 2);
  PointCloud plain = Cloud(2, false, false);
  held.AppendTo({1, 2}, &plain);
  EXPECT_EQ(plain.weights, (std::vector<float>{1, 1, 0.5f, 1}));
  ASSERT_EQ(plain.normals.size(), 4u);
  EXPECT_EQ(plain.normals[1], Vec3f(0, 0, 0));
  EXPECT_EQ(plain.normals[2], Vec3f(0, 0, 0));
  EXPECT_EQ(plain.normals[3], Vec3f(0, 0, 1)) << "its own normal";
  PointCloud untouched = Cloud(2, false, false);
  held.AppendTo({}, &untouched);
  EXPECT_TRUE(untouched.weights.empty());
  EXPECT_TRUE(untouched.normals.empty());
  held.Forget({0, 7});  // An index never held is ignored.
  EXPECT_EQ(held.size(), 2u);
}

// Colours stay with their points when every point has one, and are left out rather than made
// up when some point has none.
TEST(HeldOutliersTest, ColoursAreKeptOnlyWhenEveryPointHasOne) {
  auto colored = [](int n, uint8_t shade) {
    PointCloud cloud = Cloud(n, false, false);
    cloud.colors.assign(n, Rgb{shade, shade, shade});
    return cloud;
  };
  HeldOutliers held;
  held.Hold(colored(2, 7), {true, true}, 0);
  held.Hold(Cloud(1, false, false), {true}, 2);
  PointCloud all_colored = colored(1, 9);
  held.AppendTo({1, 0}, &all_colored);
  EXPECT_EQ(all_colored.colors, (std::vector<Rgb>{{9, 9, 9}, {7, 7, 7}, {7, 7, 7}}));
  PointCloud with_uncolored = colored(1, 9);
  held.AppendTo({0, 2}, &with_uncolored);
  EXPECT_EQ(with_uncolored.size(), 3u);
  EXPECT_TRUE(with_uncolored.colors.empty());
  PointCloud plain = Cloud(1, false, false);
  held.AppendTo({0}, &plain);
  EXPECT_EQ(plain.size(), 2u);
  EXPECT_TRUE(plain.colors.empty()) << "the cloud's own point has no colour";
  PointCloud none;  // Nothing but released points, all coloured.
  held.AppendTo({1}, &none);
  EXPECT_EQ(none.colors, (std::vector<Rgb>{{7, 7, 7}}));
}

}  // namespace
}  // namespace neuralmesh::server
