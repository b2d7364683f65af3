#include "server/session.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "absl/synchronization/mutex.h"
#include "core/analysis/geometric_error.h"
#include "core/io/draco_codec.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/sample_points.h"
#include "tests/server/server_test_support.h"

namespace neuralmesh::server {
namespace {

using ::testing::HasSubstr;

// Records every update and the close of a session's channel.
class Recorder : public UpdateSubscriber {
 public:
  void OnUpdate(const MeshUpdatePtr& update) override {
    absl::MutexLock lock(&mu_);
    updates_.push_back(update);
  }
  void OnClose(const absl::Status& status) override {
    absl::MutexLock lock(&mu_);
    closed_ = status;
  }
  // Waits for the close; returns its status (DEADLINE_EXCEEDED after `timeout`).
  absl::Status AwaitClose(absl::Duration timeout = absl::Seconds(60)) {
    absl::MutexLock lock(&mu_);
    auto done = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return closed_.has_value(); };
    if (!mu_.AwaitWithTimeout(absl::Condition(&done), timeout)) {
      return absl::DeadlineExceededError("the session did not end");
    }
    return *closed_;
  }
  // Waits until an update satisfies `pred`.
  MeshUpdatePtr AwaitUpdate(std::function<bool(const v1::MeshUpdate&)> pred,
                            absl::Duration timeout = absl::Seconds(30)) {
    absl::MutexLock lock(&mu_);
    auto found = [&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
      for (const auto& u : updates_) {
        if (pred(*u)) return true;
      }
      return false;
    };
    if (!mu_.AwaitWithTimeout(absl::Condition(&found), timeout)) return nullptr;
    for (const auto& u : updates_) {
      if (pred(*u)) return u;
    }
    return nullptr;
  }
  std::vector<MeshUpdatePtr> updates() {
    absl::MutexLock lock(&mu_);
    return updates_;
  }

 private:
  absl::Mutex mu_;
  std::vector<MeshUpdatePtr> updates_ ABSL_GUARDED_BY(mu_);
  std::optional<absl::Status> closed_ ABSL_GUARDED_BY(mu_);
};

class SessionTest : public ::testing::Test {
 protected:
  std::shared_ptr<Session> NewSession(SessionConfig config, size_t max_points = 1 << 22) {
    absl::Status status = ResolveSessionConfig(max_points, config);
    EXPECT_TRUE(status.ok()) << status;
    auto session = std::make_shared<Session>("s-test", "test", std::move(config), max_points,
                                             &pool_, &encoder_,
                                             std::make_shared<EventLog>(events_.Sink()));
    handles_.push_back(session->updates().Subscribe(&recorder_, 0));
    return session;
  }

  // Stops the threads before the recorder they publish to goes away.
  void TearDown() override {
    pool_.Shutdown();
    encoder_.Shutdown();
  }

  WorkerPool pool_{2, absl::Milliseconds(10)};
  Executor encoder_{1};
  Recorder recorder_;
  testing::CapturedEvents events_;
  std::vector<uint64_t> handles_;
};

PointCloud Torus(size_t n, uint64_t seed) {
  auto torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.4);
  return SamplePoints(**torus, n, seed);
}

