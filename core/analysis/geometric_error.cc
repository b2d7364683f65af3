#include "core/analysis/geometric_error.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/analysis/point_kd_tree.h"
#include "core/analysis/triangle_tree.h"
#include "core/bounding_box.h"
#include "core/parallel_ranges.h"
#include "core/random.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

// Seed offset of the reference's sample stream.
constexpr uint64_t kReferenceStream = 0x9e3779b97f4a7c15ULL;

// The points measured against a reconstruction at once: enough that a block's queries, sorted
// in Z-order, walk the reconstruction's tree in cache.
constexpr size_t kPointsPerBlock = size_t{1} << 16;

Vec3 ToVec3(const Vec3f& v) { return Vec3(v[0], v[1], v[2]); }

absl::Status CheckMesh(const TriangleMesh& mesh, absl::string_view name) {
  if (mesh.positions.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("the ", name, " has no vertices"));
  }
  if (mesh.faces.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("the ", name, " has no faces"));
  }
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3f& p = mesh.positions[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return absl::InvalidArgumentError(
          absl::StrCat("position ", i, " of the ", name, " is not finite"));
    }
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    for (uint32_t v : mesh.faces[f]) {
      if (v >= mesh.positions.size()) {
        return absl::InvalidArgumentError(absl::StrCat("face ", f, " of the ", name,
                                                       " refers to vertex ", v, " of only ",
                                                       mesh.positions.size()));
      }
    }
  }
  return absl::OkStatus();
}

// Per-face unit normals (zero for zero-area faces) and areas, in double precision.
struct FaceGeometry {
  std::vector<Vec3> normals;
  std::vector<double> areas;
};

FaceGeometry ComputeFaceGeometry(const TriangleMesh& mesh) {
  FaceGeometry out;
  out.normals.resize(mesh.faces.size());
  out.areas.resize(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& t = mesh.faces[f];
    const Vec3 a = ToVec3(mesh.positions[t[0]]);
    const Vec3 cross = (ToVec3(mesh.positions[t[1]]) - a) % (ToVec3(mesh.positions[t[2]]) - a);
    const double length = cross.norm();
    out.areas[f] = 0.5 * length;
    out.normals[f] = length > 0.0 ? cross / length : Vec3(0.0, 0.0, 0.0);
  }
  return out;
}

// Query points of one surface: area-uniform samples (with the normal of their triangle) and
// every vertex used by a face.
struct QueryPoints {
  std::vector<Vec3> samples;
  std::vector<Vec3> normals;  // One per sample.
  std::vector<Vec3> vertices;
};

absl::StatusOr<QueryPoints> MakeQueryPoints(const TriangleMesh& mesh, const FaceGeometry& geometry,
                                            size_t count, uint64_t seed, absl::string_view name) {
  const size_t n = mesh.faces.size();
  std::vector<double> cumulative(n);
  double total = 0.0;
  size_t last_positive = n;
  for (size_t f = 0; f < n; ++f) {
    total += geometry.areas[f];
    cumulative[f] = total;
    if (geometry.areas[f] > 0.0) last_positive = f;
  }
  if (!(total > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat("the ", name, " has zero area"));
  }
  Random rng(seed);
  QueryPoints out;
  out.samples.reserve(count);
  out.normals.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    // upper_bound never lands on a zero-area face: its cumulative value equals the previous.
    const double target = rng.NextDouble() * total;
    size_t f = static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), target) -
                                   cumulative.begin());
    if (f >= n) f = last_positive;  // target rounded up to total.
    const auto& t = mesh.faces[f];
    // Uniform in the triangle: sqrt warps the first coordinate (Osada et al. 2002).
    const double s = std::sqrt(rng.NextDouble());
    const double r = rng.NextDouble();
    out.samples.push_back(ToVec3(mesh.positions[t[0]]) * (1.0 - s) +
                          ToVec3(mesh.positions[t[1]]) * (s * (1.0 - r)) +
                          ToVec3(mesh.positions[t[2]]) * (s * r));
    out.normals.push_back(geometry.normals[f]);
  }
  std::vector<bool> used(mesh.positions.size(), false);
  for (const auto& t : mesh.faces) {
    for (uint32_t v : t) used[v] = true;
  }
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    if (used[v]) out.vertices.push_back(ToVec3(mesh.positions[v]));
  }
  return out;
}

