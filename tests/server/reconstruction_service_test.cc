// The service's logic over an in-process channel (no sockets).
#include "server/reconstruction_service.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/analysis/mesh_report.h"
#include "core/analysis/statistical_outliers.h"
#include "core/io/draco_codec.h"
#include "core/random.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/shapes.h"

namespace neuralmesh::server {
namespace {

using ::testing::HasSubstr;
using testing::Batch;
using testing::CreateRequest;
using testing::InProcessService;
using testing::MustCreate;
using testing::StartServer;
using testing::TorusPoints;

class ReconstructionServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.limits.max_batch_points = 5000;
    options.limits.max_sessions = 16;
    server_ = StartServer(/*listen=*/false, options);
    ASSERT_NE(server_, nullptr);
    service_ = InProcessService(*server_);
  }
  void TearDown() override { server_->Shutdown(absl::Seconds(2)); }

  v1::UploadPointsRequest Request(const std::string& id, v1::PointBatch batch) {
    v1::UploadPointsRequest request;
    request.set_session_id(id);
    *request.mutable_batch() = std::move(batch);
    return request;
  }

  grpc::Status UploadOne(const v1::UploadPointsRequest& request,
                         v1::UploadPointsResponse* response = nullptr) {
    v1::UploadPointsResponse ignored;
    return testing::UploadOne(*service_, request, response != nullptr ? response : &ignored);
  }

  // A Reconstruct call that has created a session of `target` vertices and sent `batch`.
  std::unique_ptr<grpc::ClientReaderWriter<v1::ReconstructRequest, v1::ReconstructResponse>>
  StartReconstruct(grpc::ClientContext& context, uint64_t target, const v1::PointBatch& batch) {
    auto stream = service_->Reconstruct(&context);
    v1::ReconstructRequest start;
    *start.mutable_start()->mutable_create() = CreateRequest(target);
    EXPECT_TRUE(stream->Write(start));
    v1::ReconstructRequest points;
    *points.mutable_points() = batch;
    EXPECT_TRUE(stream->Write(points));
    return stream;
  }

  std::unique_ptr<ReconstructionServer> server_;
  std::unique_ptr<v1::ReconstructionService::Stub> service_;
};

