// CreateSessionRequest.start_mesh: a session that learns on from a given mesh instead of the
// initial one. What a client sees: the start mesh published first, no milestone it has passed,
// learning that waits for points enough for it, a final mesh on the surface, and a clear
// INVALID_ARGUMENT or FAILED_PRECONDITION for what cannot work.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/match.h"
#include "core/io/draco_codec.h"
#include "core/learning/learner.h"
#include "core/sampling/implicit_surfaces.h"
#include "server/proto_conversion.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::server {
namespace {

using testing::CreateRequest;
using testing::MustCreate;
using testing::SpherePoints;
using testing::Upload;
using testing::WaitFinal;
using testing::WatchAll;
// gRPC's generated client class of the service.
using Service = v1::ReconstructionService::Stub;

// A unit sphere learned to `vertices` vertices by a local learner.
TriangleMesh LearnedSphere(size_t vertices) {
  std::unique_ptr<ImplicitSurface> sphere = MakeSphere(Vec3(0, 0, 0), 1.0).value();
  std::unique_ptr<Learner> learner = Learner::Create(LearnerOptions{}, sphere.get()).value();
  StopCriteria stop;
  stop.target_vertices = vertices;
  EXPECT_TRUE(learner->Run(stop).ok());
  return learner->Snapshot();
}

v1::CreateSessionRequest RequestFrom(const TriangleMesh& start, uint64_t target) {
  v1::CreateSessionRequest request = CreateRequest(target);
  request.mutable_config()->add_lod_milestones(200);
  request.mutable_config()->add_lod_milestones(1000);
  *request.mutable_start_mesh()->mutable_packed() = PackMesh(start);
  return request;
}

double MaxDistanceToUnitSphere(const v1::MeshUpdate& update) {
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(update.draco_mesh());
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  if (!mesh.ok()) return 1e9;
  std::unique_ptr<ImplicitSurface> sphere = MakeSphere(Vec3(0, 0, 0), 1.0).value();
  return testing::MaxVertexDistance(*mesh, *sphere);
}

class StartMeshTest : public ::testing::Test {
 protected:
  void SetUp() override {
    server_ = testing::StartServer(/*listen=*/false);
    ASSERT_NE(server_, nullptr);
    service_ = testing::InProcessService(*server_);
  }
  void TearDown() override { server_->Shutdown(absl::Seconds(2)); }

