// Tests of client/reconstruction_client.h against a real neuralmesh-server on 127.0.0.1
// (started as a subprocess, port 0), and of the Reconstruct call on an in-process server.
#include "client/reconstruction_client.h"

#include <grpcpp/grpcpp.h>

#include <cmath>
#include <csignal>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/notification.h"
#include "absl/time/clock.h"
#include "core/io/draco_codec.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/sample_points.h"
#include "gtest/gtest.h"
#include "tests/client/subprocess.h"
#include "tests/client/test_server.h"
#include "tests/server/server_test_support.h"

namespace neuralmesh::client {
namespace {

using ::neuralmesh::testing::TestServer;

PointCloud SpherePoints(size_t n) {
  auto sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  EXPECT_TRUE(sphere.ok()) << sphere.status();
  return SamplePoints(**sphere, n, /*seed=*/5);
}

v1::SessionConfig SmallConfig(uint64_t target) {
  v1::SessionConfig config;
  config.set_target_vertices(target);
  config.add_lod_milestones(target / 4);
  config.add_lod_milestones(target / 2);
  config.add_lod_milestones(target);
  return config;
}

class ReconstructionClientTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string error;
    server_ = TestServer::Start({}, &error).release();
    if (server_ == nullptr) *start_error_ = error;
  }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }

  void SetUp() override {
    ASSERT_NE(server_, nullptr) << *start_error_;
    absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
        ReconstructionClient::Connect(server_->address());
    ASSERT_TRUE(client.ok()) << client.status();
    client_ = *std::move(client);
  }

  static TestServer* server_;
  static std::string* start_error_;
  std::unique_ptr<ReconstructionClient> client_;
};

TestServer* ReconstructionClientTest::server_ = nullptr;
std::string* ReconstructionClientTest::start_error_ = new std::string;

TEST_F(ReconstructionClientTest, UploadWatchAndFinishDeliverTheFinalMesh) {
  absl::StatusOr<v1::Session> session = client_->CreateSession(SmallConfig(200), "sphere");
  ASSERT_TRUE(session.ok()) << session.status();
  const std::string id = session->session_id();
  EXPECT_FALSE(id.empty());

  std::vector<v1::MeshUpdate> updates;
  absl::Status watch_status;
  std::thread watcher([&] {
    watch_status = client_->Watch(id, 0, [&](const v1::MeshUpdate& update) {
      updates.push_back(update);
      return true;
    });
  });

  std::vector<uint64_t> progress;
  const PointCloud cloud = SpherePoints(2000);
  absl::StatusOr<v1::UploadPointsResponse> uploaded =
      client_->UploadPoints(id, cloud, 300, [&](uint64_t sent, uint64_t total) {
        EXPECT_EQ(total, 2000u);
        progress.push_back(sent);
      });
  ASSERT_TRUE(uploaded.ok()) << uploaded.status();
  EXPECT_EQ(uploaded->points_accepted(), 2000u);
  EXPECT_EQ(uploaded->batches_accepted(), 7u) << "2000 points in batches of 300";
  EXPECT_EQ(uploaded->total_points(), 2000u);
  EXPECT_EQ(progress, (std::vector<uint64_t>{300, 600, 900, 1200, 1500, 1800, 2000}));

  absl::StatusOr<v1::Session> finished = client_->Finish(id);
  ASSERT_TRUE(finished.ok()) << finished.status();
  watcher.join();
  ASSERT_TRUE(watch_status.ok()) << watch_status;

  ASSERT_FALSE(updates.empty());
  for (size_t i = 1; i < updates.size(); ++i) {
    EXPECT_GT(updates[i].sequence(), updates[i - 1].sequence()) << "update " << i;
  }
  const v1::MeshUpdate& last = updates.back();
  EXPECT_EQ(last.kind(), v1::UPDATE_KIND_FINAL);
  EXPECT_EQ(last.vertex_count(), 200u);
  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(last.draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->faces.size(), last.face_count());

  absl::StatusOr<v1::MeshUpdate> final_mesh =
      client_->GetMesh(id, v1::MESH_VERSION_FINAL, /*wait=*/true, absl::Seconds(30));
  ASSERT_TRUE(final_mesh.ok()) << final_mesh.status();
  EXPECT_EQ(final_mesh->sequence(), last.sequence());

  absl::StatusOr<v1::Session> state = client_->GetSession(id);
  ASSERT_TRUE(state.ok()) << state.status();
  EXPECT_EQ(state->state(), v1::SESSION_STATE_FINISHED);

  absl::StatusOr<std::vector<v1::Session>> sessions = client_->ListSessions();
  ASSERT_TRUE(sessions.ok()) << sessions.status();
  bool listed = false;
  for (const v1::Session& s : *sessions) listed = listed || s.session_id() == id;
  EXPECT_TRUE(listed) << "ListSessions misses " << id;
}

