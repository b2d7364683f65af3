// neuralmesh-server --state_dir (server/session_store.h): sessions outlive a restart of the
// server. Each test runs a server on a state directory, stops it, starts another on the same
// directory and checks what a client sees there: the same sessions, points, states and meshes,
// uploads and watches that go on, and what happens with damaged or full storage.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/draco_codec.h"
#include "core/sampling/implicit_surfaces.h"
#include "neuralmesh/storage/v1/learner_checkpoint.pb.h"
#include "server/server.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/file_size_limit.h"
#include "tests/testing/shapes.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::server {
namespace {

using ::neuralmesh::server::testing::Batch;
using ::neuralmesh::server::testing::CreateRequest;
using ::neuralmesh::server::testing::GetSession;
using ::neuralmesh::server::testing::MustCreate;
using ::neuralmesh::server::testing::SpherePoints;
using ::neuralmesh::server::testing::TorusPoints;
using ::neuralmesh::server::testing::Upload;
using ::neuralmesh::server::testing::WaitFinal;
using Service = v1::ReconstructionService::Stub;

// Uploads points [begin, end) of `cloud` in `batches` batches that carry their place in the
// upload (PointBatch.first_point).
grpc::Status UploadFrom(Service& service, const std::string& id, const PointCloud& cloud,
                        size_t begin, size_t end, size_t batches,
                        v1::UploadPointsResponse* response) {
  grpc::ClientContext context;
  auto writer = service.UploadPoints(&context, response);
  for (size_t b = 0; b < batches; ++b) {
    const size_t first = begin + (end - begin) * b / batches;
    v1::UploadPointsRequest request;
    request.set_session_id(id);
    *request.mutable_batch() = Batch(cloud, first, begin + (end - begin) * (b + 1) / batches);
    request.mutable_batch()->mutable_first_point()->set_value(first);
    if (!writer->Write(request)) break;
  }
  writer->WritesDone();
  return writer->Finish();
}

grpc::Status GetLatest(Service& service, const std::string& id, v1::MeshUpdate* update) {
  grpc::ClientContext context;
  context.set_deadline(absl::ToChronoTime(absl::Now() + absl::Seconds(30)));
  v1::GetMeshRequest request;
  request.set_session_id(id);
  request.set_wait(true);
  return service.GetMesh(&context, request, update);
}

grpc::Status WatchAfter(Service& service, const std::string& id, uint64_t after_sequence,
                        std::vector<v1::MeshUpdate>* updates) {
  grpc::ClientContext context;
  context.set_deadline(absl::ToChronoTime(absl::Now() + absl::Seconds(60)));
  v1::WatchSessionRequest request;
  request.set_session_id(id);
  request.set_after_sequence(after_sequence);
  auto reader = service.WatchSession(&context, request);
  v1::MeshUpdate update;
  while (reader->Read(&update)) updates->push_back(update);
  return reader->Finish();
}

class SessionRestoreTest : public ::testing::Test {
 protected:
  void SetUp() override { state_dir_ = neuralmesh::testing::MakeTempDir("state"); }

  // Starts a server on the state directory (stopping the one before), with `options`' limits.
  void Restart(ServerOptions options = {}) {
    service_.reset();
    server_.reset();
    options.address = "";
    options.state_dir = state_dir_;
    options.state_sync = false;  // The tests stop servers, not machines.
    options.event_sink = events_.Sink();
    absl::StatusOr<std::unique_ptr<ReconstructionServer>> server =
        ReconstructionServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = *std::move(server);
    // Calls on a session get UNAVAILABLE until it is restored (SessionManager::StartRestore,
    // SessionManagerRestoreTest): these tests look at what comes after.
    server_->WaitForRestore();
    service_ = testing::InProcessService(*server_);
  }

  std::string SessionDirectory(const std::string& id) const {
    return absl::StrCat(state_dir_, "/sessions/", id);
  }

