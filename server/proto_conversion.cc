#include "server/proto_conversion.h"

#include <cstring>
#include <string>

#include "absl/strings/str_cat.h"

// The wire format is little-endian float32; so is every machine this builds on.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "PackedPoints are little-endian float32; add byte swapping for this target");

namespace neuralmesh::server {
namespace {

template <typename T>
absl::Status UnpackArray(const std::string& bytes, const char* field, size_t expected,
                         const char* layout, std::vector<T>& out) {
  constexpr size_t kElementBytes = sizeof(T);
  if (bytes.size() != expected * kElementBytes) {
    return absl::InvalidArgumentError(absl::StrCat(
        "PackedPoints.", field, " has ", bytes.size(), " bytes; ", expected, " points need ",
        expected * kElementBytes, " (", kElementBytes, " per point, ", layout, ")"));
  }
  out.resize(expected);
  if (expected > 0) std::memcpy(out.data(), bytes.data(), bytes.size());
  return absl::OkStatus();
}

template <typename T>
absl::Status UnpackFloats(const std::string& bytes, const char* field, size_t expected,
                          std::vector<T>& out) {
  return UnpackArray(bytes, field, expected, "little-endian float32", out);
}

}  // namespace

absl::StatusOr<SessionConfig> SessionConfigFromProto(const v1::SessionConfig& proto) {
  SessionConfig config;
  const v1::LearnerOptions& l = proto.learner();
  LearnerOptions& o = config.learner;
  if (l.has_alpha_w()) o.alpha_w = l.alpha_w().value();
  if (l.has_alpha_l()) o.alpha_l = l.alpha_l().value();
  if (l.has_c_l()) o.c_l = l.c_l().value();
  if (l.has_c_vs()) o.c_vs = l.c_vs().value();
  if (l.has_c_ec()) o.c_ec = l.c_ec().value();
  if (l.has_early_phase_vertices()) o.early_phase_vertices = l.early_phase_vertices().value();
  if (l.has_early_c_vs()) o.early_c_vs = l.early_c_vs().value();
  if (l.has_early_c_ec()) o.early_c_ec = l.early_c_ec().value();
  if (l.has_alpha_sc()) o.alpha_sc = l.alpha_sc().value();
  if (l.has_remove_triangles()) o.remove_triangles = l.remove_triangles().value();
  if (l.has_alpha_r()) o.alpha_r = l.alpha_r().value();
  if (l.has_merge_boundaries()) o.merge_boundaries = l.merge_boundaries().value();
  if (l.has_alpha_m()) o.alpha_m = l.alpha_m().value();
  if (l.has_splits_per_step()) o.splits_per_step = l.splits_per_step().value();
  if (l.has_seed()) o.seed = l.seed().value();
  if (l.has_close_small_holes()) o.close_small_holes = l.close_small_holes().value();
  if (l.has_max_closed_hole_vertices()) {
    o.max_closed_hole_vertices = l.max_closed_hole_vertices().value();
  }
  if (l.has_merge_only_settled_boundaries()) {
    o.merge_only_settled_boundaries = l.merge_only_settled_boundaries().value();
  }
  if (l.has_split_largest_cell_near_most_active()) {
    o.split_largest_cell_near_most_active = l.split_largest_cell_near_most_active().value();
  }
  if (l.has_sewn_strip_grace_calls()) {
    o.sewn_strip_grace_calls = l.sewn_strip_grace_calls().value();
  }
  if (l.has_min_merged_loop_vertices()) {
    o.min_merged_loop_vertices = l.min_merged_loop_vertices().value();
  }
  if (l.has_cut_inactive_faces()) o.cut_inactive_faces = l.cut_inactive_faces().value();
  switch (l.initial_mesh()) {
    case v1::INITIAL_MESH_TETRAHEDRON:
      o.initial_mesh = InitialMesh::kTetrahedron;
      break;
    case v1::INITIAL_MESH_DISC:
      o.initial_mesh = InitialMesh::kDisc;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("LearnerOptions.initial_mesh has the unknown value ", l.initial_mesh()));
  }

