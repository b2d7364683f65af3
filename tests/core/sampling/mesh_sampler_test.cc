#include "core/sampling/mesh_sampler.h"

#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

std::shared_ptr<const TriangleMesh> Share(TriangleMesh mesh) {
  return std::make_shared<const TriangleMesh>(std::move(mesh));
}

// Two separate triangles: area 0.5 at x in [0, 1], area 1.5 at x in [2, 5].
TriangleMesh TwoTriangles() {
  TriangleMesh mesh;
  mesh.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0),
                    Vec3f(2, 0, 0), Vec3f(5, 0, 0), Vec3f(2, 1, 0)};
  mesh.faces = {{0, 1, 2}, {3, 4, 5}};
  return mesh;
}

// The unit grid with a Gaussian bump of height 0.25 and width 0.08 at its centre.
TriangleMesh GridWithBump() {
  TriangleMesh mesh = testing::GridPatch(60, 60);
  for (Vec3f& p : mesh.positions) {
    const double r2 = (p[0] - 0.5) * (p[0] - 0.5) + (p[1] - 0.5) * (p[1] - 0.5);
    p[2] = static_cast<float>(0.25 * std::exp(-r2 / (2 * 0.08 * 0.08)));
  }
  return mesh;
}

TEST(MeshSamplerTest, AreaModeFollowsTriangleAreas) {
  absl::StatusOr<std::unique_ptr<Sampler>> sampler = MeshSampler::Create(Share(TwoTriangles()));
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  Random rng(1);
  int small = 0;
  int large = 0;
  for (int i = 0; i < 100000; ++i) {
    const Vec3 p = (*sampler)->Sample(rng);
    (p[0] < 1.5 ? small : large)++;
  }
  ASSERT_GT(small, 0) << "the small triangle was never drawn";
  EXPECT_NEAR(large / static_cast<double>(small), 3.0, 0.1)
      << "a triangle of 3 times the area should get 3 times the samples";
}

TEST(MeshSamplerTest, PointsAreUniformInsideTheTriangle) {
  TriangleMesh mesh;
  mesh.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  mesh.faces = {{0, 1, 2}};
  absl::StatusOr<std::unique_ptr<Sampler>> sampler = MeshSampler::Create(Share(mesh));
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  Random rng(2);
  const int n = 100000;
  int left = 0;
  int near_corner = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3 p = (*sampler)->Sample(rng);
    ASSERT_TRUE(p[0] >= 0 && p[1] >= 0 && p[0] + p[1] <= 1 + 1e-12 && p[2] == 0)
        << "sample " << i << " (" << p << ") lies outside the triangle";
    left += p[0] < 0.5;
    near_corner += p[0] + p[1] < 0.5;
  }
  // Areas within the triangle of area 1/2: {x < 1/2} has 3/8, {x + y < 1/2} has 1/8.
  EXPECT_NEAR(left / static_cast<double>(n), 0.75, 0.006) << "x < 1/2 holds 3/4 of the area";
  EXPECT_NEAR(near_corner / static_cast<double>(n), 0.25, 0.006)
      << "the corner triangle x + y < 1/2 holds 1/4 of the area";
}

TEST(MeshSamplerTest, CurvatureEstimateOnASphere) {
  const double radius = 2.0;
  const TriangleMesh sphere = testing::Icosphere(4, radius);
  MeshSamplerOptions area_options;
  MeshSamplerOptions curvature_options;
  curvature_options.mode = MeshSamplingMode::kCurvature;
  curvature_options.curvature_epsilon = 0.5;
  absl::StatusOr<std::vector<double>> areas = ComputeTriangleWeights(sphere, area_options);
  absl::StatusOr<std::vector<double>> weights = ComputeTriangleWeights(sphere, curvature_options);
  ASSERT_TRUE(areas.ok()) << areas.status();
  ASSERT_TRUE(weights.ok()) << weights.status();
  BoundingBox box;
  for (const Vec3f& p : sphere.positions) box.Extend(Vec3(p));
  double sum = 0;
  for (size_t t = 0; t < sphere.faces.size(); ++t) {
    const double h = ((*weights)[t] / (*areas)[t] - 0.5) / box.diagonal();
    sum += h;
    // The twelve valence-5 vertices of the icosphere read about 5% high.
    ASSERT_NEAR(h * radius, 1.0, 0.06)
        << "triangle " << t << ": the mean curvature of a sphere is 1/r";
  }
  EXPECT_NEAR(sum / sphere.faces.size() * radius, 1.0, 0.005)
      << "on average the estimate should be within 0.5% of 1/r";
}

TEST(MeshSamplerTest, FlatMeshHasNoCurvatureWhateverTheOrientation) {
  TriangleMesh grid = testing::GridPatch(6, 6);
  // Flip every other face: the estimate must not read a fold into inconsistent orientation.
  for (size_t t = 0; t < grid.faces.size(); t += 2) std::swap(grid.faces[t][1], grid.faces[t][2]);
  MeshSamplerOptions options;
  options.mode = MeshSamplingMode::kCurvature;
  options.curvature_epsilon = 2.0;
  absl::StatusOr<std::vector<double>> weights = ComputeTriangleWeights(grid, options);
  ASSERT_TRUE(weights.ok()) << weights.status();
  for (size_t t = 0; t < weights->size(); ++t) {
    EXPECT_NEAR((*weights)[t], 2.0 * 0.5 / 36, 1e-5 * 2.0 * 0.5 / 36)
        << "triangle " << t << " of a flat grid should weigh epsilon * area";
  }
}

