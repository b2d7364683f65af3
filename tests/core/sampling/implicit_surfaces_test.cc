#include "core/sampling/implicit_surfaces.h"

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/core/sampling/surface_topology.h"

namespace neuralmesh {
namespace {

std::unique_ptr<ImplicitSurface> Must(absl::StatusOr<std::unique_ptr<ImplicitSurface>> surface) {
  EXPECT_TRUE(surface.ok()) << surface.status();
  return surface.ok() ? std::move(surface).value() : nullptr;
}

double MeshArea(const TriangleMesh& mesh) {
  double area = 0;
  for (const auto& f : mesh.faces) {
    const Vec3 a(mesh.positions[f[0]]);
    area += 0.5 *
            OpenMesh::cross(Vec3(mesh.positions[f[1]]) - a, Vec3(mesh.positions[f[2]]) - a).norm();
  }
  return area;
}

// Pearson's chi-square of `counts` against `expected` (same total).
double ChiSquare(const std::vector<int>& counts, const std::vector<double>& expected) {
  double chi2 = 0;
  for (size_t i = 0; i < counts.size(); ++i) {
    chi2 += (counts[i] - expected[i]) * (counts[i] - expected[i]) / expected[i];
  }
  return chi2;
}

// The unit outward normal from central differences of Value.
Vec3 NumericNormal(const ImplicitSurface& surface, const Vec3& p, double step) {
  Vec3 gradient;
  for (int a = 0; a < 3; ++a) {
    Vec3 d(0.0, 0.0, 0.0);
    d[a] = step;
    gradient[a] = surface.Value(p + d) - surface.Value(p - d);
  }
  return gradient.normalized();
}

void ExpectDeterministic(const Sampler& sampler, const std::string& name) {
  Random a(31);
  Random b(31);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(sampler.Sample(a), sampler.Sample(b))
        << name << ": same seed, different sample " << i;
  }
}

// ---------------------------------------------------------------------------------- Sphere

TEST(ImplicitSurfacesTest, SphereSamplesLieOnTheSurface) {
  const Vec3 center(1, 2, 3);
  const double radius = 2.0;
  std::unique_ptr<ImplicitSurface> sphere = Must(MakeSphere(center, radius));
  ASSERT_NE(sphere, nullptr);
  EXPECT_EQ(sphere->genus(), 0) << "a sphere has genus 0";
  EXPECT_FALSE(sphere->empty()) << "a surface is never empty";
  EXPECT_NEAR(sphere->Area(), 4 * M_PI * radius * radius, 1e-12) << "4 pi r^2";
  EXPECT_LT(sphere->Value(center), 0) << "the centre is inside";
  EXPECT_GT(sphere->Value(center + Vec3(3, 0, 0)), 0) << "a point at distance 3 is outside";
  EXPECT_NEAR(sphere->Distance(center + Vec3(0, 0, 0.5)), 1.5, 1e-12) << "distance from inside";
  const BoundingBox box = sphere->Bounds();
  EXPECT_EQ(box.min, center - Vec3(radius)) << "lower corner";
  EXPECT_EQ(box.max, center + Vec3(radius)) << "upper corner";
  Random rng(1);
  for (int i = 0; i < 10000; ++i) {
    const Vec3 p = sphere->Sample(rng);
    ASSERT_LT(sphere->Distance(p), 1e-6 * radius) << "sample " << i << " is off the sphere";
  }
  ExpectDeterministic(*sphere, "sphere");
}

TEST(ImplicitSurfacesTest, SphereSamplesAreAreaUniform) {
  const double radius = 1.5;
  std::unique_ptr<ImplicitSurface> sphere = Must(MakeSphere(Vec3(0, 0, 0), radius));
  ASSERT_NE(sphere, nullptr);
  // Archimedes: the height of an area-uniform point is uniform, and so is its azimuth.
  const int bins = 20;
  const int n = 100000;
  std::vector<int> heights(bins, 0);
  std::vector<int> azimuths(bins, 0);
  Random rng(2);
  for (int i = 0; i < n; ++i) {
    const Vec3 p = sphere->Sample(rng);
    ++heights[std::min(bins - 1, static_cast<int>((p[2] + radius) / (2 * radius) * bins))];
    ++azimuths[std::min(bins - 1,
                        static_cast<int>((std::atan2(p[1], p[0]) + M_PI) / (2 * M_PI) * bins))];
  }
  const std::vector<double> expected(bins, static_cast<double>(n) / bins);
  // 19 degrees of freedom: P(chi2 > 45) < 1e-3.
  EXPECT_LT(ChiSquare(heights, expected), 45.0) << "z should be uniform in [-r, r]";
  EXPECT_LT(ChiSquare(azimuths, expected), 45.0) << "the azimuth should be uniform";
}

TEST(ImplicitSurfacesTest, SphereReferenceMeshIsAClosedGeodesicSphere) {
  const double radius = 3.0;
  std::unique_ptr<ImplicitSurface> sphere = Must(MakeSphere(Vec3(0.5, 0, -1), radius));
  ASSERT_NE(sphere, nullptr);
  for (int n : {1, 3, 8}) {
    const TriangleMesh mesh = sphere->ReferenceMesh(n);
    EXPECT_EQ(mesh.positions.size(), static_cast<size_t>(40 * n * n + 2)) << "resolution " << n;
    const testing::SurfaceTopology topology = testing::MeasureTopology(mesh);
    ASSERT_TRUE(topology.problem.empty()) << "resolution " << n << ": " << topology.problem;
    EXPECT_EQ(topology.euler, 2) << "resolution " << n << ": genus 0 means V - E + F = 2";
    EXPECT_EQ(topology.components, 1) << "resolution " << n;
    EXPECT_GT(topology.volume, 0) << "resolution " << n << ": faces should face outward";
    for (const Vec3f& p : mesh.positions) {
      ASSERT_LT(sphere->Distance(Vec3(p)), 1e-6 * radius) << "vertex " << p << " is off";
    }
  }
  EXPECT_NEAR(MeshArea(sphere->ReferenceMesh(16)) / sphere->Area(), 1.0, 2e-3)
      << "a fine geodesic sphere should have about the sphere's area";
}

// ----------------------------------------------------------------------------------- Torus

TEST(ImplicitSurfacesTest, TorusSamplesLieOnTheSurfaceAndDistancesAreExact) {
  const Vec3 center(-1, 0, 2);
  const double major = 2.0;
  const double minor = 0.5;
  std::unique_ptr<ImplicitSurface> torus = Must(MakeTorus(center, major, minor));
  ASSERT_NE(torus, nullptr);
  EXPECT_EQ(torus->genus(), 1) << "a torus has genus 1";
  EXPECT_NEAR(torus->Area(), 4 * M_PI * M_PI * major * minor, 1e-12) << "4 pi^2 R r";
  EXPECT_NEAR(torus->Distance(center), major - minor, 1e-12) << "the centre is R - r away";
  EXPECT_NEAR(torus->Distance(center + Vec3(major + minor + 0.25, 0, 0)), 0.25, 1e-12)
      << "outside the outer equator";
  EXPECT_NEAR(torus->Distance(center + Vec3(0, major, 0.1)), minor - 0.1, 1e-12)
      << "inside the tube";
  EXPECT_LT(torus->Value(center + Vec3(0, major, 0)), 0) << "the core circle is inside";
  EXPECT_GT(torus->Value(center), 0) << "the hole is outside";
  const BoundingBox box = torus->Bounds();
  EXPECT_EQ(box.min, center - Vec3(2.5, 2.5, 0.5)) << "lower corner";
  EXPECT_EQ(box.max, center + Vec3(2.5, 2.5, 0.5)) << "upper corner";
  Random rng(3);
  for (int i = 0; i < 10000; ++i) {
    const Vec3 p = torus->Sample(rng);
    ASSERT_LT(torus->Distance(p), 1e-6 * major) << "sample " << i << " is off the torus";
    ASSERT_TRUE(box.Contains(p)) << "sample " << i << " is outside Bounds()";
  }
  ExpectDeterministic(*torus, "torus");
}

TEST(ImplicitSurfacesTest, TorusSamplesAreAreaUniform) {
  const double major = 2.0;
  const double minor = 1.0;
  std::unique_ptr<ImplicitSurface> torus = Must(MakeTorus(Vec3(0, 0, 0), major, minor));
  ASSERT_NE(torus, nullptr);
  const int bins = 12;
  const int n = 120000;
  std::vector<int> tube(bins, 0);
  std::vector<int> azimuth(bins, 0);
  int outer = 0;
  Random rng(4);
  for (int i = 0; i < n; ++i) {
    const Vec3 p = torus->Sample(rng);
    const double rho = std::hypot(p[0], p[1]);
    const double v = std::atan2(p[2], rho - major);  // Tube angle, 0 on the outer equator.
    outer += rho > major;
    ++tube[std::min(bins - 1, static_cast<int>((v + M_PI) / (2 * M_PI) * bins))];
    ++azimuth[std::min(bins - 1,
                       static_cast<int>((std::atan2(p[1], p[0]) + M_PI) / (2 * M_PI) * bins))];
  }
  // The outer half (cos v > 0) holds 2 pi r (pi R + 2 r) of the area 4 pi^2 R r.
  const double outer_share = 0.5 + minor / (M_PI * major);
  EXPECT_NEAR(outer / static_cast<double>(n), outer_share, 0.006)
      << "the outer half of the tube should get its share of the area";
  // Tube-angle bins: the area between v0 and v1 is proportional to R (v1 - v0) + r (sin v1 -
  // sin v0).
  std::vector<double> expected_tube(bins);
  for (int b = 0; b < bins; ++b) {
    const double v0 = -M_PI + 2 * M_PI * b / bins;
    const double v1 = -M_PI + 2 * M_PI * (b + 1) / bins;
    expected_tube[b] =
        n * (major * (v1 - v0) + minor * (std::sin(v1) - std::sin(v0))) / (2 * M_PI * major);
  }
  // 11 degrees of freedom: P(chi2 > 32) < 1e-3.
  EXPECT_LT(ChiSquare(tube, expected_tube), 32.0)
      << "the tube angle should follow the area element R + r cos v";
  EXPECT_LT(ChiSquare(azimuth, std::vector<double>(bins, static_cast<double>(n) / bins)), 32.0)
      << "the angle around the axis should be uniform";
}

TEST(ImplicitSurfacesTest, TorusReferenceMeshIsAClosedGenusOneGrid) {
  const double major = 3.0;
  const double minor = 1.0;
  std::unique_ptr<ImplicitSurface> torus = Must(MakeTorus(Vec3(0, 1, 0), major, minor));
  ASSERT_NE(torus, nullptr);
  for (int n : {1, 2, 6}) {
    const TriangleMesh mesh = torus->ReferenceMesh(n);
    EXPECT_EQ(mesh.positions.size(), static_cast<size_t>(4 * n * 12 * n))
        << "resolution " << n << ": 4n around the tube times 4n R / r around the axis";
    const testing::SurfaceTopology topology = testing::MeasureTopology(mesh);
    ASSERT_TRUE(topology.problem.empty()) << "resolution " << n << ": " << topology.problem;
    EXPECT_EQ(topology.euler, 0) << "resolution " << n << ": genus 1 means V - E + F = 0";
    EXPECT_EQ(topology.components, 1) << "resolution " << n;
    EXPECT_GT(topology.volume, 0) << "resolution " << n << ": faces should face outward";
    for (const Vec3f& p : mesh.positions) {
      ASSERT_LT(torus->Distance(Vec3(p)), 1e-6 * major) << "vertex " << p << " is off";
    }
  }
  EXPECT_NEAR(MeshArea(torus->ReferenceMesh(16)) / torus->Area(), 1.0, 2e-3)
      << "a fine grid should have about the torus's area";
}

// -------------------------------------------------------------------------------- Genus two

class GenusTwoTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    surface_ = Must(MakeGenusTwo(kCenter, kScale, kThickness)).release();
  }
  static void TearDownTestSuite() {
    delete surface_;
    surface_ = nullptr;
  }

  static constexpr double kScale = 2.0;
  static constexpr double kThickness = 0.1;
  static const Vec3 kCenter;
  static ImplicitSurface* surface_;
};

