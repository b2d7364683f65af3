#include "core/analysis/color_source.h"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>

#include "core/analysis/statistical_outliers.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using testing::ColorError;
using ::testing::HasSubstr;

std::unique_ptr<ColorSource> MustMake(absl::StatusOr<std::unique_ptr<ColorSource>> source) {
  EXPECT_TRUE(source.ok()) << source.status();
  return source.ok() ? *std::move(source) : nullptr;
}

TEST(PointColorSourceTest, AVertexOnAPointTakesItsColourAndOneBetweenBlendsByDistance) {
  PointCloud cloud;
  cloud.positions = {Vec3f(0, 0, 0), Vec3f(4, 0, 0), Vec3f(100, 0, 0)};
  cloud.colors = {{200, 0, 40}, {0, 100, 240}, {9, 9, 9}};
  PointColorOptions two;
  two.neighbours = 2;
  const std::unique_ptr<ColorSource> source = MustMake(MakePointColorSource(cloud, two));
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->ColorAt(Vec3f(0, 0, 0)), (Rgb{200, 0, 40}));
  EXPECT_EQ(source->ColorAt(Vec3f(4, 0, 0)), (Rgb{0, 100, 240}));
  // At x = 1 the points are 1 and 3 away: weights 1 and 1/3, so 3/4 of the first colour.
  EXPECT_EQ(source->ColorAt(Vec3f(1, 0, 0)), (Rgb{150, 25, 90}));
  // The far point is never among the two nearest of a query near the others.
  EXPECT_EQ(source->ColorAt(Vec3f(2, 1, 0)), (Rgb{100, 50, 140}));
}

// A sphere's points coloured by position paint a finer mesh of the sphere with the colours of
// its vertices' positions, to within the spread of their 8 nearest points.
TEST(PointColorSourceTest, PaintsAMeshWithTheColoursOfItsPositions) {
  const PointCloud cloud = testing::ColoredUnitSpherePoints(20000, 7);
  const std::unique_ptr<ColorSource> source = MustMake(MakePointColorSource(cloud));
  ASSERT_NE(source, nullptr);
  TriangleMesh mesh = testing::Icosphere(4);
  source->Paint(&mesh);
  ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
  int worst = 0;
  double sum = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const int error = ColorError(mesh.colors[v], mesh.positions[v]);
    worst = std::max(worst, error);
    sum += error;
  }
  // Points lie about 0.025 apart, a level is 1/127.5 of a unit: the nearest 8 are within about
  // 6 levels, and their weighted mean nearer still.
  EXPECT_LE(worst, 4);
  EXPECT_LT(sum / mesh.positions.size(), 1.0);
}

TEST(PointColorSourceTest, RefusesPointsWithoutColoursAndBadOptions) {
  PointCloud cloud = testing::ColoredUnitSpherePoints(10, 1);
  PointColorOptions none;
  none.neighbours = 0;
  absl::StatusOr<std::unique_ptr<ColorSource>> bad = MakePointColorSource(cloud, none);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(bad.status().message()), HasSubstr("colour neighbours = 0"));
  cloud.colors.clear();
  bad = MakePointColorSource(cloud);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(bad.status().message()), HasSubstr("0 colours for 10 points"));
  bad = MakePointColorSource(PointCloud{});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
}

// Points that arrive in batches of every size paint as the whole set so far would.
TEST(GrowingPointColorsTest, PaintsAsThePointsSoFarWould) {
  const PointCloud cloud = testing::ColoredUnitSpherePoints(30000, 11);
  GrowingPointColors growing;
  TriangleMesh mesh = testing::Icosphere(2);
  growing.Paint(&mesh);
  EXPECT_TRUE(mesh.colors.empty()) << "painted without points";
  size_t begin = 0;
  for (const size_t batch : {1, 7, 1, 300, 5000, 40, 40, 40, 12000, 1, 2611, 9959}) {
    const size_t end = begin + batch;
    ASSERT_LE(end, cloud.size());
    // In two appends (the second empty for a batch of one) taken by one paint.
    for (const auto& [at, count] :
         {std::pair(begin, batch / 2), std::pair(begin + batch / 2, batch - batch / 2)}) {
      growing.Append(absl::MakeConstSpan(cloud.positions).subspan(at, count),
                     absl::MakeConstSpan(cloud.colors).subspan(at, count));
    }
    begin = end;
    ASSERT_EQ(growing.size(), end);
    growing.Paint(&mesh);
    if (batch == 40) growing.Paint(&mesh);  // Nothing new: the same trees.
    const std::unique_ptr<ColorSource> whole =
        MustMake(MakePointColorSource(PointRange(cloud, 0, end)));
    ASSERT_NE(whole, nullptr);
    TriangleMesh expected = mesh;
    whole->Paint(&expected);
    ASSERT_EQ(mesh.colors, expected.colors) << "after " << end << " points";
  }
  EXPECT_EQ(begin, cloud.size());
}

TEST(MeshColorSourceTest, InterpolatesAcrossTheNearestTriangle) {
  TriangleMesh triangle;
  triangle.positions = {Vec3f(0, 0, 0), Vec3f(3, 0, 0), Vec3f(0, 3, 0)};
  triangle.faces = {{0, 1, 2}};
  triangle.colors = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}};
  const std::unique_ptr<ColorSource> source = MustMake(MakeMeshColorSource(triangle));
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->ColorAt(Vec3f(0, 0, 0)), (Rgb{255, 0, 0}));
  EXPECT_EQ(source->ColorAt(Vec3f(1, 1, 0)), (Rgb{85, 85, 85}));     // The centroid.
  EXPECT_EQ(source->ColorAt(Vec3f(1.5, 0, 2)), (Rgb{128, 128, 0}));  // Above an edge's middle.
  EXPECT_EQ(source->ColorAt(Vec3f(-5, -5, 1)), (Rgb{255, 0, 0}));    // Nearest: a corner.
}

TEST(MeshColorSourceTest, RefusesAMeshWithoutColoursOrFaces) {
  TriangleMesh mesh = testing::Icosphere(1);
  absl::StatusOr<std::unique_ptr<ColorSource>> bad = MakeMeshColorSource(mesh);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(bad.status().message()), HasSubstr("0 colours for 42 vertices"));
  mesh.colors.assign(mesh.positions.size(), Rgb{1, 2, 3});
  mesh.faces.clear();
  EXPECT_EQ(MakeMeshColorSource(mesh).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(StatisticalOutliersColorTest, RemovalKeepsEachColourWithItsPoint) {
  PointCloud cloud = testing::ColoredUnitSpherePoints(2000, 2);
  cloud.positions.push_back(Vec3f(50, 0, 0));
  cloud.colors.push_back({1, 2, 3});
  const absl::StatusOr<std::vector<bool>> outliers = FindStatisticalOutliers(cloud, {});
  ASSERT_TRUE(outliers.ok()) << outliers.status();
  const PointCloud kept = WithoutPoints(cloud, *outliers);
  ASSERT_EQ(kept.size(), 2000u);
  ASSERT_EQ(kept.colors.size(), kept.size());
  for (size_t i = 0; i < kept.size(); ++i) {
    ASSERT_EQ(ColorError(kept.colors[i], kept.positions[i]), 0) << "point " << i;
  }
}

}  // namespace
}  // namespace neuralmesh