TEST_F(ReconstructionClientTest, CancelThenDeleteRemovesTheSession) {
  absl::StatusOr<v1::Session> session = client_->CreateSession(SmallConfig(100), "doomed");
  ASSERT_TRUE(session.ok()) << session.status();
  const std::string id = session->session_id();
  ASSERT_TRUE(client_->UploadPoints(id, SpherePoints(500), 250).ok());

  absl::StatusOr<v1::Session> cancelled = client_->Cancel(id);
  ASSERT_TRUE(cancelled.ok()) << cancelled.status();
  EXPECT_EQ(cancelled->state(), v1::SESSION_STATE_CANCELLED);
  const absl::Status watch = client_->Watch(id, 0, [](const v1::MeshUpdate&) { return true; });
  EXPECT_TRUE(absl::IsCancelled(watch)) << watch;

  ASSERT_TRUE(client_->Delete(id).ok());
  EXPECT_TRUE(absl::IsNotFound(client_->GetSession(id).status()));
  EXPECT_TRUE(absl::IsNotFound(client_->Delete(id)));
}

// Watches a session in the background; the result is read after Join. A watch still open at
// the end (a failed test) is ended with the client's CancelCalls.
class BackgroundWatch {
 public:
  BackgroundWatch(ReconstructionClient& client, const std::string& session_id)
      : client_(client), thread_([this, session_id] {
          status_ = client_.Watch(session_id, 0, [](const v1::MeshUpdate&) { return true; });
          ended_.Notify();
        }) {}
  ~BackgroundWatch() {
    if (!ended_.HasBeenNotified()) client_.CancelCalls();
    Join().IgnoreError();
  }
  // Whether the watch ended within `timeout`.
  bool EndsWithin(absl::Duration timeout) { return ended_.WaitForNotificationWithTimeout(timeout); }
  absl::Status Join() {
    if (thread_.joinable()) thread_.join();
    return status_;
  }

 private:
  ReconstructionClient& client_;
  absl::Status status_;
  absl::Notification ended_;
  std::thread thread_;
};

TEST_F(ReconstructionClientTest, CancelCallsEndsOpenAndLaterCallsButNotCancel) {
  absl::StatusOr<v1::Session> session = client_->CreateSession(SmallConfig(100), "quiet");
  ASSERT_TRUE(session.ok()) << session.status();
  const std::string id = session->session_id();
  // No points: the session never publishes a mesh, so the watch waits until it is ended.
  BackgroundWatch watch(*client_, id);
  EXPECT_FALSE(watch.EndsWithin(absl::Milliseconds(300))) << "nothing to end the watch yet";
  client_->CancelCalls();
  ASSERT_TRUE(watch.EndsWithin(absl::Seconds(5))) << "CancelCalls must end the watch";
  const absl::Status ended = watch.Join();
  EXPECT_TRUE(absl::IsCancelled(ended)) << ended;
  const absl::Status later = client_->Watch(id, 0, [](const v1::MeshUpdate&) { return true; });
  EXPECT_TRUE(absl::IsCancelled(later)) << "a watch started afterwards ends at once: " << later;
  EXPECT_TRUE(absl::IsCancelled(client_->Finish(id).status())) << "so does a simple call";

  absl::StatusOr<std::unique_ptr<ReconstructionClient>> observer =
      ReconstructionClient::Connect(server_->address());
  ASSERT_TRUE(observer.ok()) << observer.status();
  absl::StatusOr<v1::Session> after = (*observer)->GetSession(id);
  ASSERT_TRUE(after.ok()) << after.status();
  EXPECT_EQ(after->state(), v1::SESSION_STATE_COLLECTING) << "the session itself goes on";
  absl::StatusOr<v1::Session> cancelled = client_->Cancel(id);
  ASSERT_TRUE(cancelled.ok()) << "Cancel still reaches the server: " << cancelled.status();
  EXPECT_EQ(cancelled->state(), v1::SESSION_STATE_CANCELLED);
  EXPECT_TRUE((*observer)->Delete(id).ok());
}