TEST(MeshSamplerTest, CurvatureModePutsMoreSamplesOnTheBump) {
  const std::shared_ptr<const TriangleMesh> mesh = Share(GridWithBump());
  MeshSamplerOptions curvature;
  curvature.mode = MeshSamplingMode::kCurvature;
  absl::StatusOr<std::unique_ptr<Sampler>> by_area = MeshSampler::Create(mesh);
  absl::StatusOr<std::unique_ptr<Sampler>> by_curvature = MeshSampler::Create(mesh, curvature);
  ASSERT_TRUE(by_area.ok()) << by_area.status();
  ASSERT_TRUE(by_curvature.ok()) << by_curvature.status();
  auto fraction_on_bump = [](const Sampler& sampler) {
    Random rng(3);
    int on_bump = 0;
    const int n = 50000;
    for (int i = 0; i < n; ++i) {
      const Vec3 p = sampler.Sample(rng);
      on_bump += (p[0] - 0.5) * (p[0] - 0.5) + (p[1] - 0.5) * (p[1] - 0.5) < 0.2 * 0.2;
    }
    return on_bump / static_cast<double>(n);
  };
  const double area_fraction = fraction_on_bump(**by_area);
  const double curvature_fraction = fraction_on_bump(**by_curvature);
  EXPECT_GT(curvature_fraction, 1.5 * area_fraction)
      << "curvature-adaptive sampling should favour the bump (Section 4.1): " << curvature_fraction
      << " of samples on it against " << area_fraction << " by area";
}

TEST(MeshSamplerTest, DeterministicForSeed) {
  MeshSamplerOptions options;
  options.mode = MeshSamplingMode::kCurvature;
  absl::StatusOr<std::unique_ptr<Sampler>> sampler =
      MeshSampler::Create(Share(testing::Icosphere(2)), options);
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  Random a(9);
  Random b(9);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ((*sampler)->Sample(a), (*sampler)->Sample(b)) << "same seed, different sample " << i;
  }
}

// PrefetchSample loads the draws after the next one, whose generator states it knows only
// because every draw takes four random numbers.
TEST(MeshSamplerTest, PrefetchingLeavesTheSequenceAloneAndEveryDrawTakesFourNumbers) {
  absl::StatusOr<std::unique_ptr<Sampler>> sampler =
      MeshSampler::Create(Share(testing::Icosphere(2)));
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  Random plain(4);
  Random prefetching(4);
  for (int i = 0; i < 1000; ++i) {
    Random four_on = plain;
    for (int k = 0; k < 4; ++k) four_on.NextU64();
    (*sampler)->PrefetchSample(prefetching);
    ASSERT_EQ((*sampler)->Sample(plain), (*sampler)->Sample(prefetching))
        << "prefetching changed sample " << i;
    Random after = plain;
    ASSERT_EQ(after.NextU64(), four_on.NextU64()) << "draw " << i;
  }
}

TEST(MeshSamplerTest, BoundsAreThoseOfTheFaces) {
  TriangleMesh mesh = TwoTriangles();
  mesh.positions.emplace_back(100, 100, 100);  // Not used by any face.
  absl::StatusOr<std::unique_ptr<Sampler>> sampler = MeshSampler::Create(Share(mesh));
  ASSERT_TRUE(sampler.ok()) << sampler.status();
  EXPECT_EQ((*sampler)->Bounds().min, Vec3(0, 0, 0)) << "lower corner";
  EXPECT_EQ((*sampler)->Bounds().max, Vec3(5, 1, 0)) << "upper corner, unused vertex left out";
  EXPECT_FALSE((*sampler)->empty()) << "a mesh sampler is never empty";
}

TEST(MeshSamplerTest, RejectsInvalidMeshes) {
  TriangleMesh out_of_range = TwoTriangles();
  out_of_range.faces[1][2] = 6;
  TriangleMesh nan_vertex = TwoTriangles();
  nan_vertex.positions[4][1] = std::numeric_limits<float>::quiet_NaN();
  TriangleMesh no_faces = TwoTriangles();
  no_faces.faces.clear();
  TriangleMesh flat;
  flat.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(2, 0, 0)};
  flat.faces = {{0, 1, 2}, {0, 0, 1}};
  const std::vector<std::pair<std::string, std::shared_ptr<const TriangleMesh>>> cases = {
      {"null", nullptr},
      {"empty", Share(TriangleMesh())},
      {"no faces", Share(no_faces)},
      {"index out of range", Share(out_of_range)},
      {"NaN position", Share(nan_vertex)},
      {"zero total area", Share(flat)},
  };
  for (MeshSamplingMode mode : {MeshSamplingMode::kArea, MeshSamplingMode::kCurvature}) {
    MeshSamplerOptions options;
    options.mode = mode;
    for (const auto& [name, mesh] : cases) {
      EXPECT_EQ(MeshSampler::Create(mesh, options).status().code(),
                absl::StatusCode::kInvalidArgument)
          << "should reject: " << name << " (mode " << static_cast<int>(mode) << ")";
    }
  }
  for (double epsilon : {0.0, -1.0, std::numeric_limits<double>::infinity()}) {
    MeshSamplerOptions options;
    options.curvature_epsilon = epsilon;
    EXPECT_EQ(MeshSampler::Create(Share(TwoTriangles()), options).status().code(),
              absl::StatusCode::kInvalidArgument)
        << "curvature_epsilon " << epsilon << " is out of range";
  }
}

}  // namespace
}  // namespace neuralmesh
