#include "server/session_config.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/status_macros.h"
#include "server/quantization_cube.h"

namespace neuralmesh::server {

std::vector<size_t> DefaultLodMilestones(size_t target) {
  std::vector<size_t> milestones;
  static constexpr size_t kSeries[] = {1, 2, 5};
  for (size_t decade = 10; decade < target; decade *= 10) {
    for (size_t step : kSeries) {
      const size_t milestone = decade * step;
      if (milestone >= kFirstDefaultMilestone && milestone < target) {
        milestones.push_back(milestone);
      }
    }
    if (decade > target / 10) break;  // decade * 10 would exceed the target (or overflow).
  }
  milestones.push_back(target);
  return milestones;
}

absl::Status ResolveSessionConfig(size_t max_points_per_session, SessionConfig& config) {
  if (config.target_vertices < kMinTargetVertices) {
    return absl::InvalidArgumentError(
        absl::StrCat("target_vertices is ", config.target_vertices,
                     "; it must be at least 4 (the initial tetrahedron)"));
  }
  if (config.target_vertices > kMaxTargetVertices) {
    return absl::InvalidArgumentError(
        absl::StrCat("target_vertices is ", config.target_vertices, "; at most ",
                     kMaxTargetVertices, " are supported (the mesh numbers half-edges in 32 bits)"));
  }
  if (!std::isfinite(config.points_per_vertex) || config.points_per_vertex <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("points_per_vertex is ",
                                                   config.points_per_vertex,
                                                   "; it must be finite and positive"));
  }
  const double points_needed =
      static_cast<double>(config.target_vertices) * config.points_per_vertex;
  if (points_needed > static_cast<double>(max_points_per_session)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "target_vertices ", config.target_vertices, " at points_per_vertex ",
        config.points_per_vertex, " needs ", points_needed,
        " points, more than this server accepts per session (", max_points_per_session, ")"));
  }
  if (config.refresh_interval < absl::ZeroDuration() ||
      (config.refresh_interval > absl::ZeroDuration() &&
       config.refresh_interval < kMinRefreshInterval)) {
    return absl::InvalidArgumentError(
        absl::StrCat("refresh_interval_ms is ", absl::ToInt64Milliseconds(config.refresh_interval),
                     "; it must be 0 (off) or at least 10"));
  }
  if (config.lod_milestones.empty()) {
    config.lod_milestones = DefaultLodMilestones(config.target_vertices);
  } else {
    if (config.lod_milestones.size() > kMaxLodMilestones) {
      return absl::InvalidArgumentError(absl::StrCat("lod_milestones has ",
                                                     config.lod_milestones.size(),
                                                     " entries; at most 256 are allowed"));
    }
    for (size_t i = 0; i < config.lod_milestones.size(); ++i) {
      const size_t m = config.lod_milestones[i];
      if (m < kMinTargetVertices || m > config.target_vertices) {
        return absl::InvalidArgumentError(
            absl::StrCat("lod_milestones[", i, "] is ", m, "; milestones must lie in [4, ",
                         config.target_vertices, "] (the target)"));
      }
      if (i > 0 && m <= config.lod_milestones[i - 1]) {
        return absl::InvalidArgumentError(
            absl::StrCat("lod_milestones[", i, "] is ", m,
                         ", not above the previous milestone ", config.lod_milestones[i - 1],
                         "; milestones must increase strictly"));
      }
    }
    if (config.lod_milestones.back() != config.target_vertices) {
      config.lod_milestones.push_back(config.target_vertices);
    }
  }
  if (config.bounds.has_value()) {
    const BoundingBox& b = *config.bounds;
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(b.min[c]) || !std::isfinite(b.max[c])) {
        return absl::InvalidArgumentError("bounds has a non-finite coordinate");
      }
      if (b.min[c] > b.max[c]) {
        return absl::InvalidArgumentError(
            absl::StrCat("bounds is inverted along axis ", c, ": min ", b.min[c], " > max ",
                         b.max[c]));
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (!std::isfinite(config.origin[c])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "origin.", absl::string_view("xyz").substr(c, 1), " is ", config.origin[c],
          "; it must be finite"));
    }
  }
  if (config.upload_order.has_value() &&
      config.upload_order->name.size() > UploadOrder::kMaxNameBytes) {
    return absl::InvalidArgumentError(absl::StrCat("upload_order.name has ",
                                                   config.upload_order->name.size(),
                                                   " bytes; at most ", UploadOrder::kMaxNameBytes));
  }
  NM_RETURN_IF_ERROR(config.learner.Validate());
  NM_RETURN_IF_ERROR(config.draco.Validate());
  if (config.outlier_removal.has_value()) {
    const absl::Status valid = config.outlier_removal->Validate();
    if (!valid.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("outlier_removal: ", valid.message()));
    }
  }
  if (const absl::Status valid = config.colors.Validate(); !valid.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("color_neighbours: ", valid.message()));
  }
  if (config.bounds.has_value()) {
    const absl::StatusOr<QuantizationBox> cube = QuantizationCube(
        *config.bounds, kDeclaredBoundsEnlargement, config.draco.position_quantization_bits);
    if (!cube.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("bounds: ", cube.status().message()));
    }
  }
  return absl::OkStatus();
}

}  // namespace neuralmesh::server