// Everything one surface needs to be measured against the other: its samples and vertices,
// and its tree and face normals for the other side's queries.
struct Surface {
  FaceGeometry geometry;
  QueryPoints query;
  std::optional<TriangleTree> tree;
};

absl::Status PrepareSurface(const TriangleMesh& mesh, size_t samples, uint64_t seed,
                            absl::string_view name, Surface& out) {
  out.geometry = ComputeFaceGeometry(mesh);
  NM_ASSIGN_OR_RETURN(out.query, MakeQueryPoints(mesh, out.geometry, samples, seed, name));
  NM_ASSIGN_OR_RETURN(TriangleTree tree, TriangleTree::Build(mesh));
  out.tree.emplace(std::move(tree));
  return absl::OkStatus();
}

struct SampleStats {
  double mean_distance = 0.0;
  double max_distance = 0.0;
  double mean_normal_agreement = 0.0;
  size_t normal_count = 0;
};

// Exact distances from one surface's samples to the other surface.
SampleStats MeasureSamples(const QueryPoints& query, const Surface& other, int threads) {
  TriangleTree::BatchOptions batch;
  batch.threads = threads;
  const std::vector<TriangleTree::ClosestPointResult> closest =
      other.tree->ClosestPoints(query.samples, batch);
  SampleStats out;
  double distance_sum = 0.0, normal_sum = 0.0;
  for (size_t i = 0; i < closest.size(); ++i) {
    out.max_distance = std::max(out.max_distance, closest[i].distance);
    distance_sum += closest[i].distance;
    // A degenerate closest triangle has no normal and does not vote.
    const Vec3& n = other.geometry.normals[closest[i].face];
    if (n.sqrnorm() > 0.0) {
      normal_sum += std::abs(query.normals[i].dot(n));
      ++out.normal_count;
    }
  }
  out.mean_distance = distance_sum / static_cast<double>(closest.size());
  if (out.normal_count > 0) out.mean_normal_agreement = normal_sum / out.normal_count;
  return out;
}

// The largest distance from `vertices` to the other surface, or `at_least` if none is
// larger. Queries may stop at any surface point within `at_least`, which cannot raise the
// maximum; the result is still exact.
double MaxVertexDistance(const std::vector<Vec3>& vertices, const Surface& other, double at_least,
                         int threads) {
  TriangleTree::BatchOptions batch;
  batch.threads = threads;
  batch.radius = at_least;
  double result = at_least;
  for (const auto& c : other.tree->ClosestPoints(vertices, batch)) {
    result = std::max(result, c.distance);
  }
  return result;
}

}  // namespace

absl::Status GeometricErrorOptions::Validate() const {
  if (samples == 0) return absl::InvalidArgumentError("samples must be positive");
  if (samples > kMaxSamples) {
    return absl::InvalidArgumentError(
        absl::StrCat("samples must be at most ", kMaxSamples, " per surface, not ", samples));
  }
  if (threads < 0) return absl::InvalidArgumentError("threads must be >= 0");
  return absl::OkStatus();
}