const Vec3 GenusTwoTest::kCenter(1, -2, 0.5);
ImplicitSurface* GenusTwoTest::surface_ = nullptr;

TEST_F(GenusTwoTest, SamplesLieOnTheSurfaceInsideBounds) {
  ASSERT_NE(surface_, nullptr);
  EXPECT_EQ(surface_->genus(), 2) << "the double torus has genus 2";
  const BoundingBox box = surface_->Bounds();
  Random rng(5);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 p = surface_->Sample(rng);
    ASSERT_LT(surface_->Distance(p), 1e-4 * kScale) << "sample " << i << " is off the surface";
    ASSERT_LT(std::abs(surface_->Value(p)), 1e-12) << "sample " << i << " is off the zero set";
    ASSERT_TRUE(box.Contains(p)) << "sample " << i << " (" << p << ") is outside Bounds()";
  }
  ExpectDeterministic(*surface_, "genus two");
}

TEST_F(GenusTwoTest, BoundsAreTight) {
  ASSERT_NE(surface_, nullptr);
  // The exact extent at thickness t: x^2 = (1 + sqrt(1 + 4t)) / 2, y^2 = (1 + 4t) / 8, z = t.
  const Vec3 half(std::sqrt((1 + std::sqrt(1.4)) / 2), std::sqrt(1.4 / 8), 0.1);
  const BoundingBox box = surface_->Bounds();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(box.min[a], kCenter[a] - half[a] * kScale, 1e-12) << "lower corner, axis " << a;
    EXPECT_NEAR(box.max[a], kCenter[a] + half[a] * kScale, 1e-12) << "upper corner, axis " << a;
  }
  // The reference mesh's vertices are on the surface and reach the box's faces.
  BoundingBox mesh_box;
  for (const Vec3f& p : surface_->ReferenceMesh(8).positions) mesh_box.Extend(Vec3(p));
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(mesh_box.min[a], box.min[a], 0.01 * kScale) << "axis " << a;
    EXPECT_NEAR(mesh_box.max[a], box.max[a], 0.01 * kScale) << "axis " << a;
  }
}

