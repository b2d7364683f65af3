// Concurrent sessions on a small worker pool stay isolated and all make progress.
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "core/io/draco_codec.h"
#include "tests/server/server_test_support.h"

namespace neuralmesh::server {
namespace {

TEST(ServiceConcurrentTest, EightSessionsOnTwoWorkersStayIsolatedAndAllProgress) {
  ServerOptions options;
  options.worker_threads = 2;
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(false, options);
  ASSERT_NE(server, nullptr);
  auto stub = testing::InProcessStub(*server);

  constexpr int kSessions = 8;
  // Each session gets its own shape: spheres and tori of different sizes at different places.
  std::vector<std::unique_ptr<ImplicitSurface>> surfaces;
  for (int i = 0; i < kSessions; ++i) {
    const Vec3 center(10.0 * i, 0, 0);
    auto surface = i % 2 == 0 ? MakeSphere(center, 1.0 + 0.25 * i)
                              : MakeTorus(center, 1.0 + 0.05 * i, 0.4);
    ASSERT_TRUE(surface.ok());
    surfaces.push_back(*std::move(surface));
  }
  std::vector<std::string> ids(kSessions);
  std::vector<size_t> counts(kSessions);
  for (int i = 0; i < kSessions; ++i) {
    ids[i] = testing::MustCreate(*stub, testing::CreateRequest(400 + 10 * i));
    counts[i] = 3000 + 100 * i;
  }

  // Upload everything concurrently, then check that all sessions learn at the same time.
  std::vector<std::thread> threads;
  std::vector<grpc::Status> statuses(kSessions);
  for (int i = 0; i < kSessions; ++i) {
    threads.emplace_back([&, i] {
      v1::UploadPointsResponse response;
      statuses[i] = testing::Upload(*stub, ids[i], SamplePoints(*surfaces[i], counts[i], i + 1),
                                    10, &response);
    });
  }
  for (std::thread& t : threads) t.join();
  threads.clear();
  for (int i = 0; i < kSessions; ++i) ASSERT_TRUE(statuses[i].ok()) << statuses[i].error_message();

  absl::SleepFor(absl::Milliseconds(300));
  for (int i = 0; i < kSessions; ++i) {
    v1::Session session = testing::GetSession(*stub, ids[i]);
    EXPECT_EQ(session.learning().points_received(), counts[i]) << "session " << i;
    EXPECT_GT(session.learning().basic_steps(), 0u)
        << "session " << i << " made no progress while 7 others learned";
  }

  std::vector<v1::MeshUpdate> finals(kSessions);
  for (int i = 0; i < kSessions; ++i) {
    threads.emplace_back([&, i] {
      statuses[i] = testing::Finish(*stub, ids[i]);
      if (statuses[i].ok()) statuses[i] = testing::WaitFinal(*stub, ids[i], &finals[i]);
    });
  }
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < kSessions; ++i) {
    ASSERT_TRUE(statuses[i].ok()) << "session " << i << ": " << statuses[i].error_message()
                                  << "\n" << testing::GetSession(*stub, ids[i]).DebugString();
    EXPECT_EQ(finals[i].session_id(), ids[i]);
    EXPECT_EQ(finals[i].vertex_count(), 400u + 10 * i) << "each session keeps its own target";
    EXPECT_EQ(finals[i].learning().points_received(), counts[i]);
    absl::StatusOr<TriangleMesh> mesh = DecodeMesh(finals[i].draco_mesh());
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    // The shapes lie 10 apart: a mesh that learned another session's points would have
    // vertices several units away from its own surface.
    EXPECT_LT(testing::MaxVertexDistance(*mesh, *surfaces[i]), 1.0)
        << "session " << i << "'s mesh strays from its own surface (mixed-up data?)";
  }
}

}  // namespace
}  // namespace neuralmesh::server