  config.target_vertices = proto.target_vertices();
  config.lod_milestones.assign(proto.lod_milestones().begin(), proto.lod_milestones().end());
  if (proto.has_refresh_interval_ms()) {
    config.refresh_interval = absl::Milliseconds(proto.refresh_interval_ms().value());
  }
  const v1::DracoOptions& d = proto.draco();
  if (d.has_position_quantization_bits()) {
    config.draco.position_quantization_bits = d.position_quantization_bits().value();
  }
  if (d.has_compression_speed()) {
    // Checked here, where the field has its API name (DracoOptions::Validate names its own).
    const int speed = d.compression_speed().value();
    if (speed < 0 || speed > kMaxDracoSpeed) {
      return absl::InvalidArgumentError(absl::StrCat("DracoOptions.compression_speed is ", speed,
                                                     "; it must be in [0, ", kMaxDracoSpeed, "]"));
    }
    config.draco.encode_speed = speed;
  }
  if (d.has_decode_speed()) config.draco.decode_speed = d.decode_speed().value();
  if (proto.has_points_per_vertex()) {
    config.points_per_vertex = proto.points_per_vertex().value();
  }
  if (proto.has_bounds()) {
    const v1::Box& b = proto.bounds();
    BoundingBox box;
    box.min = Vec3(b.min_x(), b.min_y(), b.min_z());
    box.max = Vec3(b.max_x(), b.max_y(), b.max_z());
    config.bounds = box;
  }
  switch (proto.final_pass()) {
    case v1::FINAL_PASS_AUTO:
      config.final_pass = FinalPass::kAuto;
      break;
    case v1::FINAL_PASS_RELEARN:
      config.final_pass = FinalPass::kRelearn;
      break;
    case v1::FINAL_PASS_CONTINUE:
      config.final_pass = FinalPass::kContinue;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("final_pass has the unknown value ", proto.final_pass()));
  }
  if (proto.has_outlier_removal()) {
    const v1::OutlierRemoval& o = proto.outlier_removal();
    OutlierOptions outliers;
    if (o.has_neighbours()) outliers.neighbours = o.neighbours().value();
    if (o.has_std_ratio()) outliers.std_ratio = o.std_ratio().value();
    config.outlier_removal = outliers;
  }
  if (proto.has_color_neighbours()) {
    // Clamped into int's range; ResolveSessionConfig refuses what is beyond 64.
    config.colors.neighbours =
        static_cast<int>(std::min<uint32_t>(proto.color_neighbours().value(), 1u << 30));
  }
  if (proto.has_origin()) {
    config.origin = {proto.origin().x(), proto.origin().y(), proto.origin().z()};
  }
  if (proto.has_upload_order() && !proto.upload_order().name().empty()) {
    config.upload_order = UploadOrder{proto.upload_order().name(), proto.upload_order().items(),
                                      proto.upload_order().fingerprint()};
  }
  return config;
}

