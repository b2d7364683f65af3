#include "core/analysis/geometric_error.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "core/analysis/triangle_tree.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using ::neuralmesh::testing::GridPatch;
using ::neuralmesh::testing::Icosphere;

GeometricErrorOptions FewSamples(size_t samples = 20000) {
  GeometricErrorOptions options;
  options.samples = samples;
  return options;
}

TEST(GeometricErrorTest, IdenticalMeshesHaveZeroErrorAndFullNormalConsistency) {
  const TriangleMesh sphere = Icosphere(3);
  const absl::StatusOr<GeometricError> error = ComputeGeometricError(sphere, sphere, FewSamples());
  ASSERT_TRUE(error.ok()) << "comparing a mesh with itself failed: " << error.status();
  EXPECT_LT(error->chamfer_l1, 1e-9) << "a mesh is at distance 0 from itself";
  EXPECT_LT(error->hausdorff, 1e-9) << "a mesh is at Hausdorff distance 0 from itself";
  EXPECT_LT(error->accuracy, 1e-9) << "accuracy of a mesh against itself";
  EXPECT_LT(error->completeness, 1e-9) << "completeness of a mesh against itself";
  EXPECT_NEAR(error->normal_consistency, 1.0, 1e-6) << "normals of a mesh agree with themselves";
  EXPECT_GT(error->diagonal, 3.0) << "the diagonal of a unit sphere's box is about 2 sqrt(3)";
}

TEST(GeometricErrorTest, ConcentricSpheresAreTheirRadiusGapApart) {
  const TriangleMesh inner = Icosphere(4, 1.0);
  const TriangleMesh outer = Icosphere(4, 1.01);
  const absl::StatusOr<GeometricError> error =
      ComputeGeometricError(inner, outer, FewSamples(50000));
  ASSERT_TRUE(error.ok()) << error.status();
  const double gap = 0.01 / error->diagonal;
  EXPECT_NEAR(error->chamfer_l1, gap, 0.03 * gap)
      << "chamfer should be the radius gap over the diagonal";
  EXPECT_NEAR(error->accuracy, gap, 0.03 * gap) << "one-sided mean inner -> outer";
  EXPECT_NEAR(error->completeness, gap, 0.03 * gap) << "one-sided mean outer -> inner";
  EXPECT_NEAR(error->hausdorff, gap, 0.03 * gap) << "the largest gap is the radius gap";
  EXPECT_GT(error->normal_consistency, 0.999) << "parallel faces have parallel normals";
}

TEST(GeometricErrorTest, HausdorffCatchesOneSpikeVertex) {
  const TriangleMesh reference = Icosphere(3);
  TriangleMesh spiky = reference;
  spiky.positions[0] *= 2.f;  // One vertex pulled out to radius 2.
  const absl::StatusOr<GeometricError> error =
      ComputeGeometricError(spiky, reference, FewSamples());
  ASSERT_TRUE(error.ok()) << error.status();
  EXPECT_NEAR(error->hausdorff * error->diagonal, 1.0, 1e-5)
      << "the spike tip is at distance 1 from the unit sphere";
  EXPECT_LT(error->chamfer_l1, 0.01 * error->hausdorff)
      << "a single thin spike barely moves the mean";
}

TEST(GeometricErrorTest, AccuracyAndCompletenessHaveTheirDirections) {
  // The reconstruction covers half the reference: accurate but incomplete.
  const TriangleMesh reference = Icosphere(3);
  TriangleMesh half = reference;
  half.faces.clear();
  for (const auto& f : reference.faces) {
    if (reference.positions[f[0]][2] + reference.positions[f[1]][2] + reference.positions[f[2]][2] >
        0) {
      half.faces.push_back(f);
    }
  }
  const absl::StatusOr<GeometricError> error = ComputeGeometricError(half, reference, FewSamples());
  ASSERT_TRUE(error.ok()) << error.status();
  EXPECT_LT(error->accuracy, 1e-9) << "every reconstruction point lies on the reference";
  EXPECT_GT(error->completeness, 0.05) << "half the reference is far from the reconstruction";
  EXPECT_NEAR(error->chamfer_l1, 0.5 * (error->accuracy + error->completeness), 1e-15)
      << "chamfer is the mean of the two sides";
}

