// Tests of client/proto_conversion.h (named client_* because the server has a
// proto_conversion_test of its own).
#include "client/proto_conversion.h"
#include "gtest/gtest.h"

namespace neuralmesh::client {
namespace {

TEST(ClientProtoConversionTest, SetsEveryLearnerField) {
  LearnerOptions options;
  options.alpha_w = 0.1;
  options.alpha_l = 0.2;
  options.c_l = 3;
  options.c_vs = 50;
  options.c_ec = 7.5;
  options.early_phase_vertices = 10000;
  options.early_c_vs = 400;
  options.early_c_ec = 6.5;
  options.alpha_sc = 0.9;
  options.remove_triangles = false;
  options.alpha_r = 6;
  options.merge_boundaries = false;
  options.alpha_m = 4;
  options.splits_per_step = 2;
  options.seed = 99;
  options.close_small_holes = false;
  options.max_closed_hole_vertices = 5;
  options.merge_only_settled_boundaries = false;
  options.split_largest_cell_near_most_active = false;
  options.sewn_strip_grace_calls = 0;
  options.min_merged_loop_vertices = 5;
  options.cut_inactive_faces = false;
  options.initial_mesh = InitialMesh::kDisc;
  const v1::LearnerOptions proto = ToProto(options);
  EXPECT_EQ(proto.alpha_w().value(), 0.1);
  EXPECT_EQ(proto.alpha_l().value(), 0.2);
  EXPECT_EQ(proto.c_l().value(), 3);
  EXPECT_EQ(proto.c_vs().value(), 50);
  EXPECT_EQ(proto.c_ec().value(), 7.5);
  EXPECT_EQ(proto.early_phase_vertices().value(), 10000u);
  EXPECT_EQ(proto.early_c_vs().value(), 400);
  EXPECT_EQ(proto.early_c_ec().value(), 6.5);
  ASSERT_TRUE(ToProto(LearnerOptions{}).has_early_phase_vertices())
      << "0 (no early phase) must be sent, not left unset";
  EXPECT_EQ(proto.alpha_sc().value(), 0.9);
  ASSERT_TRUE(proto.has_remove_triangles()) << "false must be sent, not left unset";
  EXPECT_FALSE(proto.remove_triangles().value());
  EXPECT_EQ(proto.alpha_r().value(), 6);
  ASSERT_TRUE(proto.has_merge_boundaries());
  EXPECT_FALSE(proto.merge_boundaries().value());
  EXPECT_EQ(proto.alpha_m().value(), 4);
  EXPECT_EQ(proto.splits_per_step().value(), 2);
  EXPECT_EQ(proto.seed().value(), 99u);
  ASSERT_TRUE(proto.has_close_small_holes());
  EXPECT_FALSE(proto.close_small_holes().value());
  EXPECT_EQ(proto.max_closed_hole_vertices().value(), 5);
  ASSERT_TRUE(proto.has_merge_only_settled_boundaries());
  EXPECT_FALSE(proto.merge_only_settled_boundaries().value());
  ASSERT_TRUE(proto.has_split_largest_cell_near_most_active());
  EXPECT_FALSE(proto.split_largest_cell_near_most_active().value());
  ASSERT_TRUE(proto.has_sewn_strip_grace_calls()) << "0 must be sent, not left unset";
  EXPECT_EQ(proto.sewn_strip_grace_calls().value(), 0);
  EXPECT_EQ(proto.min_merged_loop_vertices().value(), 5);
  ASSERT_TRUE(proto.has_cut_inactive_faces());
  EXPECT_FALSE(proto.cut_inactive_faces().value());
  EXPECT_EQ(proto.initial_mesh(), v1::INITIAL_MESH_DISC);
  EXPECT_EQ(ToProto(LearnerOptions{}).initial_mesh(), v1::INITIAL_MESH_TETRAHEDRON);
}

TEST(ClientProtoConversionTest, DracoSpeedBecomesCompressionSpeed) {
  DracoOptions options;
  options.position_quantization_bits = 14;
  options.encode_speed = 9;
  options.decode_speed = 2;
  const v1::DracoOptions proto = ToProto(options);
  EXPECT_EQ(proto.position_quantization_bits().value(), 14);
  EXPECT_EQ(proto.compression_speed().value(), 9);
  EXPECT_EQ(proto.decode_speed().value(), 2);
}

TEST(ClientProtoConversionTest, CopiesTheBox) {
  BoundingBox box;
  box.Extend(Vec3(-1, -2, -3));
  box.Extend(Vec3(4, 5, 6));
  const v1::Box proto = ToProto(box);
  EXPECT_EQ(proto.min_x(), -1.0f);
  EXPECT_EQ(proto.min_z(), -3.0f);
  EXPECT_EQ(proto.max_y(), 5.0f);
  EXPECT_EQ(proto.max_z(), 6.0f);
}

}  // namespace
}  // namespace neuralmesh::client