v1::SessionConfig SessionConfigToProto(const SessionConfig& config) {
  v1::SessionConfig proto;
  v1::LearnerOptions& l = *proto.mutable_learner();
  const LearnerOptions& o = config.learner;
  l.mutable_alpha_w()->set_value(o.alpha_w);
  l.mutable_alpha_l()->set_value(o.alpha_l);
  l.mutable_c_l()->set_value(o.c_l);
  l.mutable_c_vs()->set_value(o.c_vs);
  l.mutable_c_ec()->set_value(o.c_ec);
  l.mutable_early_phase_vertices()->set_value(o.early_phase_vertices);
  l.mutable_early_c_vs()->set_value(o.early_c_vs);
  l.mutable_early_c_ec()->set_value(o.early_c_ec);
  l.mutable_alpha_sc()->set_value(o.alpha_sc);
  l.mutable_remove_triangles()->set_value(o.remove_triangles);
  l.mutable_alpha_r()->set_value(o.alpha_r);
  l.mutable_merge_boundaries()->set_value(o.merge_boundaries);
  l.mutable_alpha_m()->set_value(o.alpha_m);
  l.mutable_splits_per_step()->set_value(o.splits_per_step);
  l.mutable_seed()->set_value(o.seed);
  l.mutable_close_small_holes()->set_value(o.close_small_holes);
  l.mutable_max_closed_hole_vertices()->set_value(o.max_closed_hole_vertices);
  l.mutable_merge_only_settled_boundaries()->set_value(o.merge_only_settled_boundaries);
  l.mutable_split_largest_cell_near_most_active()->set_value(o.split_largest_cell_near_most_active);
  l.mutable_sewn_strip_grace_calls()->set_value(o.sewn_strip_grace_calls);
  l.mutable_min_merged_loop_vertices()->set_value(o.min_merged_loop_vertices);
  l.mutable_cut_inactive_faces()->set_value(o.cut_inactive_faces);
  l.set_initial_mesh(o.initial_mesh == InitialMesh::kDisc ? v1::INITIAL_MESH_DISC
                                                          : v1::INITIAL_MESH_TETRAHEDRON);

  proto.set_target_vertices(config.target_vertices);
  for (size_t m : config.lod_milestones) proto.add_lod_milestones(m);
  proto.mutable_refresh_interval_ms()->set_value(
      static_cast<uint32_t>(absl::ToInt64Milliseconds(config.refresh_interval)));
  v1::DracoOptions& d = *proto.mutable_draco();
  d.mutable_position_quantization_bits()->set_value(config.draco.position_quantization_bits);
  d.mutable_compression_speed()->set_value(config.draco.encode_speed);
  d.mutable_decode_speed()->set_value(config.draco.decode_speed);
  proto.mutable_points_per_vertex()->set_value(config.points_per_vertex);
  if (config.bounds.has_value()) {
    v1::Box& b = *proto.mutable_bounds();
    b.set_min_x(config.bounds->min[0]);
    b.set_min_y(config.bounds->min[1]);
    b.set_min_z(config.bounds->min[2]);
    b.set_max_x(config.bounds->max[0]);
    b.set_max_y(config.bounds->max[1]);
    b.set_max_z(config.bounds->max[2]);
  }
  switch (config.final_pass) {
    case FinalPass::kAuto:
      proto.set_final_pass(v1::FINAL_PASS_AUTO);
      break;
    case FinalPass::kRelearn:
      proto.set_final_pass(v1::FINAL_PASS_RELEARN);
      break;
    case FinalPass::kContinue:
      proto.set_final_pass(v1::FINAL_PASS_CONTINUE);
      break;
  }
  if (config.outlier_removal.has_value()) {
    v1::OutlierRemoval& o = *proto.mutable_outlier_removal();
    o.mutable_neighbours()->set_value(config.outlier_removal->neighbours);
    o.mutable_std_ratio()->set_value(config.outlier_removal->std_ratio);
  }
  proto.mutable_color_neighbours()->set_value(static_cast<uint32_t>(config.colors.neighbours));
  if (config.origin != kNoOrigin) {
    v1::Origin& origin = *proto.mutable_origin();
    origin.set_x(config.origin[0]);
    origin.set_y(config.origin[1]);
    origin.set_z(config.origin[2]);
  }
  if (config.upload_order.has_value()) {
    proto.mutable_upload_order()->set_name(config.upload_order->name);
    proto.mutable_upload_order()->set_items(config.upload_order->items);
    proto.mutable_upload_order()->set_fingerprint(config.upload_order->fingerprint);
  }
  return proto;
}

v1::QuantizationBox QuantizationBoxToProto(const QuantizationBox& box) {
  v1::QuantizationBox proto;
  proto.set_origin_x(box.origin[0]);
  proto.set_origin_y(box.origin[1]);
  proto.set_origin_z(box.origin[2]);
  proto.set_range(box.range);
  return proto;
}

v1::MeshReport MeshReportToProto(const MeshReport& report) {
  v1::MeshReport proto;
  proto.set_valence6_share(report.valence6_share);
  proto.set_boundary_loops(static_cast<uint32_t>(report.boundary_loops));
  proto.set_components(static_cast<uint32_t>(report.components));
  proto.set_genus(report.genus);
  proto.set_euler_characteristic(static_cast<int32_t>(report.euler_characteristic));
  proto.set_manifold(report.manifold());
  proto.set_colored(report.colored);
  return proto;
}