TEST(GeometricErrorTest, DeterministicForASeedAndThreadCount) {
  const TriangleMesh a = Icosphere(3, 1.0);
  TriangleMesh b = Icosphere(2, 1.05);
  GeometricErrorOptions options = FewSamples(5000);
  options.threads = 1;
  const auto first = ComputeGeometricError(a, b, options);
  options.threads = 2;
  const auto second = ComputeGeometricError(a, b, options);
  options.seed = 99;
  const auto other_seed = ComputeGeometricError(a, b, options);
  ASSERT_TRUE(first.ok() && second.ok() && other_seed.ok()) << "valid inputs failed";
  EXPECT_EQ(first->chamfer_l1, second->chamfer_l1) << "thread count changed the chamfer";
  EXPECT_EQ(first->hausdorff, second->hausdorff) << "thread count changed the Hausdorff";
  EXPECT_EQ(first->normal_consistency, second->normal_consistency)
      << "thread count changed the normal consistency";
  EXPECT_NE(first->chamfer_l1, other_seed->chamfer_l1) << "the seed should change the samples";
  EXPECT_NEAR(first->chamfer_l1, other_seed->chamfer_l1, 0.05 * first->chamfer_l1)
      << "different seeds should estimate the same chamfer";
}

TEST(GeometricErrorTest, RejectsInvalidInput) {
  const TriangleMesh good = Icosphere(1);
  auto code = [](const absl::StatusOr<GeometricError>& r) { return r.status().code(); };
  EXPECT_EQ(code(ComputeGeometricError(TriangleMesh(), good)), absl::StatusCode::kInvalidArgument)
      << "an empty reconstruction must be rejected";
  EXPECT_EQ(code(ComputeGeometricError(good, TriangleMesh())), absl::StatusCode::kInvalidArgument)
      << "an empty reference must be rejected";
  TriangleMesh no_faces = good;
  no_faces.faces.clear();
  EXPECT_EQ(code(ComputeGeometricError(no_faces, good)), absl::StatusCode::kInvalidArgument)
      << "a reconstruction without faces must be rejected";
  TriangleMesh nan = good;
  nan.positions[5][0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(code(ComputeGeometricError(good, nan)), absl::StatusCode::kInvalidArgument)
      << "a NaN position must be rejected";
  TriangleMesh out_of_range = good;
  out_of_range.faces[2][0] = 1000;
  EXPECT_EQ(code(ComputeGeometricError(out_of_range, good)), absl::StatusCode::kInvalidArgument)
      << "an out-of-range index must be rejected";
  TriangleMesh flat = good;
  for (auto& f : flat.faces) f = {f[0], f[0], f[0]};
  EXPECT_EQ(code(ComputeGeometricError(good, flat)), absl::StatusCode::kInvalidArgument)
      << "a zero-area reference must be rejected";
  EXPECT_EQ(code(ComputeGeometricError(good, good, FewSamples(0))),
            absl::StatusCode::kInvalidArgument)
      << "zero samples must be rejected";
  EXPECT_EQ(
      code(ComputeGeometricError(good, good, FewSamples(GeometricErrorOptions::kMaxSamples + 1))),
      absl::StatusCode::kInvalidArgument)
      << "more samples than the bound must be refused, not allocated";
}

// Points measured a block at a time (65,536 to a block) give what each point's own distance
// gives: completeness is their mean, in their order, and the Hausdorff distance at least their
// largest (a stray in the last block); the normals, the sphere's own, agree.
TEST(GeometricErrorTest, AgainstPointsMeasuresEveryPointOfEveryBlock) {
  PointCloud points = testing::ColoredUnitSpherePoints(150000, 8);
  points.positions.back() = Vec3f(0, 0, 2);  // A stray in the last block, 1 from the sphere.
  for (const Vec3f& p : points.positions) points.normals.push_back(p.normalized());
  const TriangleMesh sphere = Icosphere(4);
  const absl::StatusOr<GeometricError> error =
      ComputeErrorAgainstPoints(sphere, points, FewSamples());
  ASSERT_TRUE(error.ok()) << error.status();
  std::vector<Vec3> queries;
  for (const Vec3f& p : points.positions) queries.emplace_back(p[0], p[1], p[2]);
  const absl::StatusOr<std::vector<double>> distances = DistancesToMesh(queries, sphere);
  ASSERT_TRUE(distances.ok()) << distances.status();
  double sum = 0, largest = 0;
  for (const double d : *distances) {
    sum += d;
    largest = std::max(largest, d);
  }
  EXPECT_EQ(error->completeness, sum / static_cast<double>(points.size()) / error->diagonal);
  EXPECT_NEAR(largest, 1.0, 0.01);
  EXPECT_GE(error->hausdorff * error->diagonal, largest);
  EXPECT_GT(error->normal_consistency, 0.99);
}

// The points of a unit sphere (with their normals) against meshes of it: the mesh itself fits
// them to its tessellation; a sphere 0.1 larger is that far from every point; where the points
// miss a cap, accuracy (mesh to points) sees the mesh over no data and completeness does not.
TEST(GeometricErrorTest, AgainstPointsMeasuresBothWaysInThePointsFrame) {
  PointCloud points = testing::ColoredUnitSpherePoints(20000, 5);
  for (const Vec3f& p : points.positions) points.normals.push_back(p);
  const TriangleMesh sphere = Icosphere(5);
  absl::StatusOr<GeometricError> error = ComputeErrorAgainstPoints(sphere, points, FewSamples());
  ASSERT_TRUE(error.ok()) << error.status();
  const double diagonal = error->diagonal;
  EXPECT_NEAR(diagonal, 2 * std::sqrt(3.0), 0.02) << "the points' box";
  // Icosphere(5): edges of about 0.04, chords 1e-4 to 2e-4 inside the sphere.
  EXPECT_LT(error->completeness * diagonal, 3e-4);
  // A sample's nearest point: within the spacing of 20,000 points (about 0.025).
  EXPECT_LT(error->accuracy * diagonal, 0.015);
  // The widest gap between 20,000 random points, about sqrt(log n / n) across: 0.05.
  EXPECT_LT(error->hausdorff * diagonal, 0.08);
  EXPECT_GT(error->normal_consistency, 0.99);

  const TriangleMesh larger = Icosphere(5, 1.1);
  error = ComputeErrorAgainstPoints(larger, points, FewSamples());
  ASSERT_TRUE(error.ok()) << error.status();
  EXPECT_NEAR(error->completeness * diagonal, 0.1, 0.002);
  EXPECT_NEAR(error->hausdorff * diagonal, 0.1, 0.04);

  PointCloud capless;
  for (size_t i = 0; i < points.size(); ++i) {
    if (points.positions[i][2] > 0.5f) continue;
    capless.positions.push_back(points.positions[i]);
  }
  error = ComputeErrorAgainstPoints(sphere, capless, FewSamples());
  ASSERT_TRUE(error.ok()) << error.status();
  const double capless_diagonal = error->diagonal;
  EXPECT_LT(error->completeness * capless_diagonal, 3e-4) << "every point is on the mesh";
  // A quarter of the sphere's area lies above z = 0.5, its samples up to 1 from the points
  // (the pole to the circle at z = 0.5), 0.25 on average over that cap.
  EXPECT_GT(error->accuracy * capless_diagonal, 0.04);
  EXPECT_NEAR(error->hausdorff * capless_diagonal, 1.0, 0.02);
  EXPECT_TRUE(std::isnan(error->normal_consistency)) << "no normals, no consistency";

  const auto code = [](const absl::StatusOr<GeometricError>& r) { return r.status().code(); };
  EXPECT_EQ(code(ComputeErrorAgainstPoints(sphere, PointCloud())),
            absl::StatusCode::kInvalidArgument);
  PointCloud one_place;
  one_place.positions.assign(3, Vec3f(1, 2, 3));
  EXPECT_EQ(code(ComputeErrorAgainstPoints(sphere, one_place)),
            absl::StatusCode::kInvalidArgument);
  PointCloud nan = capless;
  nan.positions[7][1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(code(ComputeErrorAgainstPoints(sphere, nan)), absl::StatusCode::kInvalidArgument);
  TriangleMesh no_faces = sphere;
  no_faces.faces.clear();
  EXPECT_EQ(code(ComputeErrorAgainstPoints(no_faces, points)),
            absl::StatusCode::kInvalidArgument);
}

TEST(GeometricErrorTest, DistancesToMeshAreExact) {
  const TriangleMesh patch = GridPatch(4, 4);  // [0,1]^2 at z = 0.
  const std::vector<Vec3> points = {Vec3(0.5, 0.5, 0.25), Vec3(0.3, 0.7, -2.0), Vec3(2.0, 0.5, 0.0),
                                    Vec3(-1.0, -1.0, 0.0), Vec3(0.25, 0.25, 0.0)};
  const double expected[] = {0.25, 2.0, 1.0, std::sqrt(2.0), 0.0};
  const absl::StatusOr<std::vector<double>> distances = DistancesToMesh(points, patch);
  ASSERT_TRUE(distances.ok()) << distances.status();
  ASSERT_EQ(distances->size(), points.size()) << "one distance per point expected";
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR((*distances)[i], expected[i], 1e-12) << "point " << i << " distance is wrong";
  }
  const std::vector<Vec3> bad = {Vec3(0, std::numeric_limits<double>::infinity(), 0)};
  EXPECT_EQ(DistancesToMesh(bad, patch).status().code(), absl::StatusCode::kInvalidArgument)
      << "a non-finite query point must be rejected";
}

// A torus grid of n x m quads, 2nm triangles.
TriangleMesh Torus(int n, int m, double minor) {
  TriangleMesh mesh;
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < n; ++i) {
      const double u = 2.0 * M_PI * i / n, v = 2.0 * M_PI * j / m;
      mesh.positions.emplace_back((2.0 + minor * std::cos(v)) * std::cos(u),
                                  (2.0 + minor * std::cos(v)) * std::sin(u), minor * std::sin(v));
    }
  }
  auto id = [&](int i, int j) { return static_cast<uint32_t>((j % m) * n + (i % n)); };
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < n; ++i) {
      mesh.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return mesh;
}

