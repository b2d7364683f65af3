#include "core/sampling/mesh_sampler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

struct EdgeFaces {
  uint32_t first_face = 0;
  uint32_t second_face = 0;
  bool first_runs_low_to_high = false;  // Whether the first face walks the edge min -> max.
  bool second_runs_low_to_high = false;
  int count = 0;
};

absl::Status CheckMesh(const TriangleMesh& mesh) {
  if (mesh.positions.empty() || mesh.faces.empty()) {
    return absl::InvalidArgumentError("the mesh has no vertices or no faces");
  }
  if (mesh.faces.size() >= std::numeric_limits<uint32_t>::max()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the mesh has ", mesh.faces.size(), " faces; at most 2^32 - 2 are supported"));
  }
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3f& p = mesh.positions[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return absl::InvalidArgumentError(absl::StrCat("vertex ", i, " has a non-finite coordinate"));
    }
  }
  const size_t n = mesh.positions.size();
  for (size_t i = 0; i < mesh.faces.size(); ++i) {
    for (uint32_t v : mesh.faces[i]) {
      if (v >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("face ", i, " refers to vertex ", v, " of only ", n));
      }
    }
  }
  return absl::OkStatus();
}

std::array<Vec3, 3> Corners(const TriangleMesh& mesh, size_t face) {
  const auto& f = mesh.faces[face];
  return {Vec3(mesh.positions[f[0]]), Vec3(mesh.positions[f[1]]), Vec3(mesh.positions[f[2]])};
}

// |H| per vertex from absolute dihedral angles, as documented in the header.
std::vector<double> VertexCurvatures(const TriangleMesh& mesh, const std::vector<double>& areas,
                                     const std::vector<Vec3>& normals) {
  std::unordered_map<uint64_t, EdgeFaces> edges;
  edges.reserve(mesh.faces.size() * 2);
  for (size_t t = 0; t < mesh.faces.size(); ++t) {
    const auto& f = mesh.faces[t];
    for (int k = 0; k < 3; ++k) {
      const uint32_t from = f[k];
      const uint32_t to = f[(k + 1) % 3];
      const uint64_t key = (uint64_t{std::min(from, to)} << 32) | std::max(from, to);
      EdgeFaces& e = edges[key];
      if (e.count == 0) {
        e.first_face = static_cast<uint32_t>(t);
        e.first_runs_low_to_high = from < to;
      } else if (e.count == 1) {
        e.second_face = static_cast<uint32_t>(t);
        e.second_runs_low_to_high = from < to;
      }
      ++e.count;
    }
  }
  std::vector<double> bend(mesh.positions.size(), 0.0);  // sum of |e| |theta_e| at v.
  for (const auto& [key, e] : edges) {
    if (e.count != 2 || areas[e.first_face] <= 0 || areas[e.second_face] <= 0) continue;
    // Consistently oriented neighbours walk the edge in opposite directions; otherwise one
    // normal is flipped before measuring the angle.
    const double sign = e.first_runs_low_to_high != e.second_runs_low_to_high ? 1.0 : -1.0;
    const Vec3& n1 = normals[e.first_face];
    const Vec3 n2 = normals[e.second_face] * sign;
    const double theta = std::atan2(OpenMesh::cross(n1, n2).norm(), OpenMesh::dot(n1, n2));
    const uint32_t a = static_cast<uint32_t>(key >> 32);
    const uint32_t b = static_cast<uint32_t>(key & 0xffffffffu);
    const double length = (Vec3(mesh.positions[a]) - Vec3(mesh.positions[b])).norm();
    bend[a] += length * theta;
    bend[b] += length * theta;
  }
  std::vector<double> vertex_area(mesh.positions.size(), 0.0);
  for (size_t t = 0; t < mesh.faces.size(); ++t) {
    for (uint32_t v : mesh.faces[t]) vertex_area[v] += areas[t] / 3.0;
  }
  std::vector<double> curvature(mesh.positions.size(), 0.0);
  for (size_t v = 0; v < curvature.size(); ++v) {
    if (vertex_area[v] > 0) curvature[v] = bend[v] / (4.0 * vertex_area[v]);
  }
  return curvature;
}