TEST_F(SessionTest, PublishesMilestonesWithGrowingVertexCountsThenTheFinalMesh) {
  SessionConfig config;
  config.target_vertices = 300;
  auto session = NewSession(config);
  const PointCloud points = Torus(6000, 1);
  for (size_t b = 0; b < 10; ++b) {
    ASSERT_TRUE(session->AddPoints(PointRange(points, b * 600, (b + 1) * 600)).ok());
  }
  ASSERT_TRUE(session->Finish().ok());
  EXPECT_TRUE(recorder_.AwaitClose().ok()) << "the session ends with OK after the final mesh";
  EXPECT_EQ(session->state(), v1::SESSION_STATE_FINISHED);

  std::vector<MeshUpdatePtr> updates = recorder_.updates();
  ASSERT_GE(updates.size(), 4u);
  std::vector<uint64_t> milestones;
  for (size_t i = 0; i < updates.size(); ++i) {
    EXPECT_EQ(updates[i]->sequence(), i + 1) << "sequence numbers count the published meshes";
    if (updates[i]->kind() == v1::UPDATE_KIND_MILESTONE) {
      EXPECT_EQ(updates[i]->vertex_count(), updates[i]->lod_milestone())
          << "a milestone mesh has exactly the milestone's vertex count";
      milestones.push_back(updates[i]->lod_milestone());
    }
    absl::StatusOr<TriangleMesh> mesh = DecodeMesh(updates[i]->draco_mesh());
    ASSERT_TRUE(mesh.ok()) << "update " << i << " does not decode: " << mesh.status();
  }
  EXPECT_EQ(milestones, std::vector<uint64_t>({50, 100, 200}));
  const v1::MeshUpdate& last = *updates.back();
  EXPECT_EQ(last.kind(), v1::UPDATE_KIND_FINAL);
  EXPECT_EQ(last.vertex_count(), 300u) << "the final mesh meets the target exactly";
  EXPECT_EQ(last.state(), v1::SESSION_STATE_FINISHED);
  EXPECT_EQ(last.learning().points_received(), 6000u);
  EXPECT_GT(last.learning().steps_per_second(), 0);
}

TEST_F(SessionTest, TheMeshNeverOutgrowsThePointsReceivedAndGrowsWithMore) {
  SessionConfig config;
  config.target_vertices = 1000;
  config.points_per_vertex = 4;
  config.refresh_interval = absl::Milliseconds(10);
  auto session = NewSession(config);
  const PointCloud points = Torus(4000, 2);
  ASSERT_TRUE(session->AddPoints(PointRange(points, 0, 400)).ok());
  // 400 points at 4 per vertex allow 100 vertices: learning pauses there.
  MeshUpdatePtr at_cap =
      recorder_.AwaitUpdate([](const v1::MeshUpdate& u) { return u.vertex_count() == 100; });
  ASSERT_NE(at_cap, nullptr) << "learning should reach the 100 vertices 400 points allow";
  absl::SleepFor(absl::Milliseconds(100));
  for (const MeshUpdatePtr& u : recorder_.updates()) {
    EXPECT_LE(u->vertex_count(), 100u) << "more vertices than 400 points support";
  }
  EXPECT_EQ(session->ToProto().learning().allowed_vertices(), 100u);

  ASSERT_TRUE(session->AddPoints(PointRange(points, 400, 2000)).ok());
  MeshUpdatePtr grown =
      recorder_.AwaitUpdate([](const v1::MeshUpdate& u) { return u.vertex_count() >= 500; });
  ASSERT_NE(grown, nullptr) << "more points must let the mesh grow to 500 vertices";
  for (const MeshUpdatePtr& u : recorder_.updates()) EXPECT_LE(u->vertex_count(), 500u);
}

TEST_F(SessionTest, BadBatchesAreRejectedAndTheSessionKeepsItsPoints) {
  SessionConfig config;
  config.target_vertices = 50;
  auto session = NewSession(config, /*max_points=*/1000);
  const PointCloud points = Torus(1000, 3);
  ASSERT_TRUE(session->AddPoints(PointRange(points, 0, 300)).ok());

  PointCloud nan = PointRange(points, 300, 310);
  nan.positions[4][1] = std::nanf("");
  absl::StatusOr<size_t> result = session->AddPoints(nan);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument) << result.status();
  EXPECT_THAT(std::string(result.status().message()),
              HasSubstr("point 4 of the batch has a non-finite coordinate"));

  PointCloud inf = PointRange(points, 300, 310);
  inf.positions[0][0] = INFINITY;
  EXPECT_EQ(session->AddPoints(inf).status().code(), absl::StatusCode::kInvalidArgument);

  PointCloud mismatched = PointRange(points, 300, 310);
  mismatched.weights = {1, 2};
  EXPECT_EQ(session->AddPoints(mismatched).status().code(), absl::StatusCode::kInvalidArgument);

  result = session->AddPoints(PointRange(points, 0, 800));  // 300 + 800 > 1000.
  EXPECT_EQ(result.status().code(), absl::StatusCode::kResourceExhausted) << result.status();

  EXPECT_EQ(session->points_received(), 300u) << "rejected batches add nothing";
  ASSERT_TRUE(session->AddPoints(PointRange(points, 300, 600)).ok()) << "the session goes on";
  ASSERT_TRUE(session->Finish().ok());
  EXPECT_TRUE(recorder_.AwaitClose().ok());
  EXPECT_EQ(session->AddPoints(PointRange(points, 0, 10)).status().code(),
            absl::StatusCode::kFailedPrecondition)
      << "a finished session takes no points";
  EXPECT_EQ(session->Finish().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(session->Cancel("late").code(), absl::StatusCode::kFailedPrecondition);
  const std::vector<std::string> events = events_.lines();
  ASSERT_EQ(events.size(), 1u) << "one end, and refused calls are no events";
  EXPECT_THAT(events[0], ::testing::MatchesRegex(
                             ".* session s-test finished: 50 vertices, [0-9]+ faces, genus -?[0-9]+, "
                             "[0-9]+ boundaries, [0-9]+ Basic Steps in [0-9.]+ s of learning, 600 "
                             "points"));
}