// With a keepalive ping every 1.2 s: a live server answers them and keeps a quiet watch open
// (gRPC's default policy closes a connection after its third ping within 5 minutes without
// data), and a server that stops answering ends the watch with UNAVAILABLE instead of leaving
// it waiting.
TEST(ReconstructionClientKeepaliveTest, AQuietWatchStaysOpenAndAFrozenServerEndsIt) {
  std::string error;
  std::unique_ptr<TestServer> server = TestServer::Start({}, &error);
  ASSERT_NE(server, nullptr) << error;
  ClientOptions options;
  options.keepalive_time = absl::Milliseconds(1200);
  options.keepalive_timeout = absl::Seconds(1);
  absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
      ReconstructionClient::Connect(server->address(), options);
  ASSERT_TRUE(client.ok()) << client.status();
  absl::StatusOr<v1::Session> session = (*client)->CreateSession(SmallConfig(100), "quiet");
  ASSERT_TRUE(session.ok()) << session.status();

  BackgroundWatch watch(**client, session->session_id());
  EXPECT_FALSE(watch.EndsWithin(absl::Seconds(6)))
      << "the server dropped a client that pinged a quiet watch: " << watch.Join();
  server->Signal(SIGSTOP);
  const absl::Time frozen = absl::Now();
  const bool ended = watch.EndsWithin(absl::Seconds(20));
  server->Signal(SIGCONT);
  ASSERT_TRUE(ended) << "the watch of a frozen server did not end within 20 s";
  const absl::Status status = watch.Join();
  EXPECT_TRUE(absl::IsUnavailable(status)) << status;
  EXPECT_LT(absl::Now() - frozen, absl::Seconds(10)) << "keepalive answers within about 2.2 s";
}

TEST_F(ReconstructionClientTest, StatusesKeepTheServersCodeAndNameTheCall) {
  const absl::Status unknown = client_->GetSession("no-such-session").status();
  EXPECT_TRUE(absl::IsNotFound(unknown)) << unknown;
  EXPECT_NE(unknown.message().find("GetSession"), absl::string_view::npos) << unknown;

  v1::SessionConfig invalid;  // No target_vertices.
  const absl::Status rejected = client_->CreateSession(invalid, "invalid").status();
  EXPECT_TRUE(absl::IsInvalidArgument(rejected)) << rejected;
}

