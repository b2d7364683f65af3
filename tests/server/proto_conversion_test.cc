#include "server/proto_conversion.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/io/draco_codec.h"
#include "tests/server/server_test_support.h"

namespace neuralmesh::server {
namespace {

using ::testing::HasSubstr;

PointCloud ThreePoints() {
  PointCloud cloud;
  cloud.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  return cloud;
}

TEST(PointBatchFromProtoTest, UnpacksPositionsWeightsAndNormals) {
  PointCloud cloud = ThreePoints();
  cloud.weights = {1, 2, 3};
  cloud.normals = {Vec3f(0, 0, 1), Vec3f(0, 0, 1), Vec3f(0, 0, 1)};
  absl::StatusOr<PointCloud> back = PointBatchFromProto(testing::Batch(cloud), 100);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->positions, cloud.positions);
  EXPECT_EQ(back->weights, cloud.weights);
  EXPECT_EQ(back->normals, cloud.normals);
}

TEST(PointBatchFromProtoTest, RejectsMalformedBatchesSayingWhatIsWrong) {
  struct Case {
    const char* what;
    v1::PointBatch batch;
    absl::StatusCode code;
    const char* message;
  };
  std::vector<Case> cases;
  cases.push_back(
      {"no encoding", v1::PointBatch(), absl::StatusCode::kInvalidArgument, "no points"});
  {
    v1::PointBatch b;
    b.mutable_packed();
    cases.push_back({"empty positions", b, absl::StatusCode::kInvalidArgument, "no points"});
  }
  {
    v1::PointBatch b = testing::Batch(ThreePoints());
    b.mutable_packed()->mutable_positions()->push_back('x');
    cases.push_back(
        {"ragged positions", b, absl::StatusCode::kInvalidArgument, "not a multiple of 12"});
  }
  {
    v1::PointBatch b = testing::Batch(ThreePoints());
    b.mutable_packed()->set_weights(std::string(8, '\0'));
    cases.push_back({"weights for two of three points", b, absl::StatusCode::kInvalidArgument,
                     "PackedPoints.weights has 8 bytes"});
  }
  {
    v1::PointBatch b = testing::Batch(ThreePoints());
    b.mutable_packed()->set_normals(std::string(24, '\0'));
    cases.push_back({"normals for two of three points", b, absl::StatusCode::kInvalidArgument,
                     "PackedPoints.normals has 24 bytes"});
  }
  {
    v1::PointBatch b;
    b.set_draco_point_cloud("DRACO this is not");
    cases.push_back({"corrupt Draco", b, absl::StatusCode::kInvalidArgument, "draco_point_cloud"});
  }
  for (const Case& c : cases) {
    absl::StatusOr<PointCloud> result = PointBatchFromProto(c.batch, 100);
    EXPECT_EQ(result.status().code(), c.code) << c.what << ": " << result.status();
    EXPECT_THAT(std::string(result.status().message()), HasSubstr(c.message)) << c.what;
  }
}

TEST(PointBatchFromProtoTest, OversizedBatchIsResourceExhausted) {
  absl::StatusOr<PointCloud> result = PointBatchFromProto(testing::Batch(ThreePoints()), 2);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kResourceExhausted) << result.status();
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("at most 2"));
}

// The limit applies to the count a Draco batch declares, before it is decoded: identical points
// compress to almost nothing, so a small message could otherwise make the server allocate for
// billions of points.
TEST(PointBatchFromProtoTest, OversizedDracoBatchIsRefusedBeforeDecoding) {
  PointCloud many;
  many.positions.assign(5000, Vec3f(1, 2, 3));
  absl::StatusOr<std::string> bytes = EncodePointCloud(many, DracoOptions());
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  EXPECT_LT(bytes->size(), 1000u) << "5,000 identical points take a few hundred bytes";
  v1::PointBatch batch;
  batch.set_draco_point_cloud(*bytes);
  absl::StatusOr<PointCloud> result = PointBatchFromProto(batch, 4999);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kResourceExhausted) << result.status();
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("declares 5000 points"));
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("at most 4999 points per batch"));
  EXPECT_TRUE(PointBatchFromProto(batch, 5000).ok());
}