absl::StatusOr<GeometricError> ComputeGeometricError(const TriangleMesh& reconstruction,
                                                     const TriangleMesh& reference,
                                                     const GeometricErrorOptions& options) {
  NM_RETURN_IF_ERROR(options.Validate());
  NM_RETURN_IF_ERROR(CheckMesh(reconstruction, "reconstruction"));
  NM_RETURN_IF_ERROR(CheckMesh(reference, "reference"));

  BoundingBox box;
  for (const auto& t : reference.faces) {
    for (uint32_t v : t) box.Extend(ToVec3(reference.positions[v]));
  }
  const double diagonal = box.diagonal();
  if (!(diagonal > 0.0)) {
    return absl::InvalidArgumentError("the reference's bounding box has zero diagonal");
  }

  // The two surfaces are prepared side by side: building a tree over a million triangles
  // is a large share of the total time. The reference is sampled from its own stream, so
  // that reconstructions compared with one reference under one seed share its samples.
  Surface reconstruction_surface, reference_surface;
  absl::Status reconstruction_status;
  auto prepare_reconstruction = [&] {
    reconstruction_status = PrepareSurface(reconstruction, options.samples, options.seed,
                                           "reconstruction", reconstruction_surface);
  };
  const bool parallel = options.threads != 1 && std::thread::hardware_concurrency() > 1;
  std::thread helper;
  if (parallel) {
    helper = std::thread(prepare_reconstruction);
  } else {
    prepare_reconstruction();
  }
  const absl::Status reference_status = PrepareSurface(
      reference, options.samples, options.seed ^ kReferenceStream, "reference", reference_surface);
  if (helper.joinable()) helper.join();
  NM_RETURN_IF_ERROR(reconstruction_status);
  NM_RETURN_IF_ERROR(reference_status);

  const SampleStats to_reference =
      MeasureSamples(reconstruction_surface.query, reference_surface, options.threads);
  const SampleStats to_reconstruction =
      MeasureSamples(reference_surface.query, reconstruction_surface, options.threads);
  double max_distance = std::max(to_reference.max_distance, to_reconstruction.max_distance);
  max_distance = MaxVertexDistance(reconstruction_surface.query.vertices, reference_surface,
                                   max_distance, options.threads);
  max_distance = MaxVertexDistance(reference_surface.query.vertices, reconstruction_surface,
                                   max_distance, options.threads);

  GeometricError error;
  error.diagonal = diagonal;
  error.accuracy = to_reference.mean_distance / diagonal;
  error.completeness = to_reconstruction.mean_distance / diagonal;
  error.chamfer_l1 = 0.5 * (error.accuracy + error.completeness);
  error.hausdorff = max_distance / diagonal;
  const size_t voting_sides =
      (to_reference.normal_count > 0 ? 1 : 0) + (to_reconstruction.normal_count > 0 ? 1 : 0);
  if (voting_sides > 0) {
    error.normal_consistency =
        (to_reference.mean_normal_agreement + to_reconstruction.mean_normal_agreement) /
        static_cast<double>(voting_sides);
  }
  return error;
}