  std::string state_dir_;
  testing::CapturedEvents events_;
  std::unique_ptr<ReconstructionServer> server_;
  std::unique_ptr<Service> service_;
};

TEST_F(SessionRestoreTest, AnUploadGoesOnWhereItWasAndEndsOnTheSphere) {
  Restart();
  const PointCloud cloud = SpherePoints(40000, 11);
  const std::string id = MustCreate(*service_, CreateRequest(2000, /*refresh_ms=*/20));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(UploadFrom(*service_, id, cloud, 0, 15000, 3, &response).ok());
  v1::MeshUpdate mesh;
  ASSERT_TRUE(GetLatest(*service_, id, &mesh).ok());
  // Let learning go on a little, so that the stored mesh is a later one.
  absl::SleepFor(absl::Milliseconds(200));
  const v1::Session before = GetSession(*service_, id);
  ASSERT_GT(before.latest_sequence(), 0u);

  Restart();
  const RestoreReport restored = server_->WaitForRestore();
  EXPECT_EQ(restored.sessions, 1u);
  EXPECT_EQ(restored.points, 15000u);
  EXPECT_TRUE(restored.problems.empty());
  EXPECT_FALSE(events_.Await("restored after a restart: 15000 points in 3 batches").empty());
  grpc::Status status;
  const v1::Session after = GetSession(*service_, id, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(after.name(), before.name());
  EXPECT_EQ(after.create_time_us(), before.create_time_us());
  EXPECT_EQ(after.config().SerializeAsString(), before.config().SerializeAsString());
  EXPECT_EQ(after.points_taken(), 15000u);
  EXPECT_EQ(after.learning().points_received(), 15000u);
  EXPECT_EQ(after.quantization_box().SerializeAsString(),
            before.quantization_box().SerializeAsString());
  // The stored mesh is the latest again, under its own sequence number (or, learning having
  // gone on since, a later one).
  EXPECT_GE(after.latest_sequence(), before.latest_sequence());
  v1::MeshUpdate restored_mesh;
  ASSERT_TRUE(GetLatest(*service_, id, &restored_mesh).ok());
  EXPECT_GE(restored_mesh.sequence(), before.latest_sequence());

  // A watch resumed after the restored mesh, and the rest of the upload resent from before
  // the points the session has (the overlap is skipped).
  std::vector<v1::MeshUpdate> watched;
  grpc::Status watch_status;
  std::thread watcher(
      [&] { watch_status = WatchAfter(*service_, id, restored_mesh.sequence(), &watched); });
  ASSERT_TRUE(UploadFrom(*service_, id, cloud, 10000, 40000, 6, &response).ok());
  EXPECT_EQ(response.total_points(), 40000u);
  EXPECT_EQ(response.points_accepted(), 25000u);  // Its first batch was there already.
  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(WaitFinal(*service_, id, &final_mesh).ok());
  watcher.join();
  ASSERT_TRUE(watch_status.ok()) << watch_status.error_message();
  ASSERT_FALSE(watched.empty());
  for (const v1::MeshUpdate& update : watched) {
    EXPECT_GT(update.sequence(), restored_mesh.sequence());
    // Nothing coarser than what the watchers had before the restart.
    EXPECT_GE(update.vertex_count(), restored_mesh.vertex_count());
  }
  EXPECT_EQ(watched.back().kind(), v1::UPDATE_KIND_FINAL);

  EXPECT_EQ(final_mesh.learning().points_received(), 40000u);
  EXPECT_EQ(final_mesh.vertex_count(), 2000u);
  EXPECT_EQ(final_mesh.report().genus(), 0);
  EXPECT_EQ(final_mesh.report().boundary_loops(), 0u);
  EXPECT_TRUE(final_mesh.report().manifold());
  absl::StatusOr<TriangleMesh> decoded = DecodeMesh(final_mesh.draco_mesh());
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  absl::StatusOr<std::unique_ptr<ImplicitSurface>> sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  ASSERT_TRUE(sphere.ok());
  EXPECT_LT(testing::MaxVertexDistance(*decoded, **sphere), 0.02);
}

// The learner checkpoint in `directory` once it holds a mesh of `vertices` vertices (the
// encoder writes it right after it publishes the milestone); fails the test after 30 s.
storage::v1::LearnerCheckpoint AwaitCheckpoint(const std::string& directory, size_t vertices) {
  storage::v1::LearnerCheckpoint checkpoint;
  const absl::Time deadline = absl::Now() + absl::Seconds(30);
  while (absl::Now() < deadline) {
    std::ifstream file(directory + "/checkpoint.binpb", std::ios::binary);
    if (file && checkpoint.ParseFromIstream(&file) &&
        checkpoint.mesh().positions().size() == vertices * 12) {
      return checkpoint;
    }
    absl::SleepFor(absl::Milliseconds(5));
  }
  ADD_FAILURE() << "no checkpoint of " << vertices << " vertices in " << directory;
  return checkpoint;
}

// A sphere session uploaded whole, learned past its 2,000-vertex milestone to its 4,000
// allowed vertices, restarted and finished. The 2,000-vertex mesh of the checkpoint is where
// learning goes on from: the counters go on from it, and the final mesh takes about 100 Basic
// Steps per vertex added since, where learning from the tetrahedron takes that per vertex of
// all 4,000.
// The points carry colours, which the journal keeps: the final mesh is painted with them.
TEST_F(SessionRestoreTest, LearningGoesOnFromTheLatestMilestonesMesh) {
  Restart();
  const PointCloud cloud = neuralmesh::testing::ColoredUnitSpherePoints(40000, 11);
  v1::CreateSessionRequest request = CreateRequest(4000, /*refresh_ms=*/20);
  request.mutable_config()->add_lod_milestones(1000);
  request.mutable_config()->add_lod_milestones(2000);
  const std::string id = MustCreate(*service_, request);
  v1::UploadPointsResponse response;
  ASSERT_TRUE(Upload(*service_, id, cloud, 4, &response).ok());
  const storage::v1::LearnerCheckpoint checkpoint = AwaitCheckpoint(SessionDirectory(id), 2000);
  const uint64_t steps_at_checkpoint = checkpoint.learning().basic_steps();
  ASSERT_GT(steps_at_checkpoint, 100000u);
  ASSERT_EQ(checkpoint.mesh().faces().size(), 3996u * 12) << "a closed mesh of 2,000 vertices";

  Restart();
  EXPECT_TRUE(server_->WaitForRestore().problems.empty());
  EXPECT_FALSE(events_.Await("learner checkpoint of 2000 vertices").empty());
  const v1::Session restored = GetSession(*service_, id);
  EXPECT_GE(restored.learning().basic_steps(), steps_at_checkpoint)
      << "the counters go on from the checkpoint's";
  EXPECT_GE(restored.learning().learning_seconds(), checkpoint.learning().learning_seconds());
  EXPECT_FALSE(events_.Await("learning goes on from the stored mesh of 2000 vertices").empty());

  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(WaitFinal(*service_, id, &final_mesh).ok());
  EXPECT_EQ(final_mesh.vertex_count(), 4000u);
  EXPECT_EQ(final_mesh.report().genus(), 0);
  EXPECT_EQ(final_mesh.report().boundary_loops(), 0u);
  EXPECT_TRUE(final_mesh.report().manifold());
  const uint64_t steps_since = final_mesh.learning().basic_steps() - steps_at_checkpoint;
  EXPECT_LT(steps_since, 300000u) << "from the 2,000-vertex mesh to 4,000 vertices";
  absl::StatusOr<TriangleMesh> decoded = DecodeMesh(final_mesh.draco_mesh());
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  absl::StatusOr<std::unique_ptr<ImplicitSurface>> sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  ASSERT_TRUE(sphere.ok());
  EXPECT_LT(testing::MaxVertexDistance(*decoded, **sphere), 0.02);
  const int worst = neuralmesh::testing::WorstColorErrorOnTheUnitSphere(*decoded);
  EXPECT_GE(worst, 0) << "the colours were lost";
  EXPECT_LE(worst, 6);
}

// A session with no milestone below its target, restarted while paused for lack of points:
// its first refresh was kept as the checkpoint, and learning goes on from it. With a
// checkpoint interval of zero there is none.
TEST_F(SessionRestoreTest, ARefreshIsTheCheckpointOfASessionWithoutMilestones) {
  for (const absl::Duration interval : {kDefaultCheckpointInterval, absl::ZeroDuration()}) {
    ServerOptions options;
    options.checkpoint_interval = interval;
    Restart(options);
    v1::CreateSessionRequest request = CreateRequest(5000, /*refresh_ms=*/20);
    request.mutable_config()->add_lod_milestones(5000);  // The target only.
    const std::string id = MustCreate(*service_, request);
    v1::UploadPointsResponse response;
    // 6,000 points allow 3,000 vertices: learning pauses there and publishes a refresh.
    ASSERT_TRUE(Upload(*service_, id, SpherePoints(6000, 14), 2, &response).ok());
    v1::MeshUpdate latest;
    ASSERT_TRUE(GetLatest(*service_, id, &latest).ok());
    EXPECT_EQ(latest.kind(), v1::UPDATE_KIND_REFRESH);
    EXPECT_EQ(latest.vertex_count(), 3000u);
    if (interval > absl::ZeroDuration()) {
      AwaitCheckpoint(SessionDirectory(id), 3000);
    } else {
      absl::SleepFor(absl::Milliseconds(100));  // Time for a checkpoint that should not come.
      EXPECT_FALSE(std::filesystem::exists(SessionDirectory(id) + "/checkpoint.binpb"));
    }
    Restart(options);
    if (interval > absl::ZeroDuration()) {
      EXPECT_FALSE(
          events_
              .Await(absl::StrCat("session ", id, " learning goes on from the stored mesh of 3000"))
              .empty());
    }
    ASSERT_TRUE(testing::Finish(*service_, id).ok());
    v1::MeshUpdate final_mesh;
    ASSERT_TRUE(WaitFinal(*service_, id, &final_mesh).ok());
    EXPECT_EQ(final_mesh.vertex_count(), 3000u);
    EXPECT_EQ(final_mesh.report().genus(), 0);
  }
}

// A checkpoint that cannot be read, and one whose mesh the learner cannot take (three faces
// on an edge): each session says so and learns again from the initial mesh to a good sphere.
TEST_F(SessionRestoreTest, ACheckpointThatCannotBeUsedMeansLearningFromTheInitialMesh) {
  Restart();
  const PointCloud cloud = SpherePoints(20000, 12);
  std::vector<std::string> ids;
  for (int i = 0; i < 2; ++i) {
    v1::CreateSessionRequest request = CreateRequest(2000);
    request.mutable_config()->add_lod_milestones(500);
    ids.push_back(MustCreate(*service_, request));
    v1::UploadPointsResponse response;
    ASSERT_TRUE(Upload(*service_, ids.back(), cloud, 2, &response).ok());
    AwaitCheckpoint(SessionDirectory(ids.back()), 500);
  }
  service_.reset();
  server_.reset();
  std::ofstream(SessionDirectory(ids[0]) + "/checkpoint.binpb", std::ios::binary) << "garbage";
  storage::v1::LearnerCheckpoint fin;
  fin.set_format_version(1);
  fin.set_session_id(ids[1]);
  const std::vector<Vec3f> positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0),
                                        Vec3f(1, 1, 1), Vec3f(1, 1, -1)};
  const std::vector<uint32_t> faces = {0, 1, 2, 1, 3, 2, 1, 2, 4};
  fin.mutable_mesh()->set_positions(
      std::string(reinterpret_cast<const char*>(positions.data()), 5 * 12));
  fin.mutable_mesh()->set_faces(std::string(reinterpret_cast<const char*>(faces.data()), 9 * 4));
  std::ofstream(SessionDirectory(ids[1]) + "/checkpoint.binpb", std::ios::binary)
      << fin.SerializeAsString();