TEST_F(ReconstructionClientTest, UploadRejectsAnEmptyCloudAndAZeroBatchSize) {
  EXPECT_TRUE(absl::IsInvalidArgument(client_->UploadPoints("any", PointCloud(), 10).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(client_->UploadPoints("any", SpherePoints(10), 0).status()));
}

// The Reconstruct call on an in-process server (no sockets): the client's logic alone.
class ReconstructCallTest : public ::testing::Test {
 protected:
  void SetUp() override {
    server_ = server::testing::StartServer(/*listen=*/false);
    ASSERT_NE(server_, nullptr);
    client_ = std::make_unique<ReconstructionClient>(server_->InProcessChannel(), ClientOptions());
  }
  void TearDown() override {
    if (server_ != nullptr) server_->Shutdown(absl::Seconds(2));
  }

  std::unique_ptr<server::ReconstructionServer> server_;
  std::unique_ptr<ReconstructionClient> client_;
};

// With outlier removal on the server, the progress still reaches every point sent: the
// dropped ones were received all the same.
TEST_F(ReconstructCallTest, ProgressCountsThePointsTheServerDroppedAsOutliers) {
  PointCloud cloud = SpherePoints(3000);
  cloud.positions.emplace_back(0.f, 0.f, 60.f);
  v1::SessionConfig config;
  config.set_target_vertices(300);
  config.mutable_outlier_removal();
  uint64_t last_progress = 0;
  absl::StatusOr<ReconstructResult> result = client_->Reconstruct(
      config, "sphere", cloud, /*batch_size=*/1000, [](const v1::MeshUpdate&) { return true; },
      [&](uint64_t received, uint64_t total) {
        EXPECT_EQ(total, 3001u);
        last_progress = received;
      });
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_GE(result->last_ack.points_held_back(), 1u) << "the stray";
  EXPECT_EQ(result->last_ack.points_accepted() + result->last_ack.points_held_back(), 3001u);
  EXPECT_EQ(last_progress, 3001u);
}

TEST_F(ReconstructCallTest, StreamsASphereAndReceivesCoarseToFineMeshes) {
  const PointCloud cloud = SpherePoints(20000);
  v1::SessionConfig config;
  config.set_target_vertices(1000);  // Default milestones: 10, 20, 50, ..., 500, 1000.
  std::vector<v1::MeshUpdate> updates;
  std::vector<uint64_t> acknowledged;
  const std::thread::id caller = std::this_thread::get_id();
  absl::StatusOr<ReconstructResult> result = client_->Reconstruct(
      config, "sphere", cloud, /*batch_size=*/200,
      [&](const v1::MeshUpdate& update) {
        EXPECT_EQ(std::this_thread::get_id(), caller) << "callbacks run on the calling thread";
        updates.push_back(update);
        return true;
      },
      [&](uint64_t accepted, uint64_t total) {
        EXPECT_EQ(total, 20000u);
        acknowledged.push_back(accepted);
      });
  ASSERT_TRUE(result.ok()) << result.status();

  EXPECT_FALSE(result->session.session_id().empty());
  EXPECT_EQ(result->session.config().target_vertices(), 1000u);
  EXPECT_EQ(result->last_ack.total_points(), 20000u);
  EXPECT_EQ(result->last_ack.batches_accepted(), 100u) << "20000 points in batches of 200";
  ASSERT_FALSE(acknowledged.empty());
  for (size_t i = 1; i < acknowledged.size(); ++i) {
    EXPECT_GT(acknowledged[i], acknowledged[i - 1]) << "acknowledgement " << i;
  }
  EXPECT_EQ(acknowledged.back(), 20000u) << "the last acknowledgement always arrives";

  // Coarse to fine: milestone meshes with increasing vertex counts, then the final mesh.
  ASSERT_FALSE(updates.empty());
  std::vector<uint64_t> counts;
  for (size_t i = 0; i < updates.size(); ++i) {
    if (i > 0) {
      EXPECT_GT(updates[i].sequence(), updates[i - 1].sequence()) << "update " << i;
    }
    if (updates[i].kind() != v1::UPDATE_KIND_REFRESH) counts.push_back(updates[i].vertex_count());
  }
  ASSERT_GE(counts.size(), 4u) << "too few milestone meshes arrived";
  for (size_t i = 1; i < counts.size(); ++i) {
    EXPECT_GT(counts[i], counts[i - 1]) << "milestone vertex counts must increase";
  }
  const v1::MeshUpdate& last = updates.back();
  ASSERT_EQ(last.kind(), v1::UPDATE_KIND_FINAL) << "the final mesh comes last";
  EXPECT_EQ(last.vertex_count(), 1000u);
  EXPECT_EQ(result->final_mesh.sequence(), last.sequence());
  EXPECT_EQ(result->final_mesh.session_id(), result->session.session_id());

  absl::StatusOr<TriangleMesh> mesh = DecodeMesh(result->final_mesh.draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->faces.size(), result->final_mesh.face_count());
  auto sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  ASSERT_TRUE(sphere.ok());
  EXPECT_LT(server::testing::MaxVertexDistance(*mesh, **sphere), 0.05)
      << "the final mesh lies off the unit sphere";

  absl::StatusOr<v1::Session> session = client_->GetSession(result->session.session_id());
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->state(), v1::SESSION_STATE_FINISHED) << "half-closing finished the session";
}

TEST_F(ReconstructCallTest, ABadBatchEndsTheCallAndTheSessionKeepsTheGoodOnes) {
  PointCloud cloud = SpherePoints(2000);
  cloud.positions[1700][1] = std::numeric_limits<float>::quiet_NaN();  // In the fourth batch.
  v1::SessionConfig config;
  config.set_target_vertices(200);
  absl::StatusOr<ReconstructResult> result = client_->Reconstruct(
      config, "bad", cloud, /*batch_size=*/500, [](const v1::MeshUpdate&) { return true; });
  ASSERT_FALSE(result.ok());
  EXPECT_TRUE(absl::IsInvalidArgument(result.status())) << result.status();
  EXPECT_NE(result.status().message().find("Reconstruct of session "), absl::string_view::npos)
      << "the status names the session the caller must clean up: " << result.status();

  absl::StatusOr<std::vector<v1::Session>> sessions = client_->ListSessions();
  ASSERT_TRUE(sessions.ok()) << sessions.status();
  ASSERT_EQ(sessions->size(), 1u);
  const v1::Session& session = sessions->front();
  EXPECT_NE(result.status().message().find(session.session_id()), absl::string_view::npos)
      << result.status();
  EXPECT_EQ(session.learning().points_received(), 1500u) << "the three good batches stay";
  EXPECT_TRUE(session.state() == v1::SESSION_STATE_COLLECTING ||
              session.state() == v1::SESSION_STATE_LEARNING)
      << "a rejected batch neither finishes nor cancels the session: "
      << v1::SessionState_Name(session.state());
}

