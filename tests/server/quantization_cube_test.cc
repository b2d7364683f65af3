#include "server/quantization_cube.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace neuralmesh::server {
namespace {

using ::testing::HasSubstr;

BoundingBox Box(const Vec3& min, const Vec3& max) {
  BoundingBox b;
  b.min = min;
  b.max = max;
  return b;
}

TEST(QuantizationCubeTest, TheFirstCubeHoldsItsBoundsEnlarged) {
  const absl::StatusOr<QuantizationBox> cube =
      QuantizationCube(Box(Vec3(0, 0, 0), Vec3(2, 1, 1)), 1.1, 11);
  ASSERT_TRUE(cube.ok()) << cube.status();
  EXPECT_GE(cube->range, 2.2f);
  EXPECT_LT(cube->range, 2.3f) << "enlarged by about 1.1, widened only to a value Draco keeps";
  EXPECT_TRUE(CubeContains(*cube, Box(Vec3(0, 0, 0), Vec3(2, 1, 1))));
}

TEST(QuantizationCubeTest, GrowingDoublesUntilTheBoundsFit) {
  const absl::StatusOr<QuantizationBox> cube =
      QuantizationCube(Box(Vec3(0, 0, 0), Vec3(1, 1, 1)), 1.0, 11);
  ASSERT_TRUE(cube.ok());
  const BoundingBox far = Box(Vec3(0, 0, 0), Vec3(100, 1, 1));
  const absl::StatusOr<QuantizationBox> grown = GrowQuantizationCube(*cube, far, 11);
  ASSERT_TRUE(grown.ok()) << grown.status();
  EXPECT_TRUE(CubeContains(*grown, far));
  EXPECT_LE(grown->range, 2 * 128 * cube->range) << "doubled no more than needed";
}

// Growth toward coordinates near the largest float used to loop forever (the cube's origin
// became -inf and its range, through DracoExactBox, 0).
TEST(QuantizationCubeTest, BoundsNoUsableCubeHoldsAreRefused) {
  const absl::StatusOr<QuantizationBox> unit =
      QuantizationCube(Box(Vec3(0, 0, 0), Vec3(1, 1, 1)), 1.0, 11);
  ASSERT_TRUE(unit.ok());
  for (const double far : {3.3e38, 1.8e38, 1e38}) {
    const BoundingBox huge = Box(Vec3(-far, 0, 0), Vec3(far, 1, 1));
    const absl::StatusOr<QuantizationBox> grown = GrowQuantizationCube(*unit, huge, 11);
    EXPECT_EQ(grown.status().code(), absl::StatusCode::kInvalidArgument) << far;
    EXPECT_THAT(std::string(grown.status().message()), HasSubstr("need a quantization cube"));
    EXPECT_EQ(QuantizationCube(huge, 2.0, 11).status().code(),
              absl::StatusCode::kInvalidArgument)
        << far;
  }
}

}  // namespace
}  // namespace neuralmesh::server
