// The learner samples a GrowingPointCloud while another thread appends points: the situation of
// a server session that learns while a client streams points in. Also run under ThreadSanitizer
// (ctest label "concurrency").
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "core/learning/learner.h"
#include "core/mesh_validation.h"
#include "core/sampling/growing_point_cloud.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/sample_points.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

// Learns a sphere while another thread streams its points in; `lookahead_from` as in
// Learner::SetLookaheadFromVertices (samples drawn ahead read the cloud earlier). With
// `weighted`, the batches after the first carry weights spread over many weight classes (some
// zero), so that the learner samples by weight while classes grow and new ones open.
void LearnWhilePointsStreamIn(size_t lookahead_from, bool weighted = false) {
  auto sphere = MakeSphere(Vec3(0, 0, 0), 1.0).value();
  const PointCloud all = SamplePoints(*sphere, 40000, 9);
  std::vector<float> weights(all.size());
  for (size_t i = 0; i < weights.size(); ++i) {
    weights[i] =
        i % 11 == 0 ? 0.0f : std::ldexp(1.0f + (i % 3) / 3.0f, static_cast<int>(i % 41) - 20);
  }
  GrowingPointCloud cloud;
  const size_t kBatch = 400;
  ASSERT_TRUE(cloud.Append(absl::MakeConstSpan(all.positions).subspan(0, kBatch)).ok());

  std::atomic<bool> writer_done{false};
  std::thread writer([&] {
    for (size_t start = kBatch; start < all.size(); start += kBatch) {
      const absl::Status s =
          weighted ? cloud.Append(absl::MakeConstSpan(all.positions).subspan(start, kBatch),
                                  absl::MakeConstSpan(weights).subspan(start, kBatch))
                   : cloud.Append(absl::MakeConstSpan(all.positions).subspan(start, kBatch));
      EXPECT_TRUE(s.ok()) << s;
      std::this_thread::yield();
    }
    writer_done = true;
  });

  auto learner = Learner::Create(LearnerOptions{}, &cloud).value();
  learner->SetLookaheadFromVertices(lookahead_from);
  size_t last_size = 0;
  StopCriteria stop;
  stop.target_vertices = 1500;
  stop.poll_interval = 2000;
  stop.observer = [&](const LearnerProgress&) {
    const size_t size = cloud.size();
    EXPECT_GE(size, last_size) << "the visible point count must never shrink";
    last_size = size;
    return true;
  };
  const auto reason = learner->Run(stop);
  writer.join();
  ASSERT_TRUE(reason.ok()) << reason.status();
  EXPECT_TRUE(writer_done);
  EXPECT_EQ(cloud.size(), all.size()) << "every appended point must be kept";
  EXPECT_TRUE(ValidateMesh(learner->mesh()).ok()) << ValidateMesh(learner->mesh());
  double worst = 0;
  for (auto v : learner->mesh().vertices()) {
    worst = std::max(worst, std::abs(learner->mesh().point(v).norm() - 1.0));
  }
  EXPECT_LT(worst, 0.02) << "the mesh learned from streamed points must lie on the sphere";
}

TEST(LearnerGrowingCloudConcurrentTest, LearnsWhilePointsStreamIn) {
  LearnWhilePointsStreamIn(std::numeric_limits<size_t>::max());
}

TEST(LearnerGrowingCloudConcurrentTest, LearnsWhilePointsStreamInLookingAhead) {
  LearnWhilePointsStreamIn(0);
}

TEST(LearnerGrowingCloudConcurrentTest, LearnsWhileWeightedPointsStreamIn) {
  LearnWhilePointsStreamIn(std::numeric_limits<size_t>::max(), /*weighted=*/true);
}

TEST(LearnerGrowingCloudConcurrentTest, LearnsWhileWeightedPointsStreamInLookingAhead) {
  LearnWhilePointsStreamIn(0, /*weighted=*/true);
}

}  // namespace
}  // namespace neuralmesh