TEST_F(ReconstructCallTest, AnInvalidConfigIsRejectedBeforeAnyUpdate) {
  v1::SessionConfig config;  // No target_vertices.
  int updates = 0;
  absl::StatusOr<ReconstructResult> result =
      client_->Reconstruct(config, "invalid", SpherePoints(100), 50, [&](const v1::MeshUpdate&) {
        ++updates;
        return true;
      });
  EXPECT_TRUE(absl::IsInvalidArgument(result.status())) << result.status();
  EXPECT_EQ(updates, 0);
}

TEST_F(ReconstructCallTest, ReturningFalseFromTheCallbackCancelsTheCall) {
  v1::SessionConfig config;
  config.set_target_vertices(5000);
  int updates = 0;
  absl::StatusOr<ReconstructResult> result = client_->Reconstruct(
      config, "stopped", SpherePoints(20000), 1000, [&](const v1::MeshUpdate&) {
        ++updates;
        return false;
      });
  EXPECT_TRUE(absl::IsCancelled(result.status())) << result.status();
  EXPECT_EQ(updates, 1) << "no update is delivered after the callback said stop";
}

TEST_F(ReconstructCallTest, RejectsAnEmptyCloudAndAZeroBatchSize) {
  v1::SessionConfig config;
  config.set_target_vertices(100);
  const auto ignore = [](const v1::MeshUpdate&) { return true; };
  EXPECT_TRUE(absl::IsInvalidArgument(
      client_->Reconstruct(config, "empty", PointCloud(), 10, ignore).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(
      client_->Reconstruct(config, "zero", SpherePoints(10), 0, ignore).status()));
  absl::StatusOr<std::vector<v1::Session>> sessions = client_->ListSessions();
  ASSERT_TRUE(sessions.ok()) << sessions.status();
  EXPECT_TRUE(sessions->empty()) << "no call was made";
}

TEST(ReconstructionClientConnectTest, NoServerGivesUnavailable) {
  ClientOptions options;
  options.connect_timeout = absl::Milliseconds(500);
  const std::string address = "127.0.0.1:" + std::to_string(testing::PickFreePort());
  absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
      ReconstructionClient::Connect(address, options);
  ASSERT_FALSE(client.ok());
  EXPECT_TRUE(absl::IsUnavailable(client.status())) << client.status();
  EXPECT_NE(client.status().message().find(address), absl::string_view::npos) << client.status();
  EXPECT_NE(client.status().message().find("Connection refused"), absl::string_view::npos)
      << "gRPC's reason is passed on: " << client.status();
}

// A server that answers GetMesh with `bytes` of Draco data, as one of a session of millions
// of vertices would.
class LargeMeshService final : public v1::ReconstructionService::Service {
 public:
  explicit LargeMeshService(size_t bytes) : bytes_(bytes) {}
  grpc::Status GetMesh(grpc::ServerContext*, const v1::GetMeshRequest* request,
                       v1::MeshUpdate* update) override {
    update->set_session_id(request->session_id());
    update->set_draco_mesh(std::string(bytes_, 'd'));
    return grpc::Status::OK;
  }

 private:
  const size_t bytes_;
};

// gRPC takes messages of at most 4 MiB by default; the client takes the server's 64 MiB, and
// a lower limit of its own gives RESOURCE_EXHAUSTED.
TEST(ReconstructionClientMessageSizeTest, MeshesLargerThanGrpcsDefaultLimitArrive) {
  LargeMeshService service(6 << 20);
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  builder.SetMaxSendMessageSize(64 << 20);
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  ASSERT_NE(server, nullptr);
  const std::string address = absl::StrCat("127.0.0.1:", port);

  absl::StatusOr<std::unique_ptr<ReconstructionClient>> client =
      ReconstructionClient::Connect(address);
  ASSERT_TRUE(client.ok()) << client.status();
  absl::StatusOr<v1::MeshUpdate> mesh =
      (*client)->GetMesh("s-1", v1::MESH_VERSION_LATEST, false, absl::Seconds(30));
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->draco_mesh().size(), size_t{6} << 20);

  ClientOptions small;
  small.max_message_bytes = 1 << 20;
  absl::StatusOr<std::unique_ptr<ReconstructionClient>> limited =
      ReconstructionClient::Connect(address, small);
  ASSERT_TRUE(limited.ok()) << limited.status();
  const absl::Status refused =
      (*limited)->GetMesh("s-1", v1::MESH_VERSION_LATEST, false, absl::Seconds(30)).status();
  EXPECT_TRUE(absl::IsResourceExhausted(refused)) << refused;
  server->Shutdown();
}

}  // namespace
}  // namespace neuralmesh::client
