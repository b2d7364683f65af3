// MakeGenusTwo of implicit_surfaces.h: a tube around the lemniscate of Bernoulli.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/marching_tetrahedra.h"
#include "core/sampling/mesh_sampler.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

// The reference tessellation that Sample draws from and Area() measures: about 50000
// vertices at thickness 0.1, where sampling is area-uniform to about 1e-3 relative and the
// area is within 2e-4 of the limit.
constexpr int kSamplingResolution = 16;
// Bounds the grid to about 43 million points (3 million vertices at thickness 0.1).
constexpr int kMaxResolution = 128;

// The surface in local coordinates q = (p - center) / scale, where every constant below lives.
class LocalGenusTwo {
 public:
  explicit LocalGenusTwo(double thickness)
      : thickness_(thickness), half_extent_(ExactHalfExtent(thickness)) {}

  double Value(const Vec3& q) const {
    const double g = Lemniscate(q);
    return g * g + q[2] * q[2] - thickness_ * thickness_;
  }

  Vec3 Gradient(const Vec3& q) const {
    const double r2 = q[0] * q[0] + q[1] * q[1];
    const double g = Lemniscate(q);
    return Vec3(2.0 * g * (4.0 * q[0] * r2 - 2.0 * q[0]), 2.0 * g * (4.0 * q[1] * r2 + 2.0 * q[1]),
                2.0 * q[2]);
  }

  // Newton steps along the gradient onto the zero set. A step is never longer than the
  // distance to the surface's bounding box (a lower bound of the distance to the surface) or a
  // tenth of the thickness, whichever is larger, so it cannot jump across the tube. Stops when
  // the first-order distance estimate |f| / |grad f| is at round-off level.
  Vec3 Project(Vec3 q, int max_steps) const {
    for (int step = 0; step < max_steps; ++step) {
      const double f = Value(q);
      const Vec3 gradient = Gradient(q);
      const double g2 = gradient.sqrnorm();
      if (!(g2 > 1e-300)) {
        // On the tube's core curve or at a hole's centre the gradient vanishes; any direction
        // leads away, so take a fixed small one.
        q += Vec3(1e-3, 0.7e-3, 0.5e-3) * thickness_;
        continue;
      }
      Vec3 move = gradient * (f / g2);
      const double length = move.norm();
      Vec3 outside;
      for (int a = 0; a < 3; ++a) outside[a] = std::max(0.0, std::abs(q[a]) - half_extent_[a]);
      const double max_step = std::max(0.1 * thickness_, outside.norm());
      if (length > max_step) move *= max_step / length;
      q -= move;
      if (length < 1e-15) break;
    }
    return q;
  }

  // The foot of the normal from q: project, then move the foot along the tangent plane by the
  // tangential part of q - foot until that part vanishes; the nearest foot met is kept. Finds
  // the nearest point when q is closer to the surface than its smallest radius of curvature
  // (thickness / 4 at the ends of the lobes).
  Vec3 ClosestPoint(const Vec3& q) const {
    Vec3 foot = Project(q, 200);
    Vec3 best = foot;
    for (int iteration = 0; iteration < 100; ++iteration) {
      const Vec3 normal = Gradient(foot).normalized();
      const Vec3 d = q - foot;
      const Vec3 tangential = d - normal * OpenMesh::dot(d, normal);
      if (tangential.norm() < 1e-14) break;
      foot = Project(foot + tangential, 50);
      if ((q - foot).sqrnorm() < (q - best).sqrnorm()) best = foot;
    }
    return best;
  }

  // Half the size of the zero set's bounding box, which is centred on the origin.
  const Vec3& HalfExtent() const { return half_extent_; }

  double thickness() const { return thickness_; }

 private:
  // |z| <= t, and in the plane the region |g| <= t reaches x^2 = (1 + sqrt(1 + 4 t)) / 2 (on
  // y = 0, since g grows with y^2) and y^2 = (1 + 4 t) / 8 (where g = t, at
  // x^2 = (3 - 4 t) / 8).
  static Vec3 ExactHalfExtent(double t) {
    return Vec3(std::sqrt((1.0 + std::sqrt(1.0 + 4.0 * t)) / 2.0), std::sqrt((1.0 + 4.0 * t) / 8.0),
                t);
  }

  static double Lemniscate(const Vec3& q) {
    const double x2 = q[0] * q[0];
    const double y2 = q[1] * q[1];
    return (x2 + y2) * (x2 + y2) - x2 + y2;
  }

  const double thickness_;
  const Vec3 half_extent_;
};