TEST_F(SessionTest, BatchesSentAgainAddOnlyWhatTheSessionLacks) {
  SessionConfig config;
  config.target_vertices = 50;
  auto session = NewSession(config);
  const PointCloud points = Torus(1000, 4);
  size_t skipped = 0;
  ASSERT_TRUE(session->AddPoints(PointRange(points, 0, 300), nullptr, 0, &skipped).ok());
  EXPECT_EQ(skipped, 0u);
  // After a lost connection the client sends from 200 again: 100 points it had already.
  absl::StatusOr<size_t> total = session->AddPoints(PointRange(points, 200, 500), nullptr, 200, &skipped);
  ASSERT_TRUE(total.ok()) << total.status();
  EXPECT_EQ(skipped, 100u);
  EXPECT_EQ(*total, 500u);
  total = session->AddPoints(PointRange(points, 0, 100), nullptr, 0, &skipped);
  ASSERT_TRUE(total.ok()) << total.status();
  EXPECT_EQ(skipped, 100u) << "all of it known: nothing added";
  EXPECT_EQ(*total, 500u);
  // A gap is refused and changes nothing.
  total = session->AddPoints(PointRange(points, 600, 700), nullptr, 600, &skipped);
  EXPECT_EQ(total.status().code(), absl::StatusCode::kOutOfRange) << total.status();
  EXPECT_THAT(std::string(total.status().message()), HasSubstr("send from point 500"));
  EXPECT_EQ(session->ToProto().points_taken(), 500u);
  // Without a place, every point is new.
  ASSERT_TRUE(session->AddPoints(PointRange(points, 500, 600)).ok());
  EXPECT_EQ(session->ToProto().points_taken(), 600u);
  EXPECT_EQ(session->points_received(), 600u);
  // The points are those of the upload, each once, in order.
  ASSERT_TRUE(session->Finish().ok());
  EXPECT_TRUE(recorder_.AwaitClose().ok());
  EXPECT_EQ(session->ToProto().learning().points_received(), 600u);
}

TEST_F(SessionTest, PointsTakenCountOutliersHeldBack) {
  SessionConfig config;
  config.target_vertices = 50;
  config.outlier_removal = OutlierOptions();
  auto session = NewSession(config);
  PointCloud batch = Torus(2000, 6);
  batch.positions.push_back(Vec3f(0, 0, 100));  // A stray far off the torus.
  size_t held = 0;
  ASSERT_TRUE(session->AddPoints(batch, &held, 0).ok());
  EXPECT_EQ(held, 1u);
  EXPECT_EQ(session->points_received(), 2000u);
  EXPECT_EQ(session->ToProto().points_taken(), 2001u) << "the stray was taken, and held";
  size_t skipped = 0;
  ASSERT_TRUE(session->AddPoints(batch, &held, 0, &skipped).ok());
  EXPECT_EQ(skipped, 2001u);
  EXPECT_EQ(held, 0u) << "nothing judged twice";
  EXPECT_EQ(session->ToProto().learning().outliers_held(), 1u);
}