absl::StatusOr<GeometricError> ComputeErrorAgainstPoints(const TriangleMesh& reconstruction,
                                                         const PointCloud& points,
                                                         const GeometricErrorOptions& options) {
  NM_RETURN_IF_ERROR(options.Validate());
  NM_RETURN_IF_ERROR(CheckMesh(reconstruction, "reconstruction"));
  if (points.empty()) return absl::InvalidArgumentError("there are no points to compare with");
  BoundingBox box;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3f& p = points.positions[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return absl::InvalidArgumentError(absl::StrCat("point ", i, " is not finite"));
    }
    box.Extend(ToVec3(p));
  }
  const double diagonal = box.diagonal();
  if (!(diagonal > 0.0)) {
    return absl::InvalidArgumentError("the points' bounding box has zero diagonal");
  }
  Surface surface;
  NM_RETURN_IF_ERROR(
      PrepareSurface(reconstruction, options.samples, options.seed, "reconstruction", surface));
  const bool normals = !points.normals.empty();

  // Points to the reconstruction: exact, every one, a block of them at a time (a query and its
  // result take 64 bytes: a gigabyte for every 16 million points at once).
  TriangleTree::BatchOptions batch;
  batch.threads = options.threads;
  double max_distance = 0.0, to_mesh_sum = 0.0, normal_sum = 0.0;
  size_t normal_count = 0;
  std::vector<Vec3> queries;
  for (size_t begin = 0; begin < points.size(); begin += kPointsPerBlock) {
    const size_t end = std::min(points.size(), begin + kPointsPerBlock);
    queries.resize(end - begin);
    for (size_t i = begin; i < end; ++i) queries[i - begin] = ToVec3(points.positions[i]);
    const std::vector<TriangleTree::ClosestPointResult> closest =
        surface.tree->ClosestPoints(queries, batch);
    for (size_t i = begin; i < end; ++i) {
      const TriangleTree::ClosestPointResult& found = closest[i - begin];
      max_distance = std::max(max_distance, found.distance);
      to_mesh_sum += found.distance;
      const Vec3& n = surface.geometry.normals[found.face];
      if (normals && n.sqrnorm() > 0.0 && points.normals[i].sqrnorm() > 0.0f) {
        normal_sum += std::abs(ToVec3(points.normals[i]).normalized().dot(n));
        ++normal_count;
      }
    }
  }
  const double points_agreement = normal_count > 0 ? normal_sum / normal_count : 0.0;
  const size_t points_voted = normal_count;

  // The reconstruction's samples and vertices to their nearest point.
  const PointKdTree tree(points.positions, 0, static_cast<uint32_t>(points.size()),
                         options.threads);
  const QueryPoints& query = surface.query;
  const size_t samples = query.samples.size();
  std::vector<double> distance(samples + query.vertices.size());
  std::vector<uint32_t> nearest(samples);
  ForEachRange(distance.size(), options.threads, 4096, [&](size_t first, size_t last) {
    NeighbourHeap heap;
    for (size_t i = first; i < last; ++i) {
      const Vec3& q = i < samples ? query.samples[i] : query.vertices[i - samples];
      tree.Search(Vec3f(q[0], q[1], q[2]), UINT32_MAX, 1, &heap);
      const uint32_t index = heap.top().second;
      heap.pop();
      distance[i] = (ToVec3(points.positions[index]) - q).norm();
      if (i < samples) nearest[i] = index;
    }
  });
  double to_points_sum = 0.0;
  normal_sum = 0.0;
  normal_count = 0;
  for (size_t i = 0; i < distance.size(); ++i) {
    max_distance = std::max(max_distance, distance[i]);
    if (i >= samples) continue;
    to_points_sum += distance[i];
    const Vec3f& n = normals ? points.normals[nearest[i]] : Vec3f(0, 0, 0);
    if (n.sqrnorm() > 0.0f && query.normals[i].sqrnorm() > 0.0) {
      normal_sum += std::abs(query.normals[i].dot(ToVec3(n).normalized()));
      ++normal_count;
    }
  }

  GeometricError error;
  error.diagonal = diagonal;
  error.accuracy = to_points_sum / static_cast<double>(samples) / diagonal;
  error.completeness = to_mesh_sum / static_cast<double>(points.size()) / diagonal;
  error.chamfer_l1 = 0.5 * (error.accuracy + error.completeness);
  error.hausdorff = max_distance / diagonal;
  const size_t voting_sides = (points_voted > 0 ? 1 : 0) + (normal_count > 0 ? 1 : 0);
  error.normal_consistency =
      voting_sides == 0
          ? std::numeric_limits<double>::quiet_NaN()
          : (points_agreement + (normal_count > 0 ? normal_sum / normal_count : 0.0)) /
                static_cast<double>(voting_sides);
  return error;
}

absl::StatusOr<std::vector<double>> DistancesToMesh(absl::Span<const Vec3> points,
                                                    const TriangleMesh& mesh, int threads) {
  for (size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(points[i][0]) || !std::isfinite(points[i][1]) ||
        !std::isfinite(points[i][2])) {
      return absl::InvalidArgumentError(absl::StrCat("query point ", i, " is not finite"));
    }
  }
  NM_ASSIGN_OR_RETURN(const TriangleTree tree, TriangleTree::Build(mesh));
  TriangleTree::BatchOptions batch;
  batch.threads = threads;
  const std::vector<TriangleTree::ClosestPointResult> closest = tree.ClosestPoints(points, batch);
  std::vector<double> distances(closest.size());
  for (size_t i = 0; i < closest.size(); ++i) distances[i] = closest[i].distance;
  return distances;
}

}  // namespace neuralmesh