  std::unique_ptr<ReconstructionServer> server_;
  std::unique_ptr<Service> service_;
};

// A 500-vertex sphere refined to 2,000 vertices: learning waits until the points allow 500
// vertices, the first mesh published is the start mesh, the 200-vertex milestone is skipped,
// and the final mesh lies on the sphere after about 100 Basic Steps per vertex added (from the
// tetrahedron, per vertex of all 2,000).
TEST_F(StartMeshTest, LearningStartsFromTheStartMeshOnceThePointsAllowIt) {
  const TriangleMesh start = LearnedSphere(500);
  const std::string id = MustCreate(*service_, RequestFrom(start, 2000));
  std::vector<v1::MeshUpdate> watched;
  grpc::Status watch_status;
  std::thread watcher([&] { watch_status = WatchAll(*service_, id, &watched); });

  // 600 points allow 300 vertices: too few for the start mesh.
  const PointCloud points = SpherePoints(20000, 5);
  v1::UploadPointsResponse response;
  ASSERT_TRUE(testing::UploadOne(*service_, [&] {
                v1::UploadPointsRequest request;
                request.set_session_id(id);
                *request.mutable_batch() = testing::Batch(points, 0, 600);
                return request;
              }(), &response).ok());
  absl::SleepFor(absl::Milliseconds(300));
  v1::Session waiting = testing::GetSession(*service_, id);
  EXPECT_EQ(waiting.state(), v1::SESSION_STATE_COLLECTING) << "no learner before 1,000 points";
  EXPECT_EQ(waiting.latest_sequence(), 0u);
  grpc::Status too_few = testing::Finish(*service_, id);
  EXPECT_EQ(too_few.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_TRUE(absl::StrContains(too_few.error_message(),
                                "finishing needs at least 1000 (the start mesh's 500 vertices"))
      << too_few.error_message();

  v1::UploadPointsRequest rest;
  rest.set_session_id(id);
  for (size_t begin = 600; begin < points.size(); begin += 5000) {
    *rest.mutable_batch() = testing::Batch(points, begin, std::min(begin + 5000, points.size()));
    ASSERT_TRUE(testing::UploadOne(*service_, rest, &response).ok());
  }
  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(WaitFinal(*service_, id, &final_mesh).ok());
  watcher.join();
  ASSERT_TRUE(watch_status.ok()) << watch_status.error_message();

  ASSERT_GE(watched.size(), 2u);
  EXPECT_EQ(watched.front().kind(), v1::UPDATE_KIND_REFRESH);
  EXPECT_EQ(watched.front().vertex_count(), 500u) << "the start mesh comes first";
  EXPECT_EQ(watched.front().learning().basic_steps(), 0u);
  for (const v1::MeshUpdate& update : watched) {
    EXPECT_GE(update.vertex_count(), 500u);
    if (update.kind() == v1::UPDATE_KIND_MILESTONE) {
      EXPECT_EQ(update.lod_milestone(), 1000u) << "the 200-vertex milestone is passed";
    }
  }
  EXPECT_EQ(final_mesh.vertex_count(), 2000u);
  EXPECT_EQ(final_mesh.report().genus(), 0);
  EXPECT_EQ(final_mesh.report().boundary_loops(), 0u);
  EXPECT_LT(final_mesh.learning().basic_steps(), 170000u)
      << "from 500 vertices; about 200,000 from the tetrahedron";
  EXPECT_LT(MaxDistanceToUnitSphere(final_mesh), 0.02);
}

TEST_F(StartMeshTest, ADracoStartMeshIsTakenToo) {
  const TriangleMesh start = LearnedSphere(300);
  v1::CreateSessionRequest request = RequestFrom(start, 1500);
  DracoOptions draco;
  draco.position_quantization_bits = 16;
  request.mutable_start_mesh()->set_draco_mesh(EncodeMesh(start, draco).value());
  const std::string id = MustCreate(*service_, request);
  v1::UploadPointsResponse response;
  ASSERT_TRUE(Upload(*service_, id, SpherePoints(10000, 6), 2, &response).ok());
  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(WaitFinal(*service_, id, &final_mesh).ok());
  EXPECT_EQ(final_mesh.vertex_count(), 1500u);
  EXPECT_LT(final_mesh.learning().basic_steps(), 140000u) << "from 300 vertices";
  EXPECT_LT(MaxDistanceToUnitSphere(final_mesh), 0.02);
}

// A Draco start mesh whose metadata give another origin than the session's (a mesh written
// relative to (499990, 4100000, 0), so 10 m off in the session's frame) is moved into the
// session's frame: the first mesh published, the start mesh itself, lies on the sphere.
TEST_F(StartMeshTest, ADracoStartMeshIsMovedIntoTheSessionsFrame) {
  TriangleMesh start = LearnedSphere(300);
  start.origin = {500000, 4100000, 0};
  ASSERT_TRUE(MoveOrigin({499990, 4100000, 0}, &start).ok());
  v1::CreateSessionRequest request = RequestFrom(start, 400);
  request.mutable_config()->clear_lod_milestones();
  request.mutable_config()->mutable_origin()->set_x(500000);
  request.mutable_config()->mutable_origin()->set_y(4100000);
  DracoOptions draco;
  draco.position_quantization_bits = 16;
  request.mutable_start_mesh()->set_draco_mesh(EncodeMesh(start, draco).value());
  const std::string id = MustCreate(*service_, request);
  std::vector<v1::MeshUpdate> watched;
  grpc::Status watch_status;
  std::thread watcher([&] { watch_status = WatchAll(*service_, id, &watched); });
  v1::UploadPointsResponse response;
  ASSERT_TRUE(Upload(*service_, id, SpherePoints(4000, 6), 2, &response).ok());
  ASSERT_TRUE(testing::Finish(*service_, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(WaitFinal(*service_, id, &final_mesh).ok());
  watcher.join();
  ASSERT_TRUE(watch_status.ok()) << watch_status.error_message();
  ASSERT_FALSE(watched.empty());
  EXPECT_EQ(watched.front().learning().basic_steps(), 0u) << "the start mesh comes first";
  EXPECT_LT(MaxDistanceToUnitSphere(watched.front()), 0.05) << "not 10 m off";
  const absl::StatusOr<TriangleMesh> first = DecodeMesh(watched.front().draco_mesh());
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(first->origin, (std::array<double, 3>{500000, 4100000, 0}));
}

TEST_F(StartMeshTest, AStartMeshThatCannotBeLearnedFromIsInvalidArgument) {
  const TriangleMesh start = LearnedSphere(100);
  auto create = [&](const v1::CreateSessionRequest& request) {
    grpc::ClientContext context;
    v1::Session session;
    return service_->CreateSession(&context, request, &session);
  };
  struct Case {
    const char* what;
    v1::CreateSessionRequest request;
    const char* message;
  };
  std::vector<Case> cases;
  v1::CreateSessionRequest small = RequestFrom(start, 100);
  small.mutable_config()->clear_lod_milestones();
  cases.push_back({"as many vertices as the target", small,
                   "start_mesh has 100 vertices; it must have fewer than target_vertices (100)"});
  TriangleMesh fin = start;  // A third face on the edge of face 0.
  fin.positions.push_back(Vec3f(3, 3, 3));
  fin.faces.push_back({fin.faces[0][0], fin.faces[0][1], 100});
  cases.push_back({"three faces on an edge", RequestFrom(fin, 1000),
                   "non-manifold or inconsistently oriented"});
  TriangleMesh nan = start;
  nan.positions[7][2] = std::nanf("");
  cases.push_back({"a NaN", RequestFrom(nan, 1000),
                   "start_mesh: vertex 7 of the start mesh has a coordinate that is not finite"});
  v1::CreateSessionRequest cut = RequestFrom(start, 1000);
  cut.mutable_start_mesh()->mutable_packed()->mutable_faces()->pop_back();
  cases.push_back({"faces cut short", cut, "each must be a multiple of 12"});
  v1::CreateSessionRequest empty = RequestFrom(start, 1000);
  empty.mutable_start_mesh()->Clear();
  cases.push_back({"no mesh", empty, "start_mesh holds no mesh"});
  v1::CreateSessionRequest garbage = RequestFrom(start, 1000);
  garbage.mutable_start_mesh()->set_draco_mesh("not draco");
  cases.push_back({"not Draco", garbage, "start_mesh.draco_mesh: "});
  for (const Case& c : cases) {
    const grpc::Status status = create(c.request);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << c.what;
    EXPECT_TRUE(absl::StrContains(status.error_message(), c.message))
        << c.what << ": " << status.error_message();
  }
  grpc::ClientContext context;
  v1::ListSessionsResponse list;
  ASSERT_TRUE(service_->ListSessions(&context, v1::ListSessionsRequest(), &list).ok());
  EXPECT_EQ(list.sessions_size(), 0) << "no session was created";
}

// With a state directory the start mesh is the session's first checkpoint: a restart before
// any milestone learns on from it.
TEST(StartMeshRestartTest, ARestartBeforeAnyMilestoneLearnsOnFromTheStartMesh) {
  const std::string state_dir = neuralmesh::testing::MakeTempDir("start_state");
  testing::CapturedEvents events;
  ServerOptions options;
  options.address = "";
  options.state_dir = state_dir;
  options.state_sync = false;
  options.event_sink = events.Sink();
  std::unique_ptr<ReconstructionServer> server = ReconstructionServer::Start(options).value();
  std::unique_ptr<Service> service = testing::InProcessService(*server);
  const TriangleMesh start = LearnedSphere(500);
  const std::string id = MustCreate(*service, RequestFrom(start, 2000));
  service.reset();
  server.reset();

  server = ReconstructionServer::Start(options).value();
  server->WaitForRestore();
  service = testing::InProcessService(*server);
  EXPECT_FALSE(events.Await("learner checkpoint of 500 vertices").empty());
  v1::UploadPointsResponse response;
  ASSERT_TRUE(Upload(*service, id, SpherePoints(20000, 7), 4, &response).ok());
  EXPECT_FALSE(events.Await("learning goes on from the stored mesh of 500 vertices").empty());
  ASSERT_TRUE(testing::Finish(*service, id).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(WaitFinal(*service, id, &final_mesh).ok());
  EXPECT_EQ(final_mesh.vertex_count(), 2000u);
  EXPECT_LT(final_mesh.learning().basic_steps(), 170000u);
  EXPECT_LT(MaxDistanceToUnitSphere(final_mesh), 0.02);
}

}  // namespace
}  // namespace neuralmesh::server