  Restart();
  const std::vector<std::string> problems = server_->WaitForRestore().problems;
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_TRUE(absl::StrContains(problems[0],
                                absl::StrCat("session ", ids[0],
                                             ": its learner checkpoint "
                                             "cannot be used (it is not a learner checkpoint)")))
      << problems[0];
  EXPECT_FALSE(events_.Await("cannot learn on from the stored mesh (face 2").empty());
  for (const std::string& id : ids) {
    ASSERT_TRUE(testing::Finish(*service_, id).ok());
    v1::MeshUpdate final_mesh;
    ASSERT_TRUE(WaitFinal(*service_, id, &final_mesh).ok());
    EXPECT_EQ(final_mesh.vertex_count(), 2000u);
    EXPECT_EQ(final_mesh.report().genus(), 0) << id;
    EXPECT_EQ(final_mesh.report().boundary_loops(), 0u) << id;
    absl::StatusOr<TriangleMesh> decoded = DecodeMesh(final_mesh.draco_mesh());
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    absl::StatusOr<std::unique_ptr<ImplicitSurface>> sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
    ASSERT_TRUE(sphere.ok());
    EXPECT_LT(testing::MaxVertexDistance(*decoded, **sphere), 0.02) << id;
  }
}

// A session stopped while finishing, whose final pass relearns (SessionConfig.final_pass):
// the final mesh is learned again from the initial mesh, as it would have been without the
// restart, and the checkpoint is not used.
TEST_F(SessionRestoreTest, AFinalPassThatRelearnsLeavesTheCheckpointUnused) {
  Restart();
  v1::CreateSessionRequest request = CreateRequest(2000);
  request.mutable_config()->add_lod_milestones(500);
  request.mutable_config()->set_final_pass(v1::FINAL_PASS_RELEARN);
  const std::string id = MustCreate(*service_, request);
  v1::UploadPointsResponse response;
  ASSERT_TRUE(Upload(*service_, id, SpherePoints(20000, 13), 2, &response).ok());
  AwaitCheckpoint(SessionDirectory(id), 500);
  service_.reset();
  server_.reset();
  // As if the server had stopped right after taking the finish.
  const std::string state_path = SessionDirectory(id) + "/session.binpb";
  storage::v1::StoredSession stored;
  {
    std::ifstream file(state_path, std::ios::binary);
    ASSERT_TRUE(stored.ParseFromIstream(&file));
  }
  stored.set_state(v1::SESSION_STATE_FINISHING);
  std::ofstream(state_path, std::ios::binary | std::ios::trunc) << stored.SerializeAsString();

  Restart();
  EXPECT_FALSE(events_.Await("finishing, mesh").empty());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(WaitFinal(*service_, id, &final_mesh).ok());
  EXPECT_TRUE(final_mesh.learning().relearning());
  EXPECT_EQ(final_mesh.vertex_count(), 2000u);
  EXPECT_EQ(final_mesh.report().genus(), 0);
  EXPECT_FALSE(events_.Await("finished: 2000 vertices").empty());
  for (const std::string& line : events_.lines()) {
    EXPECT_FALSE(absl::StrContains(line, "learning goes on")) << line;
  }
  EXPECT_FALSE(std::filesystem::exists(SessionDirectory(id) + "/checkpoint.binpb"))
      << "a finished session keeps no checkpoint";
}