TEST_F(GenusTwoTest, DistanceIsExactNearTheSurface) {
  ASSERT_NE(surface_, nullptr);
  Random rng(6);
  // Within a quarter of the thickness, the smallest radius of curvature.
  for (double offset : {-0.2, -0.05, 0.01, 0.1, 0.2}) {
    const double delta = offset * kThickness * kScale;
    for (int i = 0; i < 200; ++i) {
      const Vec3 p = surface_->Sample(rng);
      const Vec3 q = p + NumericNormal(*surface_, p, 1e-6 * kScale) * delta;
      ASSERT_NEAR(surface_->Distance(q), std::abs(delta), 1e-7 * kScale)
          << "a point " << delta << " along the normal from sample " << i << " (" << p << ")";
    }
  }
  EXPECT_LT(surface_->Value(kCenter), 0) << "the crossing of the figure eight is inside";
  EXPECT_GT(surface_->Value(kCenter + Vec3(std::sqrt(0.5) * kScale, 0, 0)), 0)
      << "the centre of a hole is outside";
  EXPECT_NEAR(surface_->Distance(kCenter + Vec3(0, 0, 2 * kScale)), (2 - kThickness) * kScale, 1e-9)
      << "straight above the crossing, the nearest point is the top of the tube";
}

TEST_F(GenusTwoTest, SamplingIsAreaUniform) {
  ASSERT_NE(surface_, nullptr);
  // Area shares of three regions, in local coordinates, measured on a much finer mesh.
  auto regions = [](const Vec3& p) {
    const Vec3 q = (p - kCenter) / kScale;
    return std::array<bool, 3>{std::abs(q[2]) > 0.07, q[0] > 0.9, std::abs(q[0]) < 0.2};
  };
  const TriangleMesh fine = surface_->ReferenceMesh(32);
  std::array<double, 3> area_share = {0, 0, 0};
  double total = 0;
  for (const auto& f : fine.faces) {
    const Vec3 a(fine.positions[f[0]]), b(fine.positions[f[1]]), c(fine.positions[f[2]]);
    const double area = 0.5 * OpenMesh::cross(b - a, c - a).norm();
    total += area;
    const auto in = regions((a + b + c) / 3.0);
    for (int r = 0; r < 3; ++r) area_share[r] += in[r] ? area : 0.0;
  }
  const int n = 400000;
  std::array<int, 3> counts = {0, 0, 0};
  Random rng(7);
  for (int i = 0; i < n; ++i) {
    const auto in = regions(surface_->Sample(rng));
    for (int r = 0; r < 3; ++r) counts[r] += in[r];
  }
  for (int r = 0; r < 3; ++r) {
    const double share = area_share[r] / total;
    const double sigma = std::sqrt(share * (1 - share) / n);
    EXPECT_NEAR(counts[r] / static_cast<double>(n), share, 4 * sigma + 2e-3 * share)
        << "region " << r << ": the share of samples should match the share of area";
  }
  EXPECT_NEAR(surface_->Area() / total, 1.0, 1e-3) << "Area() against a much finer mesh";
}