// With outlier removal the session keeps every point received, dropped ones too (they are
// the neighbours later batches are judged against), so they count toward its point limit: a
// client sending only outliers cannot grow it without bound.
TEST_F(SessionTest, OutliersCountTowardThePointLimit) {
  SessionConfig config;
  config.target_vertices = 50;
  config.outlier_removal = OutlierOptions{};
  auto session = NewSession(config, /*max_points=*/1000);
  const PointCloud points = Torus(990, 3);
  size_t removed = 0;
  ASSERT_TRUE(session->AddPoints(points, &removed).ok());
  const size_t accepted = session->points_received();
  EXPECT_EQ(accepted + removed, 990u);
  for (int i = 1; i <= 10; ++i) {
    PointCloud stray;
    stray.positions.emplace_back(1000.f * static_cast<float>(i), 0.f, 0.f);
    ASSERT_TRUE(session->AddPoints(stray, &removed).ok());
    EXPECT_EQ(removed, 1u) << "stray " << i;
  }
  EXPECT_EQ(session->points_received(), accepted);
  const absl::StatusOr<size_t> full = session->AddPoints(PointRange(points, 0, 1));
  EXPECT_EQ(full.status().code(), absl::StatusCode::kResourceExhausted) << full.status();
  EXPECT_THAT(std::string(full.status().message()), HasSubstr("outliers included"));
  EXPECT_EQ(session->points_received(), accepted) << "the refused batch adds nothing";
}

// Coordinates so large that no quantization cube Draco can encode holds them: the batch is
// refused at once (growing the cube toward them never ended before, with the session locked),
// and the session goes on with its points. Slightly smaller ones still fit a usable cube.
TEST_F(SessionTest, ABatchNoQuantizationCubeCanHoldIsRefused) {
  SessionConfig config;
  config.target_vertices = 50;
  auto session = NewSession(config);
  const PointCloud points = Torus(1000, 3);
  ASSERT_TRUE(session->AddPoints(PointRange(points, 0, 300)).ok());
  for (const float far : {3.3e38f, 1.8e38f}) {
    PointCloud huge = PointRange(points, 300, 310);
    huge.positions[2] = Vec3f(far, -far, far);
    const absl::StatusOr<size_t> result = session->AddPoints(huge);
    EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument)
        << far << ": " << result.status();
  }
  EXPECT_EQ(session->points_received(), 300u) << "refused batches add nothing";
  ASSERT_TRUE(session->AddPoints(PointRange(points, 300, 600)).ok()) << "the session goes on";
  PointCloud large = PointRange(points, 600, 610);
  large.positions[2] = Vec3f(1e38f, -1e38f, 1e38f);
  EXPECT_TRUE(session->AddPoints(large).ok()) << "a cube of range 2e38 is still usable";
  EXPECT_EQ(session->points_received(), 610u);
  ASSERT_TRUE(session->Cancel("done").ok());
}

TEST_F(SessionTest, ATinyPointsPerVertexAllowsTheWholeTarget) {
  SessionConfig config;
  config.target_vertices = 60;
  config.points_per_vertex = 1e-18;  // 300 / 1e-18 is far beyond any size_t.
  auto session = NewSession(config);
  ASSERT_TRUE(session->AddPoints(Torus(300, 4)).ok());
  EXPECT_EQ(session->ToProto().learning().allowed_vertices(), 60u);
  ASSERT_TRUE(session->Finish().ok());
  EXPECT_TRUE(recorder_.AwaitClose().ok());
  EXPECT_EQ(recorder_.updates().back()->vertex_count(), 60u);
}

TEST_F(SessionTest, FinishNeedsPointsForATetrahedron) {
  SessionConfig config;
  config.target_vertices = 100;
  auto session = NewSession(config);
  ASSERT_TRUE(session->AddPoints(PointRange(Torus(7, 4), 0, 7)).ok());
  absl::Status status = session->Finish();
  EXPECT_EQ(status.code(), absl::StatusCode::kFailedPrecondition) << status;
  EXPECT_THAT(std::string(status.message()), HasSubstr("at least 8"));
  EXPECT_EQ(session->state(), v1::SESSION_STATE_COLLECTING) << "still collecting";
}