TEST_F(ReconstructionServiceTest, CreateGetListAndDelete) {
  const std::string id = MustCreate(*service_, CreateRequest(500));
  ASSERT_FALSE(id.empty());
  grpc::Status status;
  v1::Session session = testing::GetSession(*service_, id, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(session.state(), v1::SESSION_STATE_COLLECTING);
  EXPECT_EQ(session.name(), "test");
  EXPECT_DOUBLE_EQ(session.config().learner().alpha_w().value(), 0.06)
      << "unset options echo the paper's defaults";
  EXPECT_EQ(session.config().lod_milestones_size(), 4) << "50 100 200 500";
  EXPECT_EQ(session.config().draco().position_quantization_bits().value(), 11);

  grpc::ClientContext list_context;
  v1::ListSessionsResponse list;
  ASSERT_TRUE(service_->ListSessions(&list_context, v1::ListSessionsRequest(), &list).ok());
  ASSERT_EQ(list.sessions_size(), 1);
  EXPECT_EQ(list.sessions(0).session_id(), id);

  ASSERT_TRUE(testing::Delete(*service_, id).ok());
  testing::GetSession(*service_, id, &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(testing::Delete(*service_, id).error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(ReconstructionServiceTest, InvalidOptionsAreInvalidArgumentNamingTheField) {
  struct Case {
    const char* what;
    v1::CreateSessionRequest request;
    const char* field;
  };
  std::vector<Case> cases;
  cases.push_back({"target below 4", CreateRequest(3), "target_vertices"});
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_learner()->mutable_alpha_w()->set_value(0);
    cases.push_back({"alpha_w = 0", r, "alpha_w"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_learner()->mutable_alpha_w()->set_value(1.01);
    cases.push_back({"alpha_w > 1", r, "alpha_w"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_learner()->mutable_early_c_vs()->set_value(0);
    cases.push_back({"early_c_vs = 0", r, "early_c_vs"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->add_lod_milestones(50);
    r.mutable_config()->add_lod_milestones(20);
    cases.push_back({"milestones decreasing", r, "lod_milestones"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_draco()->mutable_position_quantization_bits()->set_value(31);
    cases.push_back({"31 quantization bits", r, "position_quantization_bits"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_draco()->mutable_compression_speed()->set_value(11);
    cases.push_back({"compression speed 11", r, "DracoOptions.compression_speed is 11"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_points_per_vertex()->set_value(-1);
    cases.push_back({"negative points_per_vertex", r, "points_per_vertex"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_learner()->set_initial_mesh(static_cast<v1::InitialMesh>(9));
    cases.push_back({"unknown initial mesh", r, "initial_mesh"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_outlier_removal()->mutable_neighbours()->set_value(0);
    cases.push_back({"0 outlier neighbours", r, "outlier_removal: outlier neighbours = 0"});
  }
  {
    v1::CreateSessionRequest r = CreateRequest(100);
    r.mutable_config()->mutable_outlier_removal()->mutable_std_ratio()->set_value(-1);
    cases.push_back({"negative outlier std_ratio", r, "outlier_removal: outlier std_ratio"});
  }
  for (const Case& c : cases) {
    grpc::ClientContext context;
    v1::Session session;
    grpc::Status status = service_->CreateSession(&context, c.request, &session);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << c.what;
    EXPECT_THAT(status.error_message(), HasSubstr(c.field)) << c.what;
  }
}

TEST_F(ReconstructionServiceTest, BatchesSentAgainCountOnlyTheirNewPoints) {
  const std::string id = MustCreate(*service_, CreateRequest(50));
  const PointCloud points = TorusPoints(3000, 8);
  auto batch = [&](size_t begin, size_t end) {
    v1::PointBatch b = testing::Batch(points, begin, end);
    b.mutable_first_point()->set_value(begin);
    return b;
  };
  v1::UploadPointsResponse response;
  ASSERT_TRUE(UploadOne(Request(id, batch(0, 2000)), &response).ok());
  EXPECT_EQ(response.points_accepted(), 2000u);
  // The connection was lost before the client saw the answer: it sends from 1000 again.
  ASSERT_TRUE(UploadOne(Request(id, batch(1000, 3000)), &response).ok());
  EXPECT_EQ(response.points_accepted(), 1000u) << "only points 2000-2999 are new";
  EXPECT_EQ(response.total_points(), 3000u);
  const grpc::Status known = UploadOne(Request(id, batch(2500, 2600)), &response);
  EXPECT_EQ(known.error_code(), grpc::StatusCode::OK) << "2500 < 3000: all known";
  EXPECT_EQ(response.points_accepted(), 0u);
  v1::PointBatch beyond = testing::Batch(points, 0, 10);
  beyond.mutable_first_point()->set_value(3001);
  const grpc::Status refused = UploadOne(Request(id, beyond), &response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::OUT_OF_RANGE) << refused.error_message();
  EXPECT_THAT(refused.error_message(), ::testing::HasSubstr("send from point 3000"));
  const v1::Session session = testing::GetSession(*service_, id);
  EXPECT_EQ(session.points_taken(), 3000u);
  EXPECT_EQ(session.learning().points_received(), 3000u);
}

TEST_F(ReconstructionServiceTest, MaxSessionsIsResourceExhausted) {
  for (int i = 0; i < 16; ++i) MustCreate(*service_, CreateRequest(100));
  grpc::ClientContext context;
  v1::Session session;
  grpc::Status status = service_->CreateSession(&context, CreateRequest(100), &session);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("maximum of 16 sessions"));
}

TEST_F(ReconstructionServiceTest, EveryBadInputGetsItsStatusAndTheSessionGoesOn) {
  const std::string id = MustCreate(*service_, CreateRequest(200));
  const PointCloud points = TorusPoints(4000, 11);
  v1::UploadPointsResponse response;
  ASSERT_TRUE(UploadOne(Request(id, Batch(points, 0, 1000)), &response).ok());
  EXPECT_EQ(response.total_points(), 1000u);

  struct Case {
    const char* what;
    v1::UploadPointsRequest request;
    grpc::StatusCode code;
    const char* message;
  };
  std::vector<Case> cases;
  {
    PointCloud bad;
    bad.positions = {Vec3f(0, 0, 0), Vec3f(std::nanf(""), 0, 0)};
    cases.push_back({"NaN coordinate", Request(id, testing::Batch(bad, 0, 2)),
                     grpc::StatusCode::INVALID_ARGUMENT, "batch 1 of this call rejected"});
    bad.positions[1] = Vec3f(0, INFINITY, 0);
    cases.push_back({"infinite coordinate", Request(id, testing::Batch(bad, 0, 2)),
                     grpc::StatusCode::INVALID_ARGUMENT, "the session keeps its 1000 points"});
  }
  {
    v1::PointBatch batch = Batch(points, 1000, 1010);
    batch.mutable_packed()->set_weights(std::string(9 * 4, '\0'));
    cases.push_back({"weights of the wrong length", Request(id, batch),
                     grpc::StatusCode::INVALID_ARGUMENT, "weights has 36 bytes"});
  }
  {
    v1::PointBatch batch = Batch(points, 1000, 1010);
    batch.mutable_packed()->mutable_positions()->resize(10 * 12 - 4);
    cases.push_back({"positions not a multiple of 12", Request(id, batch),
                     grpc::StatusCode::INVALID_ARGUMENT, "multiple of 12"});
  }
  {
    v1::PointBatch batch;
    batch.mutable_packed();
    cases.push_back({"empty batch", Request(id, batch), grpc::StatusCode::INVALID_ARGUMENT,
                     "no points"});
  }
  cases.push_back({"oversized batch", Request(id, Batch(TorusPoints(6000, 12), 0, 6000)),
                   grpc::StatusCode::RESOURCE_EXHAUSTED, "at most 5000"});
  {
    v1::PointBatch batch;
    batch.set_draco_point_cloud(std::string("DRACO\x02\x02\x00\x00garbage", 16));
    cases.push_back({"corrupt Draco", Request(id, batch), grpc::StatusCode::INVALID_ARGUMENT,
                     "draco_point_cloud"});
  }
  cases.push_back({"unknown session", Request("s-nope", Batch(points, 0, 10)),
                   grpc::StatusCode::NOT_FOUND, "s-nope"});
  cases.push_back({"no session id", Request("", Batch(points, 0, 10)),
                   grpc::StatusCode::INVALID_ARGUMENT, "session_id"});

  for (const Case& c : cases) {
    grpc::Status status = UploadOne(c.request);
    EXPECT_EQ(status.error_code(), c.code) << c.what << ": " << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(c.message)) << c.what;
    EXPECT_EQ(testing::GetSession(*service_, id).learning().points_received(), 1000u)
        << c.what << " changed the session";
  }

  // A stream whose later batch is bad keeps the batches before it.
  {
    grpc::ClientContext context;
    auto writer = service_->UploadPoints(&context, &response);
    writer->Write(Request(id, Batch(points, 1000, 1500)));
    v1::UploadPointsRequest bad = Request("", Batch(points, 1500, 1510));
    bad.mutable_batch()->mutable_packed()->mutable_positions()->resize(7);
    writer->Write(bad);
    writer->WritesDone();
    grpc::Status status = writer->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("batch 2 of this call rejected"));
    EXPECT_THAT(status.error_message(),
                HasSubstr("the session keeps its 1500 points, 500 of them from the 1 batch this "
                          "call sent before"));
  }
  EXPECT_EQ(testing::GetSession(*service_, id).learning().points_received(), 1500u);

  // Draco point clouds are accepted like packed ones.
  {
    absl::StatusOr<std::string> draco =
        EncodePointCloud(PointRange(points, 1500, 4000), DracoOptions());
    ASSERT_TRUE(draco.ok());
    v1::PointBatch batch;
    batch.set_draco_point_cloud(*draco);
    ASSERT_TRUE(UploadOne(Request(id, batch), &response).ok());
    EXPECT_EQ(response.total_points(), 4000u);
  }

  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  v1::MeshUpdate final_mesh;
  grpc::Status status = testing::WaitFinal(*service_, id, &final_mesh);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(final_mesh.vertex_count(), 200u) << "the session went on to its target";

  status = UploadOne(Request(id, Batch(points, 0, 10)));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << "finished session";
  EXPECT_THAT(status.error_message(), HasSubstr("FINISHED"));
  EXPECT_EQ(testing::Finish(*service_, id).error_code(), grpc::StatusCode::FAILED_PRECONDITION);

  const std::string cancelled = MustCreate(*service_, CreateRequest(200));
  v1::Session session;
  ASSERT_TRUE(testing::Cancel(*service_, cancelled, &session).ok());
  EXPECT_EQ(session.state(), v1::SESSION_STATE_CANCELLED);
  status = UploadOne(Request(cancelled, Batch(points, 0, 10)));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << "cancelled session";
  EXPECT_EQ(testing::Finish(*service_, "s-unknown").error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(ReconstructionServiceTest, WatchersJoinLateLeaveEarlyAndReadSlowly) {
  const std::string id = MustCreate(*service_, CreateRequest(1000, /*refresh_ms=*/10));
  const PointCloud points = TorusPoints(20000, 13);

  std::vector<v1::MeshUpdate> early_updates, slow_updates;
  grpc::Status early_status, slow_status, leaver_status;
  std::thread early([&] { early_status = testing::WatchAll(*service_, id, &early_updates); });
  std::thread slow([&] {
    grpc::ClientContext context;
    v1::WatchSessionRequest request;
    request.set_session_id(id);
    auto reader = service_->WatchSession(&context, request);
    v1::MeshUpdate update;
    while (reader->Read(&update)) {
      slow_updates.push_back(update);
      absl::SleepFor(absl::Milliseconds(150));  // Much slower than the refreshes.
    }
    slow_status = reader->Finish();
  });
  int leaver_reads = 0;
  std::thread leaver([&] {
    grpc::ClientContext context;
    v1::WatchSessionRequest request;
    request.set_session_id(id);
    auto reader = service_->WatchSession(&context, request);
    v1::MeshUpdate update;
    while (reader->Read(&update)) {
      if (++leaver_reads == 2) context.TryCancel();
    }
    leaver_status = reader->Finish();
  });

  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*service_, id, points, 20, &response).ok());
  EXPECT_EQ(response.total_points(), 20000u);
  EXPECT_EQ(response.batches_accepted(), 20u);

  // A late watcher gets the latest mesh at once.
  // Learning and encoding run concurrently with the upload: wait (bounded) for a mesh.
  v1::Session before = testing::GetSession(*service_, id);
  for (const absl::Time deadline = absl::Now() + absl::Seconds(20);
       before.latest_sequence() == 0 && absl::Now() < deadline;
       before = testing::GetSession(*service_, id)) {
    absl::SleepFor(absl::Milliseconds(5));
  }
  ASSERT_GT(before.latest_sequence(), 0u) << "no mesh was published within 20 s of the upload";
  {
    grpc::ClientContext context;
    v1::WatchSessionRequest request;
    request.set_session_id(id);
    auto reader = service_->WatchSession(&context, request);
    v1::MeshUpdate first;
    ASSERT_TRUE(reader->Read(&first));
    EXPECT_GE(first.sequence(), before.latest_sequence())
        << "a late watcher starts from the latest mesh, not from the beginning";
    context.TryCancel();
    reader->Finish();
  }

  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  early.join();
  slow.join();
  leaver.join();

  ASSERT_TRUE(early_status.ok()) << early_status.error_message();
  ASSERT_FALSE(early_updates.empty());
  EXPECT_EQ(early_updates.back().kind(), v1::UPDATE_KIND_FINAL);
  for (size_t i = 1; i < early_updates.size(); ++i) {
    EXPECT_GT(early_updates[i].sequence(), early_updates[i - 1].sequence());
  }

  ASSERT_TRUE(slow_status.ok()) << "a slow watcher still ends normally: "
                                << slow_status.error_message();
  ASSERT_FALSE(slow_updates.empty());
  EXPECT_EQ(slow_updates.back().kind(), v1::UPDATE_KIND_FINAL)
      << "the final mesh always reaches a slow watcher";
  EXPECT_EQ(slow_updates.back().sequence(), early_updates.back().sequence());
  bool skipped = false;
  for (size_t i = 1; i < slow_updates.size(); ++i) {
    EXPECT_GT(slow_updates[i].sequence(), slow_updates[i - 1].sequence());
    skipped |= slow_updates[i].sequence() > slow_updates[i - 1].sequence() + 1;
  }
  if (early_updates.back().sequence() > slow_updates.size() + 2) {
    EXPECT_TRUE(skipped) << "a slow watcher skips to the newest update";
  }

  EXPECT_EQ(leaver_status.error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_EQ(leaver_reads, 2);
  EXPECT_EQ(testing::GetSession(*service_, id).watchers(), 0u) << "every watcher unsubscribed";
}

TEST_F(ReconstructionServiceTest, ReconstructDoesEverythingInOneCall) {
  const PointCloud points = TorusPoints(4000, 14);
  grpc::ClientContext context;
  auto stream = service_->Reconstruct(&context);
  v1::ReconstructRequest start;
  *start.mutable_start()->mutable_create() = CreateRequest(300);
  ASSERT_TRUE(stream->Write(start));
  for (size_t b = 0; b < 8; ++b) {
    v1::ReconstructRequest request;
    *request.mutable_points() = Batch(points, b * 500, (b + 1) * 500);
    ASSERT_TRUE(stream->Write(request));
  }
  stream->WritesDone();

  std::vector<v1::ReconstructResponse> responses;
  v1::ReconstructResponse response;
  while (stream->Read(&response)) responses.push_back(response);
  grpc::Status status = stream->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(responses.size(), 3u);
  EXPECT_EQ(responses.front().kind_case(), v1::ReconstructResponse::kSession);
  uint64_t last_total = 0;
  for (const auto& r : responses) {
    if (r.has_ack()) last_total = r.ack().total_points();
  }
  EXPECT_EQ(last_total, 4000u) << "the last acknowledgement carries the running total";
  ASSERT_TRUE(responses.back().has_update());
  EXPECT_EQ(responses.back().update().kind(), v1::UPDATE_KIND_FINAL);
  EXPECT_EQ(responses.back().update().vertex_count(), 300u);
}

// A client that asks for the disc start gets it: points of a flat square come back as one
// sheet with one border (from the tetrahedron they come back in two layers, README).
TEST_F(ReconstructionServiceTest, ADiscStartGivesAFlatSquareOneBorder) {
  Random rng(21);
  PointCloud points;
  for (int i = 0; i < 20000; ++i) {
    points.positions.emplace_back(rng.NextDouble(), rng.NextDouble(), 0.f);
  }
  grpc::ClientContext context;
  auto stream = service_->Reconstruct(&context);
  v1::ReconstructRequest start;
  *start.mutable_start()->mutable_create() = CreateRequest(2000);
  start.mutable_start()->mutable_create()->mutable_config()->mutable_learner()->set_initial_mesh(
      v1::INITIAL_MESH_DISC);
  ASSERT_TRUE(stream->Write(start));
  for (size_t b = 0; b < 4; ++b) {
    v1::ReconstructRequest request;
    *request.mutable_points() = Batch(points, b * 5000, (b + 1) * 5000);
    ASSERT_TRUE(stream->Write(request));
  }
  stream->WritesDone();
  v1::ReconstructResponse response;
  v1::MeshUpdate last;
  while (stream->Read(&response)) {
    if (response.has_update()) last = response.update();
  }
  grpc::Status status = stream->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(last.kind(), v1::UPDATE_KIND_FINAL);
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(last.draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const MeshReport report = ComputeMeshReport(*mesh);
  EXPECT_EQ(report.boundary_loops, 1u);
  EXPECT_EQ(report.genus, 0);
  EXPECT_TRUE(report.manifold());
  double up = 0;  // The area facing +z and -z: one layer faces one way.
  double down = 0;
  for (const auto& f : mesh->faces) {
    const Vec3f a = mesh->positions[f[0]];
    const Vec3f b = mesh->positions[f[1]];
    const Vec3f c = mesh->positions[f[2]];
    const double z = 0.5 * OpenMesh::cross(b - a, c - a)[2];
    (z > 0 ? up : down) += std::abs(z);
  }
  EXPECT_LT(std::min(up, down), 0.01 * (up + down))
      << "area facing up " << up << ", down " << down << ": two layers";
}

// Sphere points streamed in batches with two strays, one inside a batch and one alone in its
// own: with outlier removal the session holds them back (and few surface points) before they
// count, and drops them for good when it finishes, so the quantization cube stays near the
// sphere and the mesh has no spike; without it, the stray at 100 radii grows the cube past 100.
TEST_F(ReconstructionServiceTest, OutlierRemovalDropsStraysBeforeTheSessionTakesThem) {
  const PointCloud sphere = testing::SpherePoints(20000, 23);
  std::vector<PointCloud> batches(21);
  for (size_t i = 0; i < sphere.size(); ++i) {
    batches[i / 1000].positions.push_back(sphere.positions[i]);
  }
  batches[7].positions.emplace_back(100.f, 0.f, 0.f);
  batches[20].positions.emplace_back(0.f, 0.f, -50.f);  // A stray alone in its batch.
  auto upload = [&](const std::string& id, v1::UploadPointsResponse* response) {
    grpc::ClientContext context;
    auto writer = service_->UploadPoints(&context, response);
    for (const PointCloud& batch : batches) {
      v1::UploadPointsRequest request;
      request.set_session_id(id);
      *request.mutable_batch() = testing::Batch(batch);
      EXPECT_TRUE(writer->Write(request));
    }
    writer->WritesDone();
    return writer->Finish();
  };

  v1::CreateSessionRequest create = CreateRequest(2000);
  create.mutable_config()->mutable_outlier_removal();  // Set, with the defaults.
  const std::string id = MustCreate(*service_, create);
  v1::UploadPointsResponse response;
  const grpc::Status status = upload(id, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.points_accepted() + response.points_held_back(), 20002u);
  EXPECT_GE(response.points_held_back(), 2u);
  EXPECT_LE(response.points_held_back(), 2u + 100u) << "at most 0.5% of the sphere";
  v1::Session session = testing::GetSession(*service_, id);
  EXPECT_EQ(session.config().outlier_removal().neighbours().value(), 16) << "defaults echoed";
  EXPECT_DOUBLE_EQ(session.config().outlier_removal().std_ratio().value(), 3.0);
  const v1::LearningState& learning = session.learning();
  EXPECT_EQ(learning.points_received(),
            response.points_accepted() + learning.outliers_accepted_later());
  EXPECT_EQ(learning.outliers_held() + learning.outliers_accepted_later() +
                learning.points_removed_as_outliers(),
            response.points_held_back());
  EXPECT_GE(learning.outliers_held(), 1u) << "the stray alone in the last batch";
  EXPECT_LT(session.quantization_box().range(), 10.f);
  v1::UploadPointsRequest nan;  // Refused as without outlier removal, nothing added.
  nan.set_session_id(id);
  PointCloud nan_points = batches[0];
  nan_points.positions[5][1] = std::nanf("");
  *nan.mutable_batch() = testing::Batch(nan_points);
  v1::UploadPointsResponse refused;
  EXPECT_EQ(testing::UploadOne(*service_, nan, &refused).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(testing::GetSession(*service_, id).learning().points_received(),
            learning.points_received());
  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  const v1::LearningState finished = testing::GetSession(*service_, id).learning();
  EXPECT_EQ(finished.outliers_held(), 0u) << "dropped at the finish";
  EXPECT_EQ(finished.points_received(), learning.points_received());
  EXPECT_EQ(finished.points_removed_as_outliers() + finished.outliers_accepted_later(),
            response.points_held_back());
  v1::MeshUpdate final_mesh;
  const grpc::Status waited = testing::WaitFinal(*service_, id, &final_mesh);
  ASSERT_TRUE(waited.ok()) << waited.error_message();
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(final_mesh.draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  auto unit_sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  ASSERT_TRUE(unit_sphere.ok());
  EXPECT_LT(testing::MaxVertexDistance(*mesh, **unit_sphere), 0.05) << "no spike";
  EXPECT_EQ(ComputeMeshReport(*mesh).genus, 0);

  const std::string unfiltered = MustCreate(*service_, CreateRequest(2000));
  v1::UploadPointsResponse taken_all;
  ASSERT_TRUE(upload(unfiltered, &taken_all).ok());
  EXPECT_EQ(taken_all.points_accepted(), 20002u);
  EXPECT_EQ(taken_all.points_held_back(), 0u);
  EXPECT_GT(testing::GetSession(*service_, unfiltered).quantization_box().range(), 100.f);
  ASSERT_TRUE(testing::Delete(*service_, unfiltered).ok());
}

// testing::WorstColorErrorOnTheUnitSphere of a published mesh.
int WorstColorError(const v1::MeshUpdate& update) {
  const absl::StatusOr<TriangleMesh> mesh = DecodeMesh(update.draco_mesh());
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  return mesh.ok() ? neuralmesh::testing::WorstColorErrorOnTheUnitSphere(*mesh) : -1;
}

// Points with colours, packed or in Draco, give meshes whose vertices carry the colours of
// their positions, with outlier removal too (a black stray, held back and dropped, paints
// nothing); points without give meshes without; colours of the wrong size are refused and
// the session goes on.
TEST_F(ReconstructionServiceTest, ColouredPointsGiveColouredMeshes) {
  const PointCloud sphere = neuralmesh::testing::ColoredUnitSpherePoints(20000, 9);
  for (const bool filtered : {false, true}) {
    SCOPED_TRACE(filtered ? "with outlier removal" : "without outlier removal");
    v1::CreateSessionRequest create = CreateRequest(1500);
    create.mutable_config()->add_lod_milestones(500);
    if (filtered) create.mutable_config()->mutable_outlier_removal();
    const std::string id = MustCreate(*service_, create);
    PointCloud first = PointRange(sphere, 0, 10000);
    if (filtered) {
      first.positions.emplace_back(0.f, 0.f, 60.f);  // A black stray far above.
      first.colors.push_back({0, 0, 0});
    }
    v1::UploadPointsResponse response;
    ASSERT_TRUE(testing::Upload(*service_, id, first, 5, &response).ok());
    v1::UploadPointsRequest draco;  // A quarter as one Draco batch.
    draco.set_session_id(id);
    const absl::StatusOr<std::string> encoded =
        EncodePointCloud(PointRange(sphere, 10000, 15000), DracoOptions{});
    ASSERT_TRUE(encoded.ok()) << encoded.status();
    draco.mutable_batch()->set_draco_point_cloud(*encoded);
    const grpc::Status draco_status = testing::UploadOne(*service_, draco, &response);
    ASSERT_TRUE(draco_status.ok()) << draco_status.error_message();
    ASSERT_TRUE(
        testing::Upload(*service_, id, PointRange(sphere, 15000, 20000), 2, &response).ok());

    v1::UploadPointsRequest bad;
    bad.set_session_id(id);
    *bad.mutable_batch() = Batch(PointRange(sphere, 0, 2));
    bad.mutable_batch()->mutable_packed()->set_colors("\x01\x02\x03\x04\x05");
    const grpc::Status refused = testing::UploadOne(*service_, bad, &response);
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(refused.error_message(),
                HasSubstr("PackedPoints.colors has 5 bytes; 2 points need 6 (3 per point"));

    ASSERT_TRUE(testing::Finish(*service_, id).ok());
    std::vector<v1::MeshUpdate> updates;
    ASSERT_TRUE(testing::WatchAll(*service_, id, &updates).ok());
    ASSERT_FALSE(updates.empty());
    int milestones = 0;
    for (const v1::MeshUpdate& update : updates) {
      if (update.kind() == v1::UPDATE_KIND_REFRESH) continue;
      ++milestones;
      const int worst = WorstColorError(update);
      EXPECT_GE(worst, 0) << "mesh " << update.sequence() << " has no colours";
      EXPECT_TRUE(update.report().colored()) << "mesh " << update.sequence();
      // The final mesh is painted from all 20,000 points (8 nearest within about 0.04, 5
      // levels; 3-4 measured); a milestone from those that had come (3-5 measured from
      // 10,000, up to 16 levels from 2,000).
      EXPECT_LE(worst, update.kind() == v1::UPDATE_KIND_FINAL ? 6 : 16)
          << "mesh " << update.sequence();
    }
    EXPECT_GE(milestones, 1);
  }

  const std::string plain = MustCreate(*service_, CreateRequest(300));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*service_, plain, testing::SpherePoints(5000, 3), 2, &response).ok());
  ASSERT_TRUE(testing::Finish(*service_, plain).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(testing::WaitFinal(*service_, plain, &final_mesh).ok());
  EXPECT_EQ(WorstColorError(final_mesh), -1) << "colours without coloured points";
  EXPECT_FALSE(final_mesh.report().colored());
}

// SessionConfig.color_neighbours: with 1 every vertex takes the colour of one point exactly;
// with the default 8 colours blend, so that points coloured at random give vertices of colours
// no point has. Values outside [1, 64] are refused.
TEST_F(ReconstructionServiceTest, ColourNeighboursSetHowMeshesArePainted) {
  PointCloud sphere = testing::SpherePoints(6000, 31);
  Random random(5);
  for (size_t i = 0; i < sphere.size(); ++i) {
    sphere.colors.push_back({static_cast<uint8_t>(random.NextIndex(256)),
                             static_cast<uint8_t>(random.NextIndex(256)),
                             static_cast<uint8_t>(random.NextIndex(256))});
  }
  const std::set<Rgb> point_colors(sphere.colors.begin(), sphere.colors.end());
  for (const uint32_t neighbours : {1u, 8u}) {
    SCOPED_TRACE(neighbours);
    v1::CreateSessionRequest create = CreateRequest(500);
    create.mutable_config()->mutable_color_neighbours()->set_value(neighbours);
    const std::string id = MustCreate(*service_, create);
    v1::UploadPointsResponse response;
    ASSERT_TRUE(testing::Upload(*service_, id, sphere, 3, &response).ok());
    ASSERT_TRUE(testing::Finish(*service_, id).ok());
    v1::MeshUpdate final_mesh;
    ASSERT_TRUE(testing::WaitFinal(*service_, id, &final_mesh).ok());
    EXPECT_TRUE(final_mesh.report().colored());
    const absl::StatusOr<TriangleMesh> mesh = DecodeMesh(final_mesh.draco_mesh());
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    ASSERT_EQ(mesh->colors.size(), mesh->positions.size());
    size_t found = 0;
    for (const Rgb& color : mesh->colors) found += point_colors.count(color);
    if (neighbours == 1) {
      EXPECT_EQ(found, mesh->colors.size()) << "vertices of colours no point has";
    } else {
      EXPECT_LT(found, mesh->colors.size() / 10) << "vertices took single points' colours";
    }
  }
  for (const uint32_t bad : {0u, 65u, 4000000000u}) {
    v1::CreateSessionRequest create = CreateRequest(500);
    create.mutable_config()->mutable_color_neighbours()->set_value(bad);
    v1::Session session;
    grpc::ClientContext context;
    const grpc::Status status = service_->CreateSession(&context, create, &session);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << bad;
    EXPECT_THAT(status.error_message(), HasSubstr("color_neighbours: colour neighbours = "))
        << bad;
  }
}

// SessionConfig.origin: georeferenced points uploaded relative to an origin give meshes whose
// Draco data carry it, so that watchers write the data's own coordinates; GetSession echoes
// it. A non-finite origin is refused.
TEST_F(ReconstructionServiceTest, TheSessionOriginTravelsWithEveryMesh) {
  v1::CreateSessionRequest create = CreateRequest(200);
  create.mutable_config()->mutable_origin()->set_x(500000);
  create.mutable_config()->mutable_origin()->set_y(4100000);
  const std::string id = MustCreate(*service_, create);
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*service_, id, testing::SpherePoints(2000, 3), 2, &response).ok());
  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(testing::WaitFinal(*service_, id, &final_mesh).ok());
  const absl::StatusOr<TriangleMesh> mesh = DecodeMesh(final_mesh.draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->origin, (std::array<double, 3>{500000, 4100000, 0}));
  for (const Vec3f& p : mesh->positions) ASSERT_LT(p.norm(), 1.5f) << "positions stay local";
  v1::Session session = testing::GetSession(*service_, id);
  EXPECT_EQ(session.config().origin().y(), 4100000);

  create.mutable_config()->mutable_origin()->set_z(NAN);
  grpc::ClientContext refused_context;
  const grpc::Status refused = service_->CreateSession(&refused_context, create, &session);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("origin.z is nan; it must be finite"));
}

// A sphere scanned region by region (its points sorted along x, batches of 500): the points on
// each batch's leading edge are held back, and accepted once the next batch brings their other
// side. Fewer points are lost for good than the whole-cloud filter drops (16 against 52);
// judged on arrival only, every point held back was lost (492).
TEST_F(ReconstructionServiceTest, OutlierRemovalAcceptsTheLeadingEdgesOfASweptScanLater) {
  PointCloud sphere = testing::SpherePoints(20000, 25);
  std::sort(sphere.positions.begin(), sphere.positions.end(),
            [](const Vec3f& a, const Vec3f& b) { return a[0] < b[0]; });
  const auto whole = FindStatisticalOutliers(sphere, OutlierOptions{});
  ASSERT_TRUE(whole.ok()) << whole.status();
  const auto whole_count = static_cast<uint64_t>(std::count(whole->begin(), whole->end(), true));
  v1::CreateSessionRequest create = CreateRequest(2000);
  create.mutable_config()->mutable_outlier_removal();
  const std::string id = MustCreate(*service_, create);
  grpc::ClientContext context;
  v1::UploadPointsResponse response;
  auto writer = service_->UploadPoints(&context, &response);
  for (size_t begin = 0; begin < sphere.size(); begin += 500) {
    v1::UploadPointsRequest request;
    request.set_session_id(id);
    *request.mutable_batch() = Batch(sphere, begin, begin + 500);
    ASSERT_TRUE(writer->Write(request));
  }
  writer->WritesDone();
  const grpc::Status status = writer->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_GE(response.points_held_back(), 4 * whole_count);
  const v1::LearningState learning = testing::GetSession(*service_, id).learning();
  EXPECT_GE(learning.outliers_accepted_later(), response.points_held_back() - whole_count);
  EXPECT_EQ(learning.points_received(),
            response.points_accepted() + learning.outliers_accepted_later());
  EXPECT_EQ(response.total_points(), learning.points_received());
  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  const v1::LearningState finished = testing::GetSession(*service_, id).learning();
  EXPECT_EQ(finished.outliers_held(), 0u);
  EXPECT_LE(finished.points_removed_as_outliers(), whole_count);
  EXPECT_EQ(finished.points_received() + finished.points_removed_as_outliers(), 20000u);
  ASSERT_TRUE(testing::Delete(*service_, id).ok());
}

// A Reconstruct call's acknowledgements count the points outlier removal held back.
TEST_F(ReconstructionServiceTest, ReconstructAcksCountHeldBackOutliers) {
  PointCloud points = testing::SpherePoints(3000, 24);
  points.positions.emplace_back(0.f, 30.f, 0.f);
  grpc::ClientContext context;
  auto stream = service_->Reconstruct(&context);
  v1::ReconstructRequest start;
  *start.mutable_start()->mutable_create() = CreateRequest(500);
  start.mutable_start()->mutable_create()->mutable_config()->mutable_outlier_removal();
  ASSERT_TRUE(stream->Write(start));
  v1::ReconstructRequest request;
  *request.mutable_points() = Batch(points, 0, points.size());
  ASSERT_TRUE(stream->Write(request));
  stream->WritesDone();
  v1::ReconstructResponse response;
  v1::PointsAck ack;
  while (stream->Read(&response)) {
    if (response.has_ack()) ack = response.ack();
  }
  const grpc::Status status = stream->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(ack.batches_accepted(), 1u);
  EXPECT_GE(ack.points_held_back(), 1u);
  EXPECT_LE(ack.points_held_back(), 1u + 15u);
  EXPECT_EQ(ack.points_accepted() + ack.points_held_back(), 3001u);
  EXPECT_EQ(ack.total_points(), ack.points_accepted()) << "one batch: nothing accepted later";
}

TEST_F(ReconstructionServiceTest, ReconstructRejectsABadBatchAndTheSessionStays) {
  const PointCloud points = TorusPoints(2000, 15);
  grpc::ClientContext context;
  auto stream = StartReconstruct(context, 100, Batch(points, 0, 1000));
  v1::ReconstructRequest good;
  *good.mutable_points() = Batch(points, 0, 1000);
  v1::ReconstructRequest bad = good;
  bad.mutable_points()->mutable_packed()->mutable_positions()->resize(13);
  stream->Write(bad);
  stream->WritesDone();
  std::string id;
  v1::ReconstructResponse response;
  while (stream->Read(&response)) {
    if (response.has_session()) id = response.session().session_id();
  }
  grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("batch 2 of this call rejected"));
  ASSERT_FALSE(id.empty());
  v1::Session session = testing::GetSession(*service_, id);
  EXPECT_EQ(session.learning().points_received(), 1000u) << "the good batch stays";
  EXPECT_NE(session.state(), v1::SESSION_STATE_FINISHING) << "an error does not finish it";

  // The first request must be a start.
  grpc::ClientContext context2;
  auto stream2 = service_->Reconstruct(&context2);
  stream2->Write(good);
  stream2->WritesDone();
  while (stream2->Read(&response)) {
  }
  EXPECT_EQ(stream2->Finish().error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

// A client that cancels (or loses its connection) ends the call, not the session: the points
// it sent stay, and the session is not finished on its behalf, so the upload can be resumed.
TEST_F(ReconstructionServiceTest, ACancelledReconstructLeavesTheSessionOpen) {
  const PointCloud points = TorusPoints(2000, 16);
  for (int attempt = 0; attempt < 5; ++attempt) {
    grpc::ClientContext context;
    auto stream = StartReconstruct(context, 1000, Batch(points, 0, 1000));
    std::string id;
    uint64_t acknowledged = 0;
    v1::ReconstructResponse response;
    while (acknowledged < 1000 && stream->Read(&response)) {
      if (response.has_session()) id = response.session().session_id();
      if (response.has_ack()) acknowledged = response.ack().points_accepted();
    }
    ASSERT_EQ(acknowledged, 1000u);
    context.TryCancel();
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::CANCELLED);
    // Once the server has seen the cancel, the call no longer watches the session.
    v1::Session session = testing::GetSession(*service_, id);
    for (int i = 0; i < 500 && session.watchers() > 0; ++i) {
      absl::SleepFor(absl::Milliseconds(10));
      session = testing::GetSession(*service_, id);
    }
    ASSERT_EQ(session.watchers(), 0u) << "the server did not end the cancelled call";
    EXPECT_EQ(session.learning().points_received(), 1000u);
    EXPECT_TRUE(session.state() == v1::SESSION_STATE_COLLECTING ||
                session.state() == v1::SESSION_STATE_LEARNING)
        << "attempt " << attempt
        << ": the cancel finished the session: " << v1::SessionState_Name(session.state());
  }
}

TEST_F(ReconstructionServiceTest, GetMeshLatestFinalAndWaiting) {
  const std::string id = MustCreate(*service_, CreateRequest(200));
  grpc::ClientContext context;
  v1::GetMeshRequest request;
  request.set_session_id(id);
  v1::MeshUpdate mesh;
  grpc::Status status = service_->GetMesh(&context, request, &mesh);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("no mesh yet"));

  // A waiting call for the final mesh returns once the session finishes.
  v1::MeshUpdate final_mesh;
  grpc::Status final_status;
  std::thread waiter([&] { final_status = testing::WaitFinal(*service_, id, &final_mesh); });
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*service_, id, TorusPoints(2000, 16), 4, &response).ok());
  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  waiter.join();
  ASSERT_TRUE(final_status.ok()) << final_status.error_message();
  EXPECT_EQ(final_mesh.kind(), v1::UPDATE_KIND_FINAL);

  grpc::ClientContext latest_context;
  ASSERT_TRUE(service_->GetMesh(&latest_context, request, &mesh).ok());
  EXPECT_EQ(mesh.sequence(), final_mesh.sequence()) << "after finishing, latest is final";

  // Waiting for a final mesh that cannot come.
  const std::string other = MustCreate(*service_, CreateRequest(200));
  grpc::Status cancelled_status;
  std::thread waiter2([&] {
    v1::MeshUpdate unused;
    cancelled_status = testing::WaitFinal(*service_, other, &unused);
  });
  absl::SleepFor(absl::Milliseconds(100));
  ASSERT_TRUE(testing::Cancel(*service_, other).ok());
  waiter2.join();
  EXPECT_EQ(cancelled_status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);

  // A deadline ends the wait.
  const std::string third = MustCreate(*service_, CreateRequest(200));
  v1::MeshUpdate unused;
  status = testing::WaitFinal(*service_, third, &unused, absl::Milliseconds(200));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
}

TEST_F(ReconstructionServiceTest, CancelAndDeleteEndWatchers) {
  const std::string id = MustCreate(*service_, CreateRequest(100000));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*service_, id, TorusPoints(20000, 17), 4, &response).ok());
  std::vector<v1::MeshUpdate> updates;
  grpc::Status watch_status;
  std::thread watcher([&] { watch_status = testing::WatchAll(*service_, id, &updates); });
  absl::SleepFor(absl::Milliseconds(200));
  ASSERT_TRUE(testing::Cancel(*service_, id).ok());
  watcher.join();
  EXPECT_EQ(watch_status.error_code(), grpc::StatusCode::CANCELLED)
      << watch_status.error_message();
  EXPECT_TRUE(testing::Cancel(*service_, id).ok()) << "cancel is idempotent";

  const std::string id2 = MustCreate(*service_, CreateRequest(100000));
  ASSERT_TRUE(testing::Upload(*service_, id2, TorusPoints(20000, 18), 4, &response).ok());
  std::thread watcher2([&] { watch_status = testing::WatchAll(*service_, id2, &updates); });
  absl::SleepFor(absl::Milliseconds(200));
  ASSERT_TRUE(testing::Delete(*service_, id2).ok());
  watcher2.join();
  EXPECT_EQ(watch_status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(watch_status.error_message(), HasSubstr("deleted"));
}

// An upload left open must not outlive its session: deleting the session once left the call
// open, holding the deleted session's points, until the client sent its next batch. Deletion,
// cancellation and another call's finish now end it at once, with what it had added.
TEST_F(ReconstructionServiceTest, AnOpenUploadEndsWhenItsSessionEnds) {
  const PointCloud points = TorusPoints(2000, 19);
  enum class End { kDelete, kCancel, kFinish };
  for (const End end : {End::kDelete, End::kCancel, End::kFinish}) {
    const std::string id = MustCreate(*service_, CreateRequest(200));
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
    v1::UploadPointsResponse response;
    auto writer = service_->UploadPoints(&context, &response);
    ASSERT_TRUE(writer->Write(Request(id, Batch(points, 0, 1000))));
    while (testing::GetSession(*service_, id).learning().points_received() < 1000) {
      absl::SleepFor(absl::Milliseconds(5));
    }
    const grpc::Status ended = end == End::kDelete   ? testing::Delete(*service_, id)
                               : end == End::kCancel ? testing::Cancel(*service_, id)
                                                     : testing::Finish(*service_, id);
    ASSERT_TRUE(ended.ok()) << ended.error_message();
    // No WritesDone: the server ends the call by itself.
    const grpc::Status status = writer->Finish();
    const grpc::StatusCode expected =
        end == End::kDelete ? grpc::StatusCode::NOT_FOUND : grpc::StatusCode::FAILED_PRECONDITION;
    EXPECT_EQ(status.error_code(), expected) << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr("accepts no more points"));
    EXPECT_THAT(status.error_message(), HasSubstr("this call had added 1000 points in 1 batch"));
  }
}

// Ids are echoed in status messages; a bogus one of any length must still get NOT_FOUND, not
// a message too large for the client's metadata limit (RESOURCE_EXHAUSTED from 9 KB on).
TEST_F(ReconstructionServiceTest, AnUnknownIdOfAnyLengthIsNotFoundWithAShortMessage) {
  const std::string id(10000, 'x');
  grpc::ClientContext context;
  v1::GetSessionRequest request;
  request.set_session_id(id);
  v1::Session session;
  const grpc::Status status = service_->GetSession(&context, request, &session);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("(10000 bytes)"));
  EXPECT_LT(status.error_message().size(), 200u);
}

// Sessions without an open stream or a call for --idle_timeout are deleted: an idle one goes, a
// watched one stays while its watcher is connected, and GetSession, a call, keeps one alive.
TEST(ReconstructionServiceIdleTimeoutTest, IdleSessionsAreDeletedWatchedOnesStay) {
  ServerOptions options;
  options.limits.idle_timeout = absl::Seconds(1);  // The reaper looks every 250 ms.
  std::unique_ptr<ReconstructionServer> server = StartServer(/*listen=*/false, options);
  ASSERT_NE(server, nullptr);
  // The generated client class of the service (gRPC calls it a service), over an in-process channel.
  auto client = InProcessService(*server);
  // ListSessions is no call on a session: it keeps none alive.
  auto listed = [&] {
    grpc::ClientContext context;
    v1::ListSessionsResponse list;
    EXPECT_TRUE(client->ListSessions(&context, v1::ListSessionsRequest(), &list).ok());
    std::vector<std::string> ids;
    for (const v1::Session& session : list.sessions()) ids.push_back(session.session_id());
    return ids;
  };
  auto wait_until_listed_only = [&](const std::vector<std::string>& ids) {
    const absl::Time give_up = absl::Now() + absl::Seconds(20);
    while (listed() != ids && absl::Now() < give_up) absl::SleepFor(absl::Milliseconds(20));
    return listed();
  };

  const std::string idle = MustCreate(*client, CreateRequest(1000));
  const std::string watched = MustCreate(*client, CreateRequest(1000));
  const std::string polled = MustCreate(*client, CreateRequest(1000));
  grpc::ClientContext watch_context;
  v1::WatchSessionRequest watch_request;
  watch_request.set_session_id(watched);
  auto watcher = client->WatchSession(&watch_context, watch_request);

  // `polled` gets a GetSession every 50 ms for at least 2 s (2 timeouts) and until `idle` is
  // gone.
  const absl::Time polled_from = absl::Now();
  const absl::Time give_up = polled_from + absl::Seconds(20);
  while (absl::Now() < polled_from + absl::Seconds(2) ||
         (::testing::Value(listed(), ::testing::Contains(idle)) && absl::Now() < give_up)) {
    grpc::Status status;
    testing::GetSession(*client, polled, &status);
    ASSERT_TRUE(status.ok()) << "polled every 50 ms, so never idle: " << status.error_message();
    absl::SleepFor(absl::Milliseconds(50));
  }
  EXPECT_THAT(listed(), ::testing::UnorderedElementsAre(watched, polled));
  grpc::Status status;
  testing::GetSession(*client, idle, &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND) << status.error_message();

  EXPECT_THAT(wait_until_listed_only({watched}), ::testing::ElementsAre(watched));
  absl::SleepFor(absl::Seconds(2));
  EXPECT_THAT(listed(), ::testing::ElementsAre(watched)) << "its watcher is still connected";
  watch_context.TryCancel();
  EXPECT_EQ(watcher->Finish().error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_THAT(wait_until_listed_only({}), ::testing::IsEmpty()) << "the watcher has left";
  server->Shutdown(absl::Seconds(2));
}

TEST_F(ReconstructionServiceTest, ShutdownEndsEveryOpenStream) {
  const std::string id = MustCreate(*service_, CreateRequest(100000));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::Upload(*service_, id, TorusPoints(20000, 19), 5, &response).ok());

  grpc::Status watch_status, upload_status, bidi_status, wait_status;
  std::vector<v1::MeshUpdate> updates;
  std::thread watcher([&] { watch_status = testing::WatchAll(*service_, id, &updates); });
  std::thread uploader([&] {  // An upload that never half-closes.
    grpc::ClientContext context;
    v1::UploadPointsResponse r;
    auto writer = service_->UploadPoints(&context, &r);
    v1::UploadPointsRequest request;
    request.set_session_id(id);
    *request.mutable_batch() = Batch(TorusPoints(100, 20), 0, 100);
    writer->Write(request);
    upload_status = writer->Finish();
  });
  std::thread bidi([&] {  // A Reconstruct call that never half-closes.
    grpc::ClientContext context;
    auto stream = service_->Reconstruct(&context);
    v1::ReconstructRequest start;
    *start.mutable_start()->mutable_create() = CreateRequest(100000);
    stream->Write(start);
    v1::ReconstructResponse r;
    while (stream->Read(&r)) {
    }
    bidi_status = stream->Finish();
  });
  std::thread waiter([&] {
    v1::MeshUpdate unused;
    wait_status = testing::WaitFinal(*service_, id, &unused);
  });
  absl::SleepFor(absl::Milliseconds(300));
  const absl::Time start = absl::Now();
  server_->Shutdown(absl::Seconds(10));
  watcher.join();
  uploader.join();
  bidi.join();
  waiter.join();
  EXPECT_LT(absl::Now() - start, absl::Seconds(5)) << "shutdown must not wait for clients";
  EXPECT_EQ(watch_status.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(upload_status.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(bidi_status.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(wait_status.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(server_->reactors().size(), 0u) << "every reactor is gone";
}

}  // namespace
}  // namespace neuralmesh::server