TEST(ImplicitSurfacesTest, GenusTwoReferenceMeshIsAClosedGenusTwoSurface) {
  for (double thickness : {0.05, 0.1, 0.2}) {
    std::unique_ptr<ImplicitSurface> surface = Must(MakeGenusTwo(Vec3(0, 0, 0), 1.5, thickness));
    ASSERT_NE(surface, nullptr);
    for (int n : {1, 4, 8}) {
      const TriangleMesh mesh = surface->ReferenceMesh(n);
      const testing::SurfaceTopology topology = testing::MeasureTopology(mesh);
      ASSERT_TRUE(topology.problem.empty())
          << "thickness " << thickness << ", resolution " << n << ": " << topology.problem;
      EXPECT_EQ(topology.euler, -2)
          << "thickness " << thickness << ", resolution " << n << ": genus 2 means V - E + F = -2";
      EXPECT_EQ(topology.components, 1) << "thickness " << thickness << ", resolution " << n;
      EXPECT_GT(topology.volume, 0)
          << "thickness " << thickness << ", resolution " << n << ": faces should face outward";
      for (const Vec3f& p : mesh.positions) {
        ASSERT_LT(std::abs(surface->Value(Vec3(p))), 1e-5)
            << "thickness " << thickness << ": vertex " << p << " is off the surface";
      }
    }
  }
}