TEST_F(SessionTest, CancelStopsLearningAndEndsWatchersWithCancelled) {
  SessionConfig config;
  config.target_vertices = 200000;
  auto session = NewSession(config);
  ASSERT_TRUE(session->AddPoints(Torus(400000, 5)).ok());
  ASSERT_NE(recorder_.AwaitUpdate([](const v1::MeshUpdate& u) { return true; }), nullptr);
  ASSERT_TRUE(session->Cancel("test").ok());
  EXPECT_EQ(recorder_.AwaitClose(absl::Seconds(5)).code(), absl::StatusCode::kCancelled);
  EXPECT_TRUE(session->Cancel("again").ok()) << "cancelling twice is a no-op";
  ASSERT_EQ(events_.lines().size(), 1u) << "recorded once";
  EXPECT_THAT(events_.lines()[0], ::testing::EndsWith("session s-test cancelled: test"));
  EXPECT_EQ(session->Finish().code(), absl::StatusCode::kFailedPrecondition);
  // The slice that was running stops at the learner's next poll and leaves the pool.
  const absl::Time deadline = absl::Now() + absl::Seconds(5);
  while (pool_.active_tasks() > 0 && absl::Now() < deadline) absl::SleepFor(absl::Milliseconds(1));
  EXPECT_EQ(pool_.active_tasks(), 0u) << "a cancelled session must leave the worker pool";
  // The last slice's progress may be published just after it leaves the pool; once two
  // readings 100 ms apart agree, the count must stay put.
  uint64_t steps = session->ToProto().learning().basic_steps();
  for (const absl::Time settle = absl::Now() + absl::Seconds(5); absl::Now() < settle;) {
    absl::SleepFor(absl::Milliseconds(100));
    const uint64_t now = session->ToProto().learning().basic_steps();
    if (now == steps) break;
    steps = now;
  }
  absl::SleepFor(absl::Milliseconds(300));
  EXPECT_EQ(session->ToProto().learning().basic_steps(), steps) << "learning goes on";
  EXPECT_EQ(session->ToProto().error(), "test");
}

TEST_F(SessionTest, AllMeshesShareOneQuantizationBoxUntilDataFallsOutside) {
  SessionConfig config;
  config.target_vertices = 200;
  auto session = NewSession(config);
  const PointCloud points = Torus(4000, 6);
  for (size_t b = 0; b < 4; ++b) {
    ASSERT_TRUE(session->AddPoints(PointRange(points, b * 1000, (b + 1) * 1000)).ok());
  }
  ASSERT_NE(recorder_.AwaitUpdate([](const v1::MeshUpdate& u) { return u.vertex_count() >= 100; }),
            nullptr);
  std::vector<MeshUpdatePtr> updates = recorder_.updates();
  for (const MeshUpdatePtr& u : updates) {
    EXPECT_EQ(u->quantization_epoch(), 0u);
    EXPECT_EQ(u->quantization_box().SerializeAsString(),
              updates.front()->quantization_box().SerializeAsString())
        << "every mesh of the epoch is quantized against the first box";
  }
  // The first batch spans about [-1.4, 1.4]^2 x [-0.4, 0.4]; its cube is enlarged 2x.
  EXPECT_NEAR(updates.front()->quantization_box().range(), 5.6, 0.3);

  PointCloud far;
  far.positions = {Vec3f(10, 0, 0)};
  ASSERT_TRUE(session->AddPoints(far).ok());
  const v1::Session proto = session->ToProto();
  EXPECT_GE(proto.quantization_box().origin_x() + proto.quantization_box().range(), 10.0f)
      << "the cube grows to hold data outside it";
}

