#include "core/learning/best_fit_plane.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace neuralmesh {
namespace {

using Matrix3 = std::array<std::array<double, 3>, 3>;

// The eigenvectors (columns of `vectors`) and eigenvalues of the symmetric matrix `a`, by
// cyclic Jacobi rotations: each rotation zeroes one off-diagonal entry; a few sweeps bring
// them below rounding.
void SymmetricEigen(Matrix3 a, Matrix3* vectors, std::array<double, 3>* values) {
  Matrix3& q = *vectors;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) q[i][j] = i == j ? 1 : 0;
  }
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = std::abs(a[0][1]) + std::abs(a[0][2]) + std::abs(a[1][2]);
    const double diagonal = std::abs(a[0][0]) + std::abs(a[1][1]) + std::abs(a[2][2]);
    if (off <= 1e-15 * diagonal || off == 0) break;
    for (int p = 0; p < 2; ++p) {
      for (int r = p + 1; r < 3; ++r) {
        if (a[p][r] == 0) continue;
        const double theta = (a[r][r] - a[p][p]) / (2 * a[p][r]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1);
        const double s = t * c;
        for (int k = 0; k < 3; ++k) {  // a = a J
          const double kp = a[k][p];
          const double kr = a[k][r];
          a[k][p] = c * kp - s * kr;
          a[k][r] = s * kp + c * kr;
        }
        for (int k = 0; k < 3; ++k) {  // a = J^T a
          const double pk = a[p][k];
          const double rk = a[r][k];
          a[p][k] = c * pk - s * rk;
          a[r][k] = s * pk + c * rk;
        }
        for (int k = 0; k < 3; ++k) {  // q = q J
          const double kp = q[k][p];
          const double kr = q[k][r];
          q[k][p] = c * kp - s * kr;
          q[k][r] = s * kp + c * kr;
        }
      }
    }
  }
  for (int i = 0; i < 3; ++i) (*values)[i] = a[i][i];
}

}  // namespace

BestFitPlane FitPlane(const Sampler& target, Random& rng, int samples) {
  std::vector<Vec3> points(static_cast<size_t>(std::max(samples, 1)));
  Vec3 sum(0, 0, 0);
  for (Vec3& p : points) {
    p = target.Sample(rng);
    sum += p;
  }
  BestFitPlane plane;
  plane.center = sum / static_cast<double>(points.size());
  Matrix3 covariance{};
  for (const Vec3& p : points) {
    const Vec3 d = p - plane.center;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) covariance[i][j] += d[i] * d[j];
    }
  }
  Matrix3 vectors;
  std::array<double, 3> values;
  SymmetricEigen(covariance, &vectors, &values);
  std::array<int, 3> order = {0, 1, 2};
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return values[a] > values[b]; });
  auto column = [&](int c) { return Vec3(vectors[0][c], vectors[1][c], vectors[2][c]); };
  plane.u = column(order[0]).normalized();
  plane.normal = OpenMesh::cross(plane.u, column(order[1])).normalized();
  plane.v = OpenMesh::cross(plane.normal, plane.u);
  for (const Vec3& p : points) {
    Vec3 d = p - plane.center;
    d -= OpenMesh::dot(d, plane.normal) * plane.normal;
    plane.radius = std::max(plane.radius, d.norm());
  }
  return plane;
}

}  // namespace neuralmesh