// ------------------------------------------------------------------------------- Factories

TEST(ImplicitSurfacesTest, FactoriesRejectInvalidParameters) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Vec3 origin(0, 0, 0);
  EXPECT_EQ(MakeSphere(origin, 0).status().code(), absl::StatusCode::kInvalidArgument)
      << "zero radius";
  EXPECT_EQ(MakeSphere(origin, -1).status().code(), absl::StatusCode::kInvalidArgument)
      << "negative radius";
  EXPECT_EQ(MakeSphere(Vec3(nan, 0, 0), 1).status().code(), absl::StatusCode::kInvalidArgument)
      << "NaN centre";
  EXPECT_EQ(MakeSphere(origin, inf).status().code(), absl::StatusCode::kInvalidArgument)
      << "infinite radius";
  EXPECT_EQ(MakeTorus(origin, 1, 1).status().code(), absl::StatusCode::kInvalidArgument)
      << "r == R is a horn torus, not genus 1";
  EXPECT_EQ(MakeTorus(origin, 1, 2).status().code(), absl::StatusCode::kInvalidArgument) << "r > R";
  EXPECT_EQ(MakeTorus(origin, 1, 0).status().code(), absl::StatusCode::kInvalidArgument)
      << "zero minor radius";
  EXPECT_EQ(MakeTorus(origin, inf, 1).status().code(), absl::StatusCode::kInvalidArgument)
      << "infinite major radius";
  EXPECT_EQ(MakeGenusTwo(origin, 0).status().code(), absl::StatusCode::kInvalidArgument)
      << "zero scale";
  EXPECT_EQ(MakeGenusTwo(origin, 1, 0.01).status().code(), absl::StatusCode::kInvalidArgument)
      << "too thin";
  EXPECT_EQ(MakeGenusTwo(origin, 1, 0.3).status().code(), absl::StatusCode::kInvalidArgument)
      << "too thick: the holes close";
  EXPECT_EQ(MakeGenusTwo(Vec3(0, inf, 0), 1).status().code(), absl::StatusCode::kInvalidArgument)
      << "infinite centre";
}

}  // namespace
}  // namespace neuralmesh