// Draco receives a fixed box as text with six decimals: a torus 3e-7 across used to reach it
// in a box of edge 0, and every mesh failed to encode. The session's box is one Draco keeps
// exactly, so such data streams meshes whose vertices decode inside that box.
TEST_F(SessionTest, DataOfTinyExtentStillStreamsMeshes) {
  SessionConfig config;
  config.target_vertices = 200;
  auto session = NewSession(config);
  PointCloud points = Torus(4000, 7);
  for (Vec3f& p : points.positions) p *= 1e-7f;
  ASSERT_TRUE(session->AddPoints(points).ok());
  ASSERT_TRUE(session->Finish().ok());
  ASSERT_TRUE(recorder_.AwaitClose().ok());
  const std::vector<MeshUpdatePtr> updates = recorder_.updates();
  ASSERT_FALSE(updates.empty());
  const v1::MeshUpdate& last = *updates.back();
  EXPECT_EQ(last.kind(), v1::UPDATE_KIND_FINAL);
  const QuantizationBox box{Vec3f(last.quantization_box().origin_x(),
                                  last.quantization_box().origin_y(),
                                  last.quantization_box().origin_z()),
                            last.quantization_box().range()};
  const QuantizationBox exact = DracoExactBox(box);
  EXPECT_EQ(exact.origin, box.origin) << "the announced box is not one Draco keeps exactly";
  EXPECT_EQ(exact.range, box.range) << "the announced box is not one Draco keeps exactly";
  const absl::StatusOr<TriangleMesh> mesh = DecodeMesh(last.draco_mesh());
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_GE(mesh->positions.size(), 50u);
  for (const Vec3f& p : mesh->positions) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_GE(p[c], box.origin[c] - 1e-12f);
      EXPECT_LE(p[c], box.origin[c] + box.range + 1e-12f);
    }
  }
}

// A session whose learner stalls on 2,000 torus points.
SessionConfig StallingConfig() {
  SessionConfig config;
  config.target_vertices = 100;
  config.learner.c_ec = 0.01;  // Step 3 after every Basic Step: collapses win over splits.
  config.learner.c_vs = 10;
  return config;
}

TEST_F(SessionTest, AStalledLearnerFailsTheSessionInsteadOfSpinning) {
  auto session = NewSession(StallingConfig());
  ASSERT_TRUE(session->AddPoints(Torus(2000, 9)).ok());
  ASSERT_TRUE(session->Finish().ok());
  absl::Status status = recorder_.AwaitClose();
  EXPECT_EQ(status.code(), absl::StatusCode::kInternal) << status;
  EXPECT_THAT(std::string(status.message()), HasSubstr("stalled"));
  EXPECT_EQ(session->state(), v1::SESSION_STATE_FAILED);
  EXPECT_THAT(session->ToProto().error(), HasSubstr("stalled"));
  // Before the finish, learning may have paused (a "paused" event) as a stall while
  // collecting does.
  ASSERT_FALSE(events_.lines().empty());
  EXPECT_THAT(events_.lines().back(), HasSubstr("session s-test failed: learning stalled"));
}

// A client that lost its connection after a few points may resume the upload: a session whose
// learner stalls while it still collects points waits for more (without spinning), learns on
// when they come, and fails only once it is finishing.
TEST_F(SessionTest, AStallWhileCollectingWaitsForPointsInsteadOfFailing) {
  auto session = NewSession(StallingConfig());
  ASSERT_TRUE(session->AddPoints(Torus(2000, 9)).ok());
  const auto learning = [&] { return session->ToProto().learning(); };
  for (int i = 0; i < 500 && !learning().stalled(); ++i) absl::SleepFor(absl::Milliseconds(20));
  ASSERT_TRUE(learning().stalled()) << "the learner did not stall";
  EXPECT_EQ(session->state(), v1::SESSION_STATE_LEARNING);
  const uint64_t steps = learning().basic_steps();
  absl::SleepFor(absl::Milliseconds(300));
  EXPECT_EQ(learning().basic_steps(), steps) << "a stalled session spins";
  ASSERT_EQ(events_.lines().size(), 1u);
  EXPECT_THAT(events_.lines()[0],
              HasSubstr("session s-test paused: learning stalled: the mesh has not grown past "));
  EXPECT_THAT(events_.lines()[0], HasSubstr("; waiting for points past 2000"));

  ASSERT_TRUE(session->AddPoints(Torus(500, 10)).ok());
  for (int i = 0; i < 500 && learning().basic_steps() == steps; ++i) {
    absl::SleepFor(absl::Milliseconds(20));
  }
  EXPECT_GT(learning().basic_steps(), steps) << "new points did not wake the learner";
  EXPECT_EQ(session->state(), v1::SESSION_STATE_LEARNING);

  ASSERT_TRUE(session->Finish().ok());
  const absl::Status status = recorder_.AwaitClose();
  EXPECT_EQ(status.code(), absl::StatusCode::kInternal) << status;
  EXPECT_EQ(session->state(), v1::SESSION_STATE_FAILED);
  EXPECT_THAT(session->ToProto().error(), HasSubstr("stalled"));
}