TEST(PointBatchFromProtoTest, DecodesDracoPointClouds) {
  PointCloud cloud = ThreePoints();
  cloud.weights = {1, 2, 4};
  absl::StatusOr<std::string> bytes = EncodePointCloud(cloud, DracoOptions());
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  v1::PointBatch batch;
  batch.set_draco_point_cloud(*bytes);
  absl::StatusOr<PointCloud> back = PointBatchFromProto(batch, 100);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->size(), 3u);
  EXPECT_EQ(back->weights.size(), 3u) << "weights travel as a generic attribute";
}

TEST(SessionConfigFromProtoTest, UnsetFieldsTakeDefaultsAndSetOnesAreKept) {
  v1::SessionConfig proto;
  proto.set_target_vertices(500);
  absl::StatusOr<SessionConfig> config = SessionConfigFromProto(proto);
  ASSERT_TRUE(config.ok());
  EXPECT_EQ(config->learner.alpha_w, LearnerOptions().alpha_w) << "paper default";
  EXPECT_EQ(config->refresh_interval, kDefaultRefreshInterval);
  EXPECT_EQ(config->points_per_vertex, kDefaultPointsPerVertex);
  EXPECT_FALSE(config->bounds.has_value());
  EXPECT_FALSE(config->outlier_removal.has_value()) << "unset: every point is accepted";
  EXPECT_FALSE(SessionConfigToProto(*config).has_outlier_removal());
  EXPECT_EQ(config->colors.neighbours, PointColorOptions().neighbours);
  EXPECT_EQ(config->learner.early_phase_vertices, 0u) << "no early phase by default";
  EXPECT_EQ(config->learner.early_c_vs, 500) << "the paper's David setting";
  EXPECT_EQ(config->learner.early_c_ec, 8);

  proto.mutable_learner()->mutable_alpha_l()->set_value(0);  // A valid zero, not "unset".
  proto.mutable_learner()->mutable_remove_triangles()->set_value(false);
  proto.mutable_learner()->mutable_split_largest_cell_near_most_active()->set_value(false);
  proto.mutable_learner()->mutable_sewn_strip_grace_calls()->set_value(0);
  proto.mutable_learner()->mutable_min_merged_loop_vertices()->set_value(3);
  proto.mutable_learner()->mutable_cut_inactive_faces()->set_value(false);
  proto.mutable_learner()->set_initial_mesh(v1::INITIAL_MESH_DISC);
  proto.mutable_learner()->mutable_early_phase_vertices()->set_value(10000);
  proto.mutable_learner()->mutable_early_c_vs()->set_value(400);
  proto.mutable_learner()->mutable_early_c_ec()->set_value(6.5);
  proto.mutable_refresh_interval_ms()->set_value(0);
  proto.mutable_draco()->mutable_position_quantization_bits()->set_value(14);
  proto.mutable_outlier_removal()->mutable_std_ratio()->set_value(2.5);
  proto.mutable_color_neighbours()->set_value(3);
  proto.mutable_origin()->set_x(500000);
  proto.mutable_origin()->set_y(4100000.5);
  proto.mutable_upload_order()->set_name("points-spread-256");
  proto.mutable_upload_order()->set_items(20000);
  proto.mutable_upload_order()->set_fingerprint(0xfedcba9876543210);
  config = SessionConfigFromProto(proto);
  ASSERT_TRUE(config.ok());
  EXPECT_EQ(config->learner.alpha_l, 0.0);
  EXPECT_FALSE(config->learner.remove_triangles);
  EXPECT_FALSE(config->learner.split_largest_cell_near_most_active);
  EXPECT_EQ(config->learner.sewn_strip_grace_calls, 0) << "0 is the paper's rule, not unset";
  EXPECT_EQ(config->learner.min_merged_loop_vertices, 3);
  EXPECT_FALSE(config->learner.cut_inactive_faces);
  EXPECT_EQ(config->learner.initial_mesh, InitialMesh::kDisc);
  EXPECT_EQ(config->learner.early_phase_vertices, 10000u);
  EXPECT_EQ(config->learner.early_c_vs, 400);
  EXPECT_EQ(config->learner.early_c_ec, 6.5);
  EXPECT_EQ(config->refresh_interval, absl::ZeroDuration()) << "0 turns refreshes off";
  EXPECT_EQ(config->draco.position_quantization_bits, 14);
  ASSERT_TRUE(config->outlier_removal.has_value()) << "an empty message turns it on";
  EXPECT_EQ(config->outlier_removal->neighbours, OutlierOptions().neighbours);
  EXPECT_EQ(config->outlier_removal->std_ratio, 2.5);
  EXPECT_EQ(config->colors.neighbours, 3);
  EXPECT_EQ(config->origin, (std::array<double, 3>{500000, 4100000.5, 0}));
  ASSERT_TRUE(config->upload_order.has_value());
  EXPECT_EQ(config->upload_order->name, "points-spread-256");
  EXPECT_EQ(config->upload_order->items, 20000u);
  EXPECT_EQ(config->upload_order->fingerprint, 0xfedcba9876543210);

  // The echo has every field set and reads back to the same configuration.
  v1::SessionConfig echo = SessionConfigToProto(*config);
  EXPECT_TRUE(echo.learner().has_alpha_w());
  absl::StatusOr<SessionConfig> again = SessionConfigFromProto(echo);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->learner.alpha_l, 0.0);
  EXPECT_FALSE(again->learner.split_largest_cell_near_most_active);
  EXPECT_EQ(again->learner.sewn_strip_grace_calls, 0);
  EXPECT_EQ(again->learner.min_merged_loop_vertices, 3);
  EXPECT_FALSE(again->learner.cut_inactive_faces);
  EXPECT_EQ(again->learner.initial_mesh, InitialMesh::kDisc);
  EXPECT_EQ(again->learner.early_phase_vertices, 10000u);
  EXPECT_EQ(again->learner.early_c_vs, 400);
  EXPECT_EQ(again->learner.early_c_ec, 6.5);
  EXPECT_EQ(again->draco.position_quantization_bits, 14);
  EXPECT_TRUE(echo.outlier_removal().has_neighbours());
  ASSERT_TRUE(again->outlier_removal.has_value());
  EXPECT_EQ(again->outlier_removal->neighbours, OutlierOptions().neighbours);
  EXPECT_EQ(again->outlier_removal->std_ratio, 2.5);
  EXPECT_EQ(again->colors.neighbours, 3);
  EXPECT_EQ(again->origin, config->origin);
  EXPECT_EQ(echo.upload_order().name(), "points-spread-256");
  EXPECT_EQ(echo.upload_order().items(), 20000u);
  EXPECT_EQ(echo.upload_order().fingerprint(), 0xfedcba9876543210);
  EXPECT_FALSE(SessionConfigToProto(SessionConfig()).has_upload_order()) << "unset stays unset";
  proto.mutable_upload_order()->clear_name();
  config = SessionConfigFromProto(proto);
  ASSERT_TRUE(config.ok());
  EXPECT_FALSE(config->upload_order.has_value()) << "an order without a name says nothing";
}

TEST(SessionConfigFromProtoTest, UnknownInitialMeshIsInvalidArgument) {
  v1::SessionConfig proto;
  proto.set_target_vertices(1000);
  EXPECT_EQ(SessionConfigFromProto(proto)->learner.initial_mesh, InitialMesh::kTetrahedron)
      << "unset is the paper's tetrahedron";
  proto.mutable_learner()->set_initial_mesh(static_cast<v1::InitialMesh>(9));
  const absl::StatusOr<SessionConfig> config = SessionConfigFromProto(proto);
  EXPECT_EQ(config.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(config.status().message().find("initial_mesh"), absl::string_view::npos)
      << config.status();
}

}  // namespace
}  // namespace neuralmesh::server
