// The sphere and the torus; the genus-2 surface is in genus_two_surface.cc.
#include "core/sampling/implicit_surfaces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>

#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// Keeps the reference meshes below 2^28 vertices.
constexpr int kMaxResolution = 2048;
constexpr long kMaxVertices = long{1} << 28;

bool IsFinite(const Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// The unit icosahedron, faces counter-clockwise seen from outside.
void Icosahedron(std::vector<Vec3>* vertices, std::vector<std::array<uint32_t, 3>>* faces) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  *vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
               {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& v : *vertices) v.normalize();
  *faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
            {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
}

class Sphere final : public ImplicitSurface {
 public:
  Sphere(const Vec3& center, double radius) : center_(center), radius_(radius) {}

  double Value(const Vec3& p) const override { return (p - center_).norm() - radius_; }
  double Distance(const Vec3& p) const override { return std::abs(Value(p)); }
  int genus() const override { return 0; }
  double Area() const override { return 2.0 * kTwoPi * radius_ * radius_; }

  // Archimedes: the height of an area-uniform point is uniform.
  Vec3 Sample(Random& rng) const override {
    const double z = 2.0 * rng.NextDouble() - 1.0;
    const double phi = kTwoPi * rng.NextDouble();
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    return center_ + Vec3(rho * std::cos(phi), rho * std::sin(phi), z) * radius_;
  }

  BoundingBox Bounds() const override {
    BoundingBox box;
    box.Extend(center_ - Vec3(radius_));
    box.Extend(center_ + Vec3(radius_));
    return box;
  }

  // Each icosahedron face becomes a triangular grid of m = 2n segments per side. A grid point
  // is named by its integer barycentric weights on the icosahedron's vertices, which the faces
  // sharing an edge or corner agree on.
  TriangleMesh ReferenceMesh(int resolution) const override {
    const int m = 2 * std::clamp(resolution, 1, kMaxResolution);
    std::vector<Vec3> corners;
    std::vector<std::array<uint32_t, 3>> icosahedron;
    Icosahedron(&corners, &icosahedron);
    TriangleMesh mesh;
    std::map<std::array<uint64_t, 3>, uint32_t> index;
    auto vertex = [&](const std::array<uint32_t, 3>& f, int i, int j) {
      const std::array<int, 3> w = {m - i - j, i, j};
      std::array<uint64_t, 3> key;
      for (int k = 0; k < 3; ++k) {
        key[k] = w[k] == 0 ? UINT64_MAX : (uint64_t{f[k]} << 32) | static_cast<uint64_t>(w[k]);
      }
      std::sort(key.begin(), key.end());
      const auto [it, inserted] = index.emplace(key, static_cast<uint32_t>(mesh.positions.size()));
      if (inserted) {
        const Vec3 p = (corners[f[0]] * w[0] + corners[f[1]] * w[1] + corners[f[2]] * w[2]);
        mesh.positions.emplace_back(center_ + p.normalized() * radius_);
      }
      return it->second;
    };
    for (const auto& f : icosahedron) {
      for (int i = 0; i < m; ++i) {
        for (int j = 0; i + j < m; ++j) {
          mesh.faces.push_back({vertex(f, i, j), vertex(f, i + 1, j), vertex(f, i, j + 1)});
          if (i + j + 2 <= m) {
            mesh.faces.push_back(
                {vertex(f, i + 1, j), vertex(f, i + 1, j + 1), vertex(f, i, j + 1)});
          }
        }
      }
    }
    return mesh;
  }

 private:
  const Vec3 center_;
  const double radius_;
};

class Torus final : public ImplicitSurface {
 public:
  Torus(const Vec3& center, double major_radius, double minor_radius)
      : center_(center), major_(major_radius), minor_(minor_radius) {}

  double Value(const Vec3& p) const override {
    const Vec3 q = p - center_;
    const double rho = std::hypot(q[0], q[1]);
    return std::hypot(rho - major_, q[2]) - minor_;
  }
  double Distance(const Vec3& p) const override { return std::abs(Value(p)); }
  int genus() const override { return 1; }
  double Area() const override { return kTwoPi * kTwoPi * major_ * minor_; }

  // The area element is r (R + r cos v) du dv: u uniform, v by rejection.
  Vec3 Sample(Random& rng) const override {
    double v;
    do {
      v = kTwoPi * rng.NextDouble();
    } while (rng.NextDouble() * (major_ + minor_) >= major_ + minor_ * std::cos(v));
    return Point(kTwoPi * rng.NextDouble(), v);
  }

  BoundingBox Bounds() const override {
    const double outer = major_ + minor_;
    BoundingBox box;
    box.Extend(center_ - Vec3(outer, outer, minor_));
    box.Extend(center_ + Vec3(outer, outer, minor_));
    return box;
  }

  // d/du x d/dv of Point is the outward normal, so (i, j) -> (i + 1, j) -> (i + 1, j + 1) is
  // counter-clockwise seen from outside.
  TriangleMesh ReferenceMesh(int resolution) const override {
    const int nv = 4 * std::clamp(resolution, 1, kMaxResolution);
    const double around = std::min(nv * major_ / minor_, static_cast<double>(kMaxVertices / nv));
    const int nu = std::max(3, static_cast<int>(std::lround(around)));
    TriangleMesh mesh;
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j)
        mesh.positions.emplace_back(Point(kTwoPi * i / nu, kTwoPi * j / nv));
    }
    auto id = [&](int i, int j) { return static_cast<uint32_t>((i % nu) * nv + (j % nv)); };
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        mesh.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
    return mesh;
  }

 private:
  // u: angle around the z axis; v: angle around the tube, 0 on the outer equator.
  Vec3 Point(double u, double v) const {
    const double rho = major_ + minor_ * std::cos(v);
    return center_ + Vec3(rho * std::cos(u), rho * std::sin(u), minor_ * std::sin(v));
  }

  const Vec3 center_;
  const double major_;
  const double minor_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<ImplicitSurface>> MakeSphere(const Vec3& center, double radius) {
  if (!IsFinite(center) || !std::isfinite(radius) || radius <= 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a sphere needs a finite centre and a finite radius > 0; the radius is ", radius));
  }
  return std::make_unique<Sphere>(center, radius);
}

absl::StatusOr<std::unique_ptr<ImplicitSurface>> MakeTorus(const Vec3& center, double major_radius,
                                                           double minor_radius) {
  if (!IsFinite(center) || !std::isfinite(major_radius) || !std::isfinite(minor_radius) ||
      !(minor_radius > 0) || !(minor_radius < major_radius)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a ring torus needs a finite centre and 0 < minor radius < major radius; got R = ",
        major_radius, ", r = ", minor_radius));
  }
  return std::make_unique<Torus>(center, major_radius, minor_radius);
}

}  // namespace neuralmesh