TEST(IsSpatiallyBiasedTest, RandomOrderIsNotBiasedAScanIs) {
  const PointCloud random = Torus(20000, 7);
  EXPECT_FALSE(IsSpatiallyBiased(random.positions));
  std::vector<Vec3f> scan = random.positions;
  std::sort(scan.begin(), scan.end(),
            [](const Vec3f& a, const Vec3f& b) { return std::atan2(a[1], a[0]) < std::atan2(b[1], b[0]); });
  EXPECT_TRUE(IsSpatiallyBiased(scan)) << "points sorted by angle arrive region after region";
  EXPECT_TRUE(IsSpatiallyBiased(absl::MakeSpan(scan).subspan(0, 100)))
      << "too few points to tell count as biased";
}

TEST_F(SessionTest, ScanOrderEndsAsGoodAsRandomOrder) {
  auto torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.4);
  const PointCloud random = SamplePoints(**torus, 20000, 8);
  PointCloud scan = random;
  std::sort(scan.positions.begin(), scan.positions.end(), [](const Vec3f& a, const Vec3f& b) {
    return std::atan2(a[1], a[0]) < std::atan2(b[1], b[0]);
  });

  auto run = [&](const PointCloud& cloud, uint64_t seed) -> TriangleMesh {
    Recorder recorder;
    SessionConfig config;
    config.target_vertices = 1000;
    config.learner.seed = seed;
    EXPECT_TRUE(ResolveSessionConfig(1 << 20, config).ok());
    auto session =
        std::make_shared<Session>("s", "", config, size_t{1} << 20, &pool_, &encoder_);
    const uint64_t handle = session->updates().Subscribe(&recorder, 0);
    for (size_t b = 0; b < 50; ++b) {
      EXPECT_TRUE(session->AddPoints(PointRange(cloud, b * 400, (b + 1) * 400)).ok());
      absl::SleepFor(absl::Milliseconds(2));  // Let learning follow the scan.
    }
    EXPECT_TRUE(session->Finish().ok());
    EXPECT_TRUE(recorder.AwaitClose().ok());
    session->updates().Unsubscribe(handle);
    absl::StatusOr<TriangleMesh> mesh = DecodeMesh(recorder.updates().back()->draco_mesh());
    EXPECT_TRUE(mesh.ok());
    return mesh.ok() ? *mesh : TriangleMesh();
  };
  // One reconstruction of 1,000 vertices is at the mercy of its seed (a handle that forms a
  // few calls late costs twice the error), so each order is judged by its median Chamfer-L1
  // distance over three seeds.
  const TriangleMesh reference = (*torus)->ReferenceMesh(16);
  GeometricErrorOptions options;
  options.samples = 20000;
  options.threads = 1;
  auto median_error = [&](const PointCloud& cloud) -> GeometricError {
    std::vector<GeometricError> errors;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      absl::StatusOr<GeometricError> error =
          ComputeGeometricError(run(cloud, seed), reference, options);
      EXPECT_TRUE(error.ok()) << error.status();
      if (error.ok()) errors.push_back(*error);
    }
    if (errors.size() != 3) return GeometricError{};
    auto by = [&](auto field) {
      std::vector<double> values;
      for (const GeometricError& e : errors) values.push_back(e.*field);
      std::sort(values.begin(), values.end());
      return values[1];
    };
    GeometricError median = errors[0];
    median.chamfer_l1 = by(&GeometricError::chamfer_l1);
    return median;
  };
  const GeometricError random_error = median_error(random);
  const GeometricError scan_error = median_error(scan);
  ASSERT_GT(random_error.chamfer_l1, 0) << "the random-order runs must produce meshes";
  EXPECT_LT(scan_error.chamfer_l1, 1.25 * random_error.chamfer_l1 + 1e-3)
      << "scan order: " << scan_error.chamfer_l1 << ", random order: " << random_error.chamfer_l1;
  // No Hausdorff bound: in either order a run now and then keeps a fin of a few vertices off
  // the surface for a while (Hausdorff 0.03-0.13 of the diagonal at 2,000 vertices, random
  // order included), so the maximum says more about the seed than about the order.
}

}  // namespace
}  // namespace neuralmesh::server
