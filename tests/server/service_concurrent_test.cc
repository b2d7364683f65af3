// Concurrent sessions on a small worker pool stay isolated and all make progress.
#include <gtest/gtest.h>

#include <algorithm>
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
  auto service = testing::InProcessService(*server);

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
    ids[i] = testing::MustCreate(*service, testing::CreateRequest(400 + 10 * i));
    counts[i] = 3000 + 100 * i;
  }

  // Upload everything concurrently, then check that all sessions learn at the same time.
  std::vector<std::thread> threads;
  std::vector<grpc::Status> statuses(kSessions);
  for (int i = 0; i < kSessions; ++i) {
    threads.emplace_back([&, i] {
      v1::UploadPointsResponse response;
      statuses[i] = testing::Upload(*service, ids[i], SamplePoints(*surfaces[i], counts[i], i + 1),
                                    10, &response);
    });
  }
  for (std::thread& t : threads) t.join();
  threads.clear();
  for (int i = 0; i < kSessions; ++i) ASSERT_TRUE(statuses[i].ok()) << statuses[i].error_message();

  absl::SleepFor(absl::Milliseconds(300));
  for (int i = 0; i < kSessions; ++i) {
    v1::Session session = testing::GetSession(*service, ids[i]);
    EXPECT_EQ(session.learning().points_received(), counts[i]) << "session " << i;
    EXPECT_GT(session.learning().basic_steps(), 0u)
        << "session " << i << " made no progress while 7 others learned";
  }

  std::vector<v1::MeshUpdate> finals(kSessions);
  for (int i = 0; i < kSessions; ++i) {
    threads.emplace_back([&, i] {
      statuses[i] = testing::Finish(*service, ids[i]);
      if (statuses[i].ok()) statuses[i] = testing::WaitFinal(*service, ids[i], &finals[i]);
    });
  }
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < kSessions; ++i) {
    ASSERT_TRUE(statuses[i].ok()) << "session " << i << ": " << statuses[i].error_message()
                                  << "\n" << testing::GetSession(*service, ids[i]).DebugString();
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

// A server whose sessions may take batches of a million points, and sessions that filter
// outliers: filtering a batch of 300,000 takes 0.8-3 s.
class FilteringServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.limits.max_batch_points = 1000000;
    server_ = testing::StartServer(false, options);
    ASSERT_NE(server_, nullptr);
    service_ = testing::InProcessService(*server_);
  }

  std::string FilteredSession() {
    v1::CreateSessionRequest create = testing::CreateRequest(1000);
    create.mutable_config()->mutable_points_per_vertex()->set_value(300);
    create.mutable_config()->mutable_outlier_removal();
    return testing::MustCreate(*service_, create);
  }

  std::unique_ptr<ReconstructionServer> server_;
  std::unique_ptr<v1::ReconstructionService::Stub> service_;
};

// Filtering a batch for outliers takes seconds for a few hundred thousand points. gRPC runs
// every reaction of the server on a few threads of its own, so were the filter run there,
// four such uploads would hold up every other call (a GetSession waited 20 s behind three
// uploads of a million points): batches of sessions that filter outliers are ingested on the
// server's filter executor instead. Four uploads of 300,000 points each take about 2 s of
// filtering each, one after the other on the filter thread; meanwhile another session's calls
// are answered at once.
TEST_F(FilteringServiceTest, FilteringOutliersDoesNotHoldUpOtherCalls) {
  const PointCloud points = testing::SpherePoints(300000, 31);
  const std::string other = testing::MustCreate(*service_, testing::CreateRequest(100));

  constexpr int kUploads = 4;
  std::vector<std::thread> uploads;
  std::vector<grpc::Status> statuses(kUploads);
  std::vector<v1::UploadPointsResponse> responses(kUploads);
  for (int i = 0; i < kUploads; ++i) {
    const std::string id = FilteredSession();
    uploads.emplace_back(
        [&, i, id] { statuses[i] = testing::Upload(*service_, id, points, 1, &responses[i]); });
  }
  absl::SleepFor(absl::Milliseconds(500));  // The uploads have arrived and are being filtered.
  absl::Duration slowest;
  for (int probe = 0; probe < 5; ++probe) {
    const absl::Time start = absl::Now();
    grpc::Status status;
    testing::GetSession(*service_, other, &status);
    ASSERT_TRUE(status.ok()) << status.error_message();
    v1::UploadPointsResponse response;
    ASSERT_TRUE(
        testing::Upload(*service_, other, testing::SpherePoints(500, probe), 1, &response).ok());
    slowest = std::max(slowest, absl::Now() - start);
    absl::SleepFor(absl::Milliseconds(100));
  }
  // Filtered on gRPC's threads, the slowest probe took 1.4 s; off them, 1-3 ms.
  EXPECT_LT(slowest, absl::Milliseconds(500)) << "another session's calls waited behind the filter";
  for (std::thread& t : uploads) t.join();
  for (int i = 0; i < kUploads; ++i) {
    ASSERT_TRUE(statuses[i].ok()) << statuses[i].error_message();
    EXPECT_EQ(responses[i].points_accepted() + responses[i].points_held_back(), 300000u);
  }
}

// The call may end while its batch is being filtered off gRPC's threads: the session deleted,
// or the server shutting down. The call ends with the reason at once, and the reactor lives
// until the filter is done with it (run these under AddressSanitizer to see that it does).
TEST_F(FilteringServiceTest, CallsEndWhileTheirBatchIsFiltered) {
  // Filtering takes 5-11 us a point on one core: a million points, at least 2.5 s in one
  // batch and 1.2 s in each of two, outlast the 0.8 s waits below even in a fast phase of the
  // machine (300,000 points were done within them once, and the upload ended OK).
  const PointCloud points = testing::SpherePoints(1000000, 32);

  const std::string deleted = FilteredSession();
  grpc::Status deleted_status;
  std::thread upload([&] {
    v1::UploadPointsResponse response;
    deleted_status = testing::Upload(*service_, deleted, points, 1, &response);
  });
  absl::SleepFor(absl::Milliseconds(800));  // The batch is being filtered.
  ASSERT_TRUE(testing::Delete(*service_, deleted).ok());
  upload.join();
  // NOT_FOUND from the deletion; FAILED_PRECONDITION if the batch reached the session after.
  EXPECT_TRUE(deleted_status.error_code() == grpc::StatusCode::NOT_FOUND ||
              deleted_status.error_code() == grpc::StatusCode::FAILED_PRECONDITION)
      << deleted_status.error_code() << ": " << deleted_status.error_message();

  const std::string shut_down = FilteredSession();
  grpc::Status shut_down_status;
  std::thread last_upload([&] {
    v1::UploadPointsResponse response;
    shut_down_status = testing::Upload(*service_, shut_down, points, 2, &response);
  });
  absl::SleepFor(absl::Milliseconds(800));
  server_->Shutdown(absl::Seconds(1));
  last_upload.join();
  EXPECT_TRUE(shut_down_status.error_code() == grpc::StatusCode::UNAVAILABLE ||
              shut_down_status.error_code() == grpc::StatusCode::FAILED_PRECONDITION)
      << shut_down_status.error_code() << ": " << shut_down_status.error_message();
}

}  // namespace
}  // namespace neuralmesh::server