// Timing for the report: a 1M-triangle reference against a 1M-triangle reconstruction with
// the default 200000 samples. Run with --gtest_also_run_disabled_tests.
TEST(GeometricErrorTest, DISABLED_MillionTriangleTiming) {
  const TriangleMesh reference = Torus(1000, 500, 0.5);
  const TriangleMesh reconstruction = Torus(1000, 500, 0.51);
  auto start = std::chrono::steady_clock::now();
  const absl::StatusOr<TriangleTree> tree = TriangleTree::Build(reference);
  const double build =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(tree.ok()) << tree.status();
  start = std::chrono::steady_clock::now();
  const absl::StatusOr<GeometricError> error =
      ComputeGeometricError(reconstruction, reference, GeometricErrorOptions());
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(error.ok()) << error.status();
  std::printf(
      "1M-triangle tree build: %.3f s; full error (two trees, 2 x 200k samples + "
      "2 x 500k vertices): %.3f s; chamfer*diag %.6f, hausdorff*diag %.6f\n",
      build, total, error->chamfer_l1 * error->diagonal, error->hausdorff * error->diagonal);
  EXPECT_NEAR(error->hausdorff * error->diagonal, 0.01, 0.001)
      << "the tori are a minor-radius gap of 0.01 apart";
}

}  // namespace
}  // namespace neuralmesh
