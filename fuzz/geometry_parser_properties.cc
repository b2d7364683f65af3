#include "fuzz/geometry_parser_properties.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/analysis/mesh_report.h"
#include "core/triangle_mesh.h"
#include "fuzz/fuzz_check.h"

namespace neuralmesh::fuzz {
namespace {

using io_internal::FaceHandling;
using io_internal::GeometryView;
using io_internal::ParsedGeometry;

bool Finite(const Vec3f& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

template <typename T>
bool BitwiseEqual(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// Floats (or vectors of them) equal bit for bit, except that a NaN equals any NaN: a text
// format holds no NaN's sign or payload ("nan").
template <typename T>
bool SameFloats(const std::vector<T>& a, const std::vector<T>& b) {
  static_assert(sizeof(T) % sizeof(float) == 0);
  if (a.size() != b.size()) return false;
  const size_t n = a.size() * sizeof(T) / sizeof(float);
  const auto* fa = reinterpret_cast<const float*>(a.data());
  const auto* fb = reinterpret_cast<const float*>(b.data());
  for (size_t i = 0; i < n; ++i) {
    if (std::isnan(fa[i]) && std::isnan(fb[i])) continue;
    if (std::memcmp(&fa[i], &fb[i], sizeof(float)) != 0) return false;
  }
  return true;
}

void CheckStatus(const absl::Status& status) {
  FUZZ_CHECK(status.code() == absl::StatusCode::kInvalidArgument,
             "a parser failed with a code other than INVALID_ARGUMENT: %s",
             status.ToString().c_str());
  FUZZ_CHECK(!status.message().empty(), "a parser failed without saying why");
}

void CheckGeometry(const ParsedGeometry& geometry) {
  const size_t n = geometry.positions.size();
  for (size_t i = 0; i < n; ++i) {
    FUZZ_CHECK(Finite(geometry.positions[i]), "position %zu is not finite", i);
  }
  FUZZ_CHECK(geometry.normals.empty() || geometry.normals.size() == n,
             "%zu normals for %zu positions", geometry.normals.size(), n);
  FUZZ_CHECK(geometry.weights.empty() || geometry.weights.size() == n,
             "%zu weights for %zu positions", geometry.weights.size(), n);
  FUZZ_CHECK(geometry.colors.empty() || geometry.colors.size() == n,
             "%zu colours for %zu positions", geometry.colors.size(), n);
  for (size_t f = 0; f < geometry.faces.size(); ++f) {
    for (uint32_t index : geometry.faces[f]) {
      FUZZ_CHECK(index < n, "face %zu refers to vertex %u of %zu", f, index, n);
    }
  }
}

// The positions with their origin put back: a reader may choose another origin for the same
// points (the written minimum can round into the next multiple of 1,000).
std::vector<std::array<double, 3>> PlacedPositions(const ParsedGeometry& geometry) {
  std::vector<std::array<double, 3>> placed(geometry.positions.size());
  for (size_t i = 0; i < placed.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      placed[i][c] = geometry.origin[c] + double{geometry.positions[i][c]};
    }
  }
  return placed;
}

// Whether `reread`, `parsed` written and read back, holds its positions: where `parsed` has an
// origin, the same coordinates with the origin put back; where it has none, its floats, which a
// text format writes in as few digits as give the float back (4100000.75 as "4100000.8"). The
// reader may then take the text relative to an origin of its own, more precisely than the float
// held it, so that coordinate is compared as the float it narrows to.
bool SamePlacedPositions(const ParsedGeometry& parsed, const ParsedGeometry& reread) {
  if (parsed.positions.size() != reread.positions.size()) return false;
  const std::vector<std::array<double, 3>> before = PlacedPositions(parsed);
  const std::vector<std::array<double, 3>> after = PlacedPositions(reread);
  for (size_t i = 0; i < before.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const bool same = parsed.origin[c] == 0
                            ? static_cast<float>(after[i][c]) == parsed.positions[i][c]
                            : after[i][c] == before[i][c];
      if (!same) return false;
    }
  }
  return true;
}

bool SamePoints(const ParsedGeometry& a, const ParsedGeometry& b) {
  return SamePlacedPositions(a, b) && SameFloats(a.normals, b.normals) &&
         SameFloats(a.weights, b.weights) && BitwiseEqual(a.colors, b.colors);
}

}  // namespace

void CheckGeometryParser(const GeometryFormat& format, const uint8_t* data, size_t size) {
  const absl::string_view text(reinterpret_cast<const char*>(data), size);
  const absl::StatusOr<ParsedGeometry> mesh =
      format.parse(text, FaceHandling::kRead, io_internal::PositionPrecision::kExact);
  if (!mesh.ok()) CheckStatus(mesh.status());
  const absl::StatusOr<ParsedGeometry> in_least_memory =
      io_internal::ParseInLeastMemory([&](io_internal::PositionPrecision precision) {
        return format.parse(text, FaceHandling::kRead, precision);
      });
  FUZZ_CHECK(in_least_memory.status() == mesh.status(), "read in the least memory: %s",
             in_least_memory.status().ToString().c_str());
  if (mesh.ok()) {
    FUZZ_CHECK(!in_least_memory->read_again_exactly && in_least_memory->origin == mesh->origin &&
                   SamePoints(*in_least_memory, *mesh) &&
                   BitwiseEqual(in_least_memory->positions, mesh->positions) &&
                   BitwiseEqual(in_least_memory->faces, mesh->faces),
               "read in the least memory, other points or faces");
  }

  if (format.skips_faces) {
    const absl::StatusOr<ParsedGeometry> points =
        format.parse(text, FaceHandling::kSkip, io_internal::PositionPrecision::kExact);
    if (!points.ok()) {
      CheckStatus(points.status());
      FUZZ_CHECK(!mesh.ok(), "parses with its faces but not without them: %s",
                 points.status().ToString().c_str());
    } else {
      CheckGeometry(*points);
      FUZZ_CHECK(points->faces.empty(), "%zu faces read while skipping faces",
                 points->faces.size());
      if (mesh.ok()) {
        FUZZ_CHECK(SamePoints(*mesh, *points), "points differ with and without faces");
      }
    }
  }
  if (!mesh.ok()) return;
  CheckGeometry(*mesh);

  if (format.format) {
    const GeometryView view{mesh->positions, mesh->normals, mesh->weights,
                            mesh->faces,     mesh->colors,  mesh->origin};
    const std::string written = format.format(view);
    const absl::StatusOr<ParsedGeometry> reread =
        format.parse(written, FaceHandling::kRead, io_internal::PositionPrecision::kExact);
    FUZZ_CHECK(reread.ok(), "the writer's output does not parse: %s",
               reread.status().ToString().c_str());
    const bool same = format.writes_normals_and_weights ? SamePoints(*mesh, *reread)
                                                        : SamePlacedPositions(*mesh, *reread);
    FUZZ_CHECK(same, "points change when written and read back");
    FUZZ_CHECK(BitwiseEqual(mesh->colors, reread->colors),
               "colours change when written and read back (%zu, then %zu)", mesh->colors.size(),
               reread->colors.size());
    FUZZ_CHECK(BitwiseEqual(mesh->faces, reread->faces),
               "faces change when written and read back (%zu, then %zu)", mesh->faces.size(),
               reread->faces.size());
  }

  TriangleMesh triangles;
  triangles.positions = mesh->positions;
  triangles.faces = mesh->faces;
  const MeshReport report = ComputeMeshReport(triangles);
  FUZZ_CHECK(report.vertices + report.isolated_vertices == triangles.positions.size(),
             "the report counts %zu + %zu isolated vertices of %zu", report.vertices,
             report.isolated_vertices, triangles.positions.size());
  FUZZ_CHECK(
      report.faces + report.degenerate_faces == triangles.faces.size() && report.invalid_faces == 0,
      "the report counts %zu + %zu degenerate + %zu invalid faces of %zu", report.faces,
      report.degenerate_faces, report.invalid_faces, triangles.faces.size());
  (void)MeshReportToJson(report);
}

void CheckPositionsWithinScale(const io_internal::ParsedGeometry& parsed,
                               const io_internal::ParsedGeometry& reread,
                               const std::array<double, 3>& scale) {
  FUZZ_CHECK(reread.positions.size() == parsed.positions.size(), "%zu points, then %zu",
             parsed.positions.size(), reread.positions.size());
  for (int c = 0; c < 3; ++c) {
    for (size_t i = 0; i < parsed.positions.size(); ++i) {
      const double before = parsed.origin[c] + double{parsed.positions[i][c]};
      const double after = reread.origin[c] + double{reread.positions[i][c]};
      const double local =
          std::max(std::fabs(parsed.positions[i][c]), std::fabs(reread.positions[i][c]));
      // Half a scale step, the float's rounding (relative to the coordinate, or for a
      // subnormal float, one below 1.2e-38, its absolute step), and the rounding of the
      // coordinate in double precision on either side (a step finer than the scale where the
      // scale is finer than the double's resolution, as 1e-10 at 500,000).
      const double tolerance = 0.5001 * scale[c] + local * std::ldexp(1.0, -23) +
                               std::numeric_limits<float>::denorm_min() +
                               std::max(std::fabs(before), std::fabs(after)) * std::ldexp(1.0, -52);
      FUZZ_CHECK(std::fabs(after - before) <= tolerance,
                 "point %zu moved by %g on axis %d when written (scale %g)", i, after - before, c,
                 scale[c]);
    }
  }
}

}  // namespace neuralmesh::fuzz