BoundingBox FaceVertexBounds(const TriangleMesh& mesh) {
  BoundingBox box;
  for (const auto& f : mesh.faces) {
    for (uint32_t v : f) box.Extend(Vec3(mesh.positions[v]));
  }
  return box;
}

}  // namespace

absl::Status MeshSamplerOptions::Validate() const {
  if (mode != MeshSamplingMode::kArea && mode != MeshSamplingMode::kCurvature) {
    return absl::InvalidArgumentError("mode is not a MeshSamplingMode");
  }
  if (!std::isfinite(curvature_epsilon) || curvature_epsilon <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("curvature_epsilon is ", curvature_epsilon, "; it must be finite and > 0"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<double>> ComputeTriangleWeights(const TriangleMesh& mesh,
                                                           const MeshSamplerOptions& options) {
  NM_RETURN_IF_ERROR(options.Validate());
  NM_RETURN_IF_ERROR(CheckMesh(mesh));
  const size_t f = mesh.faces.size();
  std::vector<double> areas(f);
  std::vector<Vec3> normals(f);
  for (size_t t = 0; t < f; ++t) {
    const auto [a, b, c] = Corners(mesh, t);
    const Vec3 n = OpenMesh::cross(b - a, c - a);
    const double norm = n.norm();
    areas[t] = 0.5 * norm;
    normals[t] = norm > 0 ? n / norm : Vec3(0.0, 0.0, 0.0);
  }
  if (options.mode == MeshSamplingMode::kArea) return areas;

  const std::vector<double> curvature = VertexCurvatures(mesh, areas, normals);
  const double diagonal = FaceVertexBounds(mesh).diagonal();
  std::vector<double> weights(f);
  for (size_t t = 0; t < f; ++t) {
    const auto& face = mesh.faces[t];
    const double h = (curvature[face[0]] + curvature[face[1]] + curvature[face[2]]) / 3.0;
    weights[t] = areas[t] * (options.curvature_epsilon + diagonal * h);
  }
  return weights;
}

absl::StatusOr<std::unique_ptr<Sampler>> MeshSampler::Create(
    std::shared_ptr<const TriangleMesh> mesh, const MeshSamplerOptions& options) {
  if (mesh == nullptr) return absl::InvalidArgumentError("the mesh is null");
  NM_ASSIGN_OR_RETURN(const std::vector<double> weights, ComputeTriangleWeights(*mesh, options));
  if (std::all_of(weights.begin(), weights.end(), [](double w) { return w == 0; })) {
    return absl::InvalidArgumentError("every triangle of the mesh has zero area");
  }
  NM_ASSIGN_OR_RETURN(AliasTable table, AliasTable::Create(weights));
  const BoundingBox bounds = FaceVertexBounds(*mesh);
  return std::unique_ptr<Sampler>(new MeshSampler(std::move(mesh), std::move(table), bounds));
}

MeshSampler::MeshSampler(std::shared_ptr<const TriangleMesh> mesh, AliasTable table,
                         const BoundingBox& bounds)
    : mesh_(std::move(mesh)), table_(std::move(table)), bounds_(bounds) {}

Vec3 MeshSampler::Sample(Random& rng) const {
  const auto [a, b, c] = Corners(*mesh_, table_.Draw(rng));
  const double s = std::sqrt(rng.NextDouble());
  const double u = rng.NextDouble();
  return a + (b - a) * (s * (1.0 - u)) + (c - a) * (s * u);
}

void MeshSampler::PrefetchSample(const Random& rng) const {
  // Every draw takes the alias table's two random numbers and two more for the point in the
  // triangle, so the states of the draws after the next one are known.
  auto skip_point_in_triangle = [](Random& r) {
    r.NextDouble();
    r.NextDouble();
  };
  Random peek = rng;
  // The next draw: its cell and its face were loaded by the last two calls; its corners start
  // loading.
  for (uint32_t corner : mesh_->faces[table_.Draw(peek)]) {
    __builtin_prefetch(&mesh_->positions[corner]);
  }
  skip_point_in_triangle(peek);
  // The one after: its cell, loaded by the last call, is read; its face starts loading.
  __builtin_prefetch(&mesh_->faces[table_.Draw(peek)]);
  skip_point_in_triangle(peek);
  // The one after that: its cell starts loading.
  table_.PrefetchDraw(peek);
}

}  // namespace neuralmesh
