#include "client/proto_conversion.h"
#include "proto/packing.h"

namespace neuralmesh::client {

v1::LearnerOptions ToProto(const LearnerOptions& options) {
  v1::LearnerOptions proto;
  proto.mutable_alpha_w()->set_value(options.alpha_w);
  proto.mutable_alpha_l()->set_value(options.alpha_l);
  proto.mutable_c_l()->set_value(options.c_l);
  proto.mutable_c_vs()->set_value(options.c_vs);
  proto.mutable_c_ec()->set_value(options.c_ec);
  proto.mutable_early_phase_vertices()->set_value(options.early_phase_vertices);
  proto.mutable_early_c_vs()->set_value(options.early_c_vs);
  proto.mutable_early_c_ec()->set_value(options.early_c_ec);
  proto.mutable_alpha_sc()->set_value(options.alpha_sc);
  proto.mutable_remove_triangles()->set_value(options.remove_triangles);
  proto.mutable_alpha_r()->set_value(options.alpha_r);
  proto.mutable_merge_boundaries()->set_value(options.merge_boundaries);
  proto.mutable_alpha_m()->set_value(options.alpha_m);
  proto.mutable_splits_per_step()->set_value(options.splits_per_step);
  proto.mutable_close_small_holes()->set_value(options.close_small_holes);
  proto.mutable_max_closed_hole_vertices()->set_value(options.max_closed_hole_vertices);
  proto.mutable_merge_only_settled_boundaries()->set_value(
      options.merge_only_settled_boundaries);
  proto.mutable_split_largest_cell_near_most_active()->set_value(
      options.split_largest_cell_near_most_active);
  proto.mutable_sewn_strip_grace_calls()->set_value(options.sewn_strip_grace_calls);
  proto.mutable_min_merged_loop_vertices()->set_value(options.min_merged_loop_vertices);
  proto.mutable_cut_inactive_faces()->set_value(options.cut_inactive_faces);
  proto.set_initial_mesh(options.initial_mesh == InitialMesh::kDisc
                             ? v1::INITIAL_MESH_DISC
                             : v1::INITIAL_MESH_TETRAHEDRON);
  proto.mutable_seed()->set_value(options.seed);
  return proto;
}

v1::DracoOptions ToProto(const DracoOptions& options) {
  v1::DracoOptions proto;
  proto.mutable_position_quantization_bits()->set_value(options.position_quantization_bits);
  proto.mutable_compression_speed()->set_value(options.encode_speed);
  proto.mutable_decode_speed()->set_value(options.decode_speed);
  return proto;
}

v1::Box ToProto(const BoundingBox& box) {
  v1::Box proto;
  proto.set_min_x(static_cast<float>(box.min[0]));
  proto.set_min_y(static_cast<float>(box.min[1]));
  proto.set_min_z(static_cast<float>(box.min[2]));
  proto.set_max_x(static_cast<float>(box.max[0]));
  proto.set_max_y(static_cast<float>(box.max[1]));
  proto.set_max_z(static_cast<float>(box.max[2]));
  return proto;
}

v1::StartMesh ToProto(const TriangleMesh& mesh) {
  v1::StartMesh proto;
  *proto.mutable_packed() = PackMesh(mesh);
  return proto;
}

}  // namespace neuralmesh::client
