// neuralmesh-server --state_dir under concurrency (ctest label server-concurrency): uploads
// into several sessions at once while meshes are stored and a reader lists them, one session is
// deleted and others finish; a restarted server then has exactly what was acknowledged.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::server {
namespace {

std::unique_ptr<ReconstructionServer> StartOn(const std::string& state_dir) {
  ServerOptions options;
  options.address = "";
  options.worker_threads = 2;
  options.state_dir = state_dir;
  options.state_sync = false;
  absl::StatusOr<std::unique_ptr<ReconstructionServer>> server =
      ReconstructionServer::Start(options);
  EXPECT_TRUE(server.ok()) << server.status();
  if (!server.ok()) return nullptr;
  (*server)->WaitForRestore();
  return *std::move(server);
}

TEST(SessionStoreConcurrentTest, ConcurrentUploadsDeletesAndFinishesComeBackAsAcknowledged) {
  const std::string state_dir = neuralmesh::testing::MakeTempDir("concurrent_state");
  std::unique_ptr<ReconstructionServer> server = StartOn(state_dir);
  ASSERT_NE(server, nullptr);
  auto service = testing::InProcessService(*server);

  constexpr int kSessions = 4;
  constexpr size_t kPoints = 8000;
  std::vector<std::string> ids;
  for (int i = 0; i < kSessions; ++i) {
    ids.push_back(testing::MustCreate(*service, testing::CreateRequest(300, /*refresh_ms=*/10)));
  }
  // Each session's points in 16 batches from its own thread; a reader lists and fetches
  // meshes all along; session 3 is deleted in the middle of its upload.
  std::atomic<bool> uploading{true};
  std::vector<std::thread> threads;
  std::vector<grpc::Status> statuses(kSessions);
  for (int i = 0; i < kSessions; ++i) {
    threads.emplace_back([&, i] {
      v1::UploadPointsResponse response;
      statuses[i] = testing::Upload(*service, ids[i], testing::SpherePoints(kPoints, i + 1), 16,
                                    &response);
    });
  }
  std::thread reader([&] {
    while (uploading.load()) {
      grpc::ClientContext context;
      v1::ListSessionsResponse list;
      service->ListSessions(&context, v1::ListSessionsRequest(), &list);
      for (const std::string& id : ids) testing::GetSession(*service, id);
    }
  });
  absl::SleepFor(absl::Milliseconds(5));
  EXPECT_TRUE(testing::Delete(*service, ids[3]).ok());
  for (std::thread& t : threads) t.join();
  uploading.store(false);
  reader.join();
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(statuses[i].ok()) << statuses[i].error_message();
  // Sessions 0 and 1 finish; session 2 goes on collecting.
  for (int i = 0; i < 2; ++i) ASSERT_TRUE(testing::Finish(*service, ids[i]).ok());
  for (int i = 0; i < 2; ++i) {
    v1::MeshUpdate final_mesh;
    ASSERT_TRUE(testing::WaitFinal(*service, ids[i], &final_mesh).ok());
  }
  service.reset();
  server.reset();
  EXPECT_FALSE(std::filesystem::exists(absl::StrCat(state_dir, "/sessions/", ids[3])));

  server = StartOn(state_dir);
  ASSERT_NE(server, nullptr);
  EXPECT_TRUE(server->WaitForRestore().problems.empty());
  EXPECT_EQ(server->WaitForRestore().sessions, 3u);
  service = testing::InProcessService(*server);
  for (int i = 0; i < 3; ++i) {
    const v1::Session session = testing::GetSession(*service, ids[i]);
    EXPECT_EQ(session.points_taken(), kPoints) << i;
    if (i < 2) {
      EXPECT_EQ(session.state(), v1::SESSION_STATE_FINISHED) << i;
    } else {  // Learning again, or about to.
      EXPECT_TRUE(session.state() == v1::SESSION_STATE_COLLECTING ||
                  session.state() == v1::SESSION_STATE_LEARNING)
          << v1::SessionState_Name(session.state());
    }
  }
  grpc::Status status;
  testing::GetSession(*service, ids[3], &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  // The collecting one finishes on the restarted server.
  ASSERT_TRUE(testing::Finish(*service, ids[2]).ok());
  v1::MeshUpdate final_mesh;
  ASSERT_TRUE(testing::WaitFinal(*service, ids[2], &final_mesh).ok());
  EXPECT_EQ(final_mesh.learning().points_received(), kPoints);
  EXPECT_EQ(final_mesh.report().genus(), 0);
}

}  // namespace
}  // namespace neuralmesh::server
