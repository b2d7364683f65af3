// ColorSource from a coloured mesh: the colour at the nearest surface point, interpolated
// barycentrically across its triangle.
#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/analysis/color_source.h"
#include "core/analysis/triangle_tree.h"

namespace neuralmesh {
namespace {

// Barycentric coordinates of `p` (a point of the triangle's plane) in triangle (a, b, c),
// clamped to the triangle; the nearest corner's for a degenerate triangle.
std::array<double, 3> Barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d00 = ab.dot(ab), d01 = ab.dot(ac), d11 = ac.dot(ac);
  const double d20 = ap.dot(ab), d21 = ap.dot(ac);
  const double denominator = d00 * d11 - d01 * d01;
  if (!(denominator > 1e-30 * std::max(d00 * d11, 1e-300))) {
    const double da = (p - a).sqrnorm(), db = (p - b).sqrnorm(), dc = (p - c).sqrnorm();
    if (da <= db && da <= dc) return {1, 0, 0};
    return db <= dc ? std::array<double, 3>{0, 1, 0} : std::array<double, 3>{0, 0, 1};
  }
  std::array<double, 3> weights;
  weights[1] = std::clamp((d11 * d20 - d01 * d21) / denominator, 0.0, 1.0);
  weights[2] = std::clamp((d00 * d21 - d01 * d20) / denominator, 0.0, 1.0);
  weights[0] = std::max(0.0, 1.0 - weights[1] - weights[2]);
  const double sum = weights[0] + weights[1] + weights[2];
  for (double& w : weights) w /= sum;
  return weights;
}

class MeshColorSource final : public ColorSource {
 public:
  MeshColorSource(TriangleMesh mesh, TriangleTree tree)
      : mesh_(std::move(mesh)), tree_(std::move(tree)) {}

  Rgb ColorAt(const Vec3f& position) const override {
    const TriangleTree::ClosestPointResult nearest = tree_.ClosestPoint(Vec3(position));
    const std::array<uint32_t, 3>& face = mesh_.faces[nearest.face];
    const std::array<double, 3> weights =
        Barycentric(nearest.point, Vec3(mesh_.positions[face[0]]), Vec3(mesh_.positions[face[1]]),
                    Vec3(mesh_.positions[face[2]]));
    Rgb color;
    for (int c = 0; c < 3; ++c) {
      double level = 0;
      for (int k = 0; k < 3; ++k) level += weights[k] * mesh_.colors[face[k]][c];
      color[c] = ChannelFromLevel(level, 255.0);
    }
    return color;
  }

 private:
  TriangleMesh mesh_;
  TriangleTree tree_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<ColorSource>> MakeMeshColorSource(const TriangleMesh& mesh) {
  if (mesh.colors.size() != mesh.positions.size()) {
    return absl::InvalidArgumentError(absl::StrCat("the mesh carries ", mesh.colors.size(),
                                                   " colours for ", mesh.positions.size(),
                                                   " vertices"));
  }
  absl::StatusOr<TriangleTree> tree = TriangleTree::Build(mesh);
  if (!tree.ok()) return tree.status();
  return std::make_unique<MeshColorSource>(mesh, *std::move(tree));
}

}  // namespace neuralmesh