TEST_F(SessionRestoreTest, EndedSessionsComeBackAsTheyEndedAndDeletedOnesDoNot) {
  Restart();
  const PointCloud cloud = TorusPoints(20000, 3);
  const std::string finished = MustCreate(*service_, CreateRequest(1000));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(Upload(*service_, finished, cloud, 4, &response).ok());
  ASSERT_TRUE(testing::Finish(*service_, finished).ok());
  v1::MeshUpdate final_before;
  ASSERT_TRUE(WaitFinal(*service_, finished, &final_before).ok());
  const std::string cancelled = MustCreate(*service_, CreateRequest(1000));
  ASSERT_TRUE(Upload(*service_, cancelled, cloud, 2, &response).ok());
  ASSERT_TRUE(testing::Cancel(*service_, cancelled).ok());
  const std::string deleted = MustCreate(*service_, CreateRequest(1000));
  ASSERT_TRUE(testing::Delete(*service_, deleted).ok());
  EXPECT_FALSE(std::filesystem::exists(SessionDirectory(deleted)));

  Restart();
  EXPECT_EQ(server_->WaitForRestore().sessions, 2u);
  grpc::ClientContext context;
  v1::ListSessionsResponse list;
  ASSERT_TRUE(service_->ListSessions(&context, v1::ListSessionsRequest(), &list).ok());
  ASSERT_EQ(list.sessions_size(), 2);
  EXPECT_EQ(list.sessions(0).session_id(), finished);
  EXPECT_EQ(list.sessions(1).session_id(), cancelled);

  // The finished session: its final mesh, byte for byte, and nothing more to learn.
  const v1::Session done = list.sessions(0);
  EXPECT_EQ(done.state(), v1::SESSION_STATE_FINISHED);
  EXPECT_EQ(done.learning().basic_steps(), final_before.learning().basic_steps());
  EXPECT_EQ(done.learning().points_received(), 20000u);
  v1::MeshUpdate final_after;
  ASSERT_TRUE(WaitFinal(*service_, finished, &final_after).ok());
  EXPECT_EQ(final_after.SerializeAsString(), final_before.SerializeAsString());
  std::vector<v1::MeshUpdate> watched;
  EXPECT_TRUE(WatchAfter(*service_, finished, 0, &watched).ok());
  ASSERT_EQ(watched.size(), 1u);
  EXPECT_EQ(watched[0].sequence(), final_before.sequence());
  EXPECT_EQ(UploadFrom(*service_, finished, cloud, 20000, 20001, 1, &response).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);

  // The cancelled one: cancelled, with who cancelled it.
  EXPECT_EQ(list.sessions(1).state(), v1::SESSION_STATE_CANCELLED);
  EXPECT_EQ(list.sessions(1).error(), "cancelled by a CancelSession call");
  watched.clear();
  EXPECT_EQ(WatchAfter(*service_, cancelled, 0, &watched).error_code(),
            grpc::StatusCode::CANCELLED);
  EXPECT_EQ(testing::Finish(*service_, cancelled).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);

  grpc::Status status;
  GetSession(*service_, deleted, &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  // Deleting a restored session removes its files too.
  ASSERT_TRUE(testing::Delete(*service_, cancelled).ok());
  EXPECT_FALSE(std::filesystem::exists(SessionDirectory(cancelled)));
  Restart();
  EXPECT_EQ(server_->WaitForRestore().sessions, 1u);
}

TEST_F(SessionRestoreTest, OutlierVerdictsComeOutAsBefore) {
  Restart();
  PointCloud cloud = TorusPoints(12000, 5);
  // Strays far from the torus, spread over the batches.
  for (size_t i = 0; i < 60; ++i) {
    cloud.positions[i * 200 + 7] = Vec3f(3.0f + 0.01f * i, -2.5f, 2.0f + 0.02f * i);
  }
  v1::CreateSessionRequest request = CreateRequest(500);
  request.mutable_config()->mutable_outlier_removal();
  const std::string id = MustCreate(*service_, request);
  v1::UploadPointsResponse response;
  ASSERT_TRUE(Upload(*service_, id, cloud, 6, &response).ok());
  const v1::Session before = GetSession(*service_, id);
  EXPECT_GT(before.learning().points_removed_as_outliers() + before.learning().outliers_held(), 0u);

  Restart();
  const v1::Session after = GetSession(*service_, id);
  EXPECT_EQ(after.points_taken(), before.points_taken());
  EXPECT_EQ(after.learning().points_received(), before.learning().points_received());
  EXPECT_EQ(after.learning().points_removed_as_outliers(),
            before.learning().points_removed_as_outliers());
  EXPECT_EQ(after.learning().outliers_held(), before.learning().outliers_held());
  EXPECT_EQ(after.learning().outliers_accepted_later(),
            before.learning().outliers_accepted_later());
  EXPECT_EQ(after.quantization_box().SerializeAsString(),
            before.quantization_box().SerializeAsString());
}

TEST_F(SessionRestoreTest, PointsBeyondANewLimitFailTheSessionAndKeepItsFiles) {
  Restart();
  const PointCloud cloud = SpherePoints(10000, 7);
  const std::string id = MustCreate(*service_, CreateRequest(1000));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(Upload(*service_, id, cloud, 4, &response).ok());
  const uintmax_t journal_bytes =
      std::filesystem::file_size(SessionDirectory(id) + "/points.journal");

  ServerOptions smaller;
  smaller.limits.max_points_per_session = 6000;
  Restart(smaller);
  const v1::Session failed = GetSession(*service_, id);
  EXPECT_EQ(failed.state(), v1::SESSION_STATE_FAILED);
  EXPECT_TRUE(absl::StrContains(failed.error(), "restoring it after a restart failed at batch 3"))
      << failed.error();
  EXPECT_EQ(failed.learning().points_received(), 5000u);
  ASSERT_EQ(server_->WaitForRestore().problems.size(), 1u);
  EXPECT_EQ(std::filesystem::file_size(SessionDirectory(id) + "/points.journal"), journal_bytes);

  // With the old limit back, the session is whole again.
  Restart();
  const v1::Session whole = GetSession(*service_, id);
  EXPECT_NE(whole.state(), v1::SESSION_STATE_FAILED) << whole.error();
  EXPECT_EQ(whole.learning().points_received(), 10000u);
  EXPECT_TRUE(testing::Finish(*service_, id).ok());
}

TEST_F(SessionRestoreTest, ATornJournalTailIsCutOffAndTheUploadResumesBeforeIt) {
  Restart();
  const PointCloud cloud = SpherePoints(9000, 8);
  const std::string id = MustCreate(*service_, CreateRequest(1000));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(UploadFrom(*service_, id, cloud, 0, 6000, 2, &response).ok());
  service_.reset();
  server_.reset();
  // A crash in the middle of writing a third record.
  std::ofstream(SessionDirectory(id) + "/points.journal", std::ios::app | std::ios::binary)
      << std::string("NMPB\x10\x00", 6);

  Restart();
  const std::vector<std::string> problems = server_->WaitForRestore().problems;
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_TRUE(absl::StrContains(problems[0], "torn record header")) << problems[0];
  const v1::Session after = GetSession(*service_, id);
  EXPECT_EQ(after.points_taken(), 6000u);
  ASSERT_TRUE(UploadFrom(*service_, id, cloud, 6000, 9000, 1, &response).ok());

  Restart();
  EXPECT_TRUE(server_->WaitForRestore().problems.empty());
  EXPECT_EQ(GetSession(*service_, id).points_taken(), 9000u);
}

TEST_F(SessionRestoreTest, ABatchThatCannotBeStoredIsRefusedAndChangesNothing) {
  Restart();
  const PointCloud cloud = SpherePoints(20000, 9);
  const std::string id = MustCreate(*service_, CreateRequest(1000, /*refresh_ms=*/0));
  v1::UploadPointsResponse response;
  ASSERT_TRUE(UploadFrom(*service_, id, cloud, 0, 5000, 1, &response).ok());
  const uintmax_t journal_bytes =
      std::filesystem::file_size(SessionDirectory(id) + "/points.journal");

  // A file size limit that the next batch's record would pass (a full disk answers alike).
  grpc::Status refused;
  {
    neuralmesh::testing::ScopedFileSizeLimit limit(journal_bytes + 1000);
    refused = UploadFrom(*service_, id, cloud, 5000, 15000, 1, &response);
  }
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(absl::StrContains(refused.error_message(), "cannot store the batch"))
      << refused.error_message();
  EXPECT_EQ(GetSession(*service_, id).points_taken(), 5000u);
  EXPECT_EQ(std::filesystem::file_size(SessionDirectory(id) + "/points.journal"), journal_bytes);

  ASSERT_TRUE(UploadFrom(*service_, id, cloud, 5000, 15000, 1, &response).ok());
  Restart();
  EXPECT_EQ(GetSession(*service_, id).points_taken(), 15000u);
}

// A session paused for lack of growth while collecting (SessionTest.AStallWhileCollecting...)
// is restored paused: no Basic Step until more points come.
TEST_F(SessionRestoreTest, APausedSessionStaysPausedUntilMorePointsCome) {
  Restart();
  const std::string id = MustCreate(*service_, testing::StallingRequest());
  const PointCloud torus = TorusPoints(2500, 9);
  v1::UploadPointsResponse response;
  ASSERT_TRUE(UploadFrom(*service_, id, torus, 0, 2000, 1, &response).ok());
  const auto learning = [&] { return GetSession(*service_, id).learning(); };
  for (int i = 0; i < 500 && !learning().stalled(); ++i) absl::SleepFor(absl::Milliseconds(20));
  ASSERT_TRUE(learning().stalled()) << "the learner did not stall";

  Restart();
  EXPECT_TRUE(learning().stalled()) << "restored learning, not paused";
  const uint64_t steps = learning().basic_steps();
  absl::SleepFor(absl::Milliseconds(500));
  EXPECT_EQ(learning().basic_steps(), steps) << "a paused session learns after a restart";
  EXPECT_NE(events_.Await("paused for lack of growth until more than 2000 points come"), "");

  ASSERT_TRUE(UploadFrom(*service_, id, torus, 2000, 2500, 1, &response).ok());
  for (int i = 0; i < 500 && learning().basic_steps() == steps; ++i) {
    absl::SleepFor(absl::Milliseconds(20));
  }
  EXPECT_GT(learning().basic_steps(), steps) << "new points did not wake the learner";
}

TEST_F(SessionRestoreTest, ARestoredSessionsIdleTimeStartsAtTheRestart) {
  ServerOptions options;
  options.limits.idle_timeout = absl::Milliseconds(400);
  Restart(options);
  const std::string id = MustCreate(*service_, CreateRequest(1000));
  absl::SleepFor(absl::Milliseconds(250));
  Restart(options);
  absl::SleepFor(absl::Milliseconds(250));
  // 500 ms after its creation, 250 ms after the restart: not idle yet.
  grpc::Status status;
  GetSession(*service_, id, &status);
  EXPECT_TRUE(status.ok()) << status.error_message();
  // And the reaper still deletes it, files too, once it is idle.
  absl::SleepFor(absl::Milliseconds(700));
  GetSession(*service_, id, &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_FALSE(std::filesystem::exists(SessionDirectory(id)));
}

TEST_F(SessionRestoreTest, OneServerAtATimeUsesAStateDirectory) {
  Restart();
  ServerOptions options;
  options.address = "";
  options.state_dir = state_dir_;
  absl::StatusOr<std::unique_ptr<ReconstructionServer>> second =
      ReconstructionServer::Start(options);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(absl::StrContains(second.status().message(), "in use by another")) << second.status();
}

}  // namespace
}  // namespace neuralmesh::server