// Marching tetrahedra on a grid with cubic cells fitted around the surface, then every vertex
// projected onto the zero set.
absl::StatusOr<TriangleMesh> Tessellate(const LocalGenusTwo& surface, const Vec3& center,
                                        double scale, int resolution) {
  // The tube is thinnest at the ends of the lobes, `thickness` across in the plane: two cells
  // across it keep the topology.
  const Vec3 half = surface.HalfExtent();
  const int min_cells = static_cast<int>(std::ceil(4.0 * half[0] / surface.thickness()));
  const int cells_x = std::max(8 * std::clamp(resolution, 1, kMaxResolution), min_cells);
  const double spacing = 2.0 * half[0] / cells_x;
  // Two cells of margin keep the grid's boundary outside the surface.
  std::array<int, 3> cells;
  BoundingBox box;
  for (int a = 0; a < 3; ++a) {
    cells[a] = 2 * static_cast<int>(std::ceil(half[a] / spacing)) + 4;
    const double extent = 0.5 * cells[a] * spacing;
    box.min[a] = -extent;
    box.max[a] = extent;
  }
  NM_ASSIGN_OR_RETURN(
      TriangleMesh mesh,
      MarchingTetrahedra([&surface](const Vec3& q) { return surface.Value(q); }, box, cells));
  for (Vec3f& p : mesh.positions) {
    p = Vec3f(center + surface.Project(Vec3(p), 50) * scale);
  }
  return mesh;
}

class GenusTwo final : public ImplicitSurface {
 public:
  GenusTwo(const Vec3& center, double scale, double thickness,
           std::unique_ptr<Sampler> mesh_sampler, double area)
      : center_(center),
        scale_(scale),
        local_(thickness),
        mesh_sampler_(std::move(mesh_sampler)),
        area_(area) {}

  double Value(const Vec3& p) const override { return local_.Value(Local(p)); }

  double Distance(const Vec3& p) const override {
    const Vec3 q = Local(p);
    return (q - local_.ClosestPoint(q)).norm() * scale_;
  }

  int genus() const override { return 2; }
  double Area() const override { return area_; }

  // The reference mesh's points are within its curvature error of the surface, so a few
  // Newton steps reach round-off.
  Vec3 Sample(Random& rng) const override {
    return center_ + local_.Project(Local(mesh_sampler_->Sample(rng)), 8) * scale_;
  }

  BoundingBox Bounds() const override {
    const Vec3 half = local_.HalfExtent() * scale_;
    BoundingBox box;
    box.Extend(center_ - half);
    box.Extend(center_ + half);
    return box;
  }

  TriangleMesh ReferenceMesh(int resolution) const override {
    // Cannot fail: the grid is fitted around the surface's exact extent and bounded in size.
    return Tessellate(local_, center_, scale_, resolution).value();
  }

 private:
  Vec3 Local(const Vec3& p) const { return (p - center_) / scale_; }

  const Vec3 center_;
  const double scale_;
  const LocalGenusTwo local_;
  const std::unique_ptr<Sampler> mesh_sampler_;
  const double area_;
};

double MeshArea(const TriangleMesh& mesh) {
  double area = 0;
  for (const auto& f : mesh.faces) {
    const Vec3 a(mesh.positions[f[0]]);
    area += 0.5 *
            OpenMesh::cross(Vec3(mesh.positions[f[1]]) - a, Vec3(mesh.positions[f[2]]) - a).norm();
  }
  return area;
}

}  // namespace

absl::StatusOr<std::unique_ptr<ImplicitSurface>> MakeGenusTwo(const Vec3& center, double scale,
                                                              double thickness) {
  if (!std::isfinite(center[0]) || !std::isfinite(center[1]) || !std::isfinite(center[2]) ||
      !std::isfinite(scale) || !(scale > 0) || !(thickness >= 0.05 && thickness <= 0.2)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the genus-2 surface needs a finite centre, a finite scale > 0 and a thickness in "
        "[0.05, 0.2]; got scale ",
        scale, ", thickness ", thickness));
  }
  const LocalGenusTwo local(thickness);
  NM_ASSIGN_OR_RETURN(TriangleMesh mesh, Tessellate(local, center, scale, kSamplingResolution));
  const double area = MeshArea(mesh);
  NM_ASSIGN_OR_RETURN(std::unique_ptr<Sampler> mesh_sampler,
                      MeshSampler::Create(std::make_shared<const TriangleMesh>(std::move(mesh))));
  return std::make_unique<GenusTwo>(center, scale, thickness, std::move(mesh_sampler), area);
}

}  // namespace neuralmesh