absl::StatusOr<PointCloud> PointBatchFromProto(const v1::PointBatch& batch,
                                               size_t max_batch_points) {
  PointCloud cloud;
  switch (batch.data_case()) {
    case v1::PointBatch::kPacked: {
      const v1::PackedPoints& packed = batch.packed();
      const std::string& positions = packed.positions();
      if (positions.empty()) return absl::InvalidArgumentError("the batch has no points");
      if (positions.size() % sizeof(Vec3f) != 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("PackedPoints.positions has ", positions.size(),
                         " bytes, not a multiple of 12 (x, y, z as little-endian float32)"));
      }
      const size_t n = positions.size() / sizeof(Vec3f);
      if (n > max_batch_points) {
        return absl::ResourceExhaustedError(absl::StrCat("the batch has ", n,
                                                         " points; this server takes at most ",
                                                         max_batch_points, " per batch"));
      }
      absl::Status status = UnpackFloats(positions, "positions", n, cloud.positions);
      if (status.ok() && !packed.weights().empty()) {
        status = UnpackFloats(packed.weights(), "weights", n, cloud.weights);
      }
      if (status.ok() && !packed.normals().empty()) {
        status = UnpackFloats(packed.normals(), "normals", n, cloud.normals);
      }
      if (status.ok() && !packed.colors().empty()) {
        status = UnpackArray(packed.colors(), "colors", n, "red, green, blue bytes", cloud.colors);
      }
      if (!status.ok()) return status;
      return cloud;
    }
    case v1::PointBatch::kDracoPointCloud: {
      if (batch.draco_point_cloud().empty()) {
        return absl::InvalidArgumentError("the batch has no points (empty Draco data)");
      }
      absl::StatusOr<PointCloud> decoded =
          DecodePointCloud(batch.draco_point_cloud(), max_batch_points);
      if (absl::IsResourceExhausted(decoded.status())) {
        return absl::ResourceExhaustedError(
            absl::StrCat("PointBatch.draco_point_cloud: ", decoded.status().message(),
                         " (this server takes at most ", max_batch_points, " points per batch)"));
      }
      if (!decoded.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("PointBatch.draco_point_cloud: ", decoded.status().message()));
      }
      if (decoded->empty()) return absl::InvalidArgumentError("the batch has no points");
      if (decoded->size() > max_batch_points) {
        return absl::ResourceExhaustedError(
            absl::StrCat("the Draco batch decodes to ", decoded->size(),
                         " points; this server takes at most ", max_batch_points, " per batch"));
      }
      return decoded;
    }
    case v1::PointBatch::DATA_NOT_SET:
      break;
  }
  return absl::InvalidArgumentError(
      "the batch has no points: set PointBatch.packed or PointBatch.draco_point_cloud");
}

absl::StatusOr<TriangleMesh> TriangleMeshFromPacked(const v1::PackedMesh& packed,
                                                    absl::string_view field) {
  TriangleMesh mesh;
  const std::string& positions = packed.positions();
  const std::string& faces = packed.faces();
  if (positions.empty()) return absl::InvalidArgumentError(absl::StrCat(field, " has no vertices"));
  if (positions.size() % sizeof(Vec3f) != 0 || faces.size() % sizeof(mesh.faces[0]) != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, " has ", positions.size(), " bytes of positions and ", faces.size(),
        " of faces; each must be a multiple of 12 (x, y, z as little-endian float32; three "
        "little-endian uint32 vertex indices)"));
  }
  mesh.positions.resize(positions.size() / sizeof(Vec3f));
  std::memcpy(mesh.positions.data(), positions.data(), positions.size());
  mesh.faces.resize(faces.size() / sizeof(mesh.faces[0]));
  if (!faces.empty()) std::memcpy(mesh.faces.data(), faces.data(), faces.size());
  return mesh;
}

absl::StatusOr<TriangleMesh> StartMeshFromProto(const v1::StartMesh& start) {
  switch (start.data_case()) {
    case v1::StartMesh::kPacked:
      return TriangleMeshFromPacked(start.packed(), "start_mesh.packed");
    case v1::StartMesh::kDracoMesh: {
      absl::StatusOr<TriangleMesh> decoded = DecodeMesh(start.draco_mesh());
      if (!decoded.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("start_mesh.draco_mesh: ", decoded.status().message()));
      }
      return decoded;
    }
    case v1::StartMesh::DATA_NOT_SET:
      break;
  }
  return absl::InvalidArgumentError(
      "start_mesh holds no mesh: set StartMesh.packed or StartMesh.draco_mesh");
}

}  // namespace neuralmesh::server
