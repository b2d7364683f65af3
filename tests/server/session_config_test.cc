#include "server/session_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace neuralmesh::server {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(DefaultLodMilestonesTest, OneTwoFiveSeriesFrom50UpToTheTarget) {
  EXPECT_THAT(DefaultLodMilestones(2000), ElementsAre(50, 100, 200, 500, 1000, 2000))
      << "the default schedule is the 1-2-5 series from 50 below the target, then the target";
  EXPECT_THAT(DefaultLodMilestones(1500), ElementsAre(50, 100, 200, 500, 1000, 1500));
  EXPECT_THAT(DefaultLodMilestones(4), ElementsAre(4)) << "a tiny target is its only milestone";
  EXPECT_THAT(DefaultLodMilestones(20), ElementsAre(20))
      << "no milestone below 50: meshes that small exceed 8 bytes per vertex";
  EXPECT_THAT(DefaultLodMilestones(50), ElementsAre(50));
  EXPECT_THAT(DefaultLodMilestones(51), ElementsAre(50, 51));
  EXPECT_THAT(DefaultLodMilestones(20000000),
              ElementsAre(50, 100, 200, 500, 1000, 2000, 5000, 10000, 20000, 50000, 100000, 200000,
                          500000, 1000000, 2000000, 5000000, 10000000, 20000000));
}

SessionConfig Valid() {
  SessionConfig config;
  config.target_vertices = 1000;
  return config;
}

TEST(ResolveSessionConfigTest, FillsDefaultMilestonesAndAppendsTheTarget) {
  SessionConfig config = Valid();
  ASSERT_TRUE(ResolveSessionConfig(1 << 20, config).ok());
  EXPECT_THAT(config.lod_milestones, ElementsAre(50, 100, 200, 500, 1000));

  config = Valid();
  config.lod_milestones = {50, 300};
  ASSERT_TRUE(ResolveSessionConfig(1 << 20, config).ok());
  EXPECT_THAT(config.lod_milestones, ElementsAre(50, 300, 1000))
      << "the target ends every schedule";
}

TEST(ResolveSessionConfigTest, RejectsInvalidOptionsNamingTheField) {
  struct Case {
    const char* what;
    void (*mutate)(SessionConfig&);
    const char* message;
  };
  const Case cases[] = {
      {"target below 4", [](SessionConfig& c) { c.target_vertices = 3; }, "target_vertices"},
      // Found by fuzz/session_config_fuzzer.cc: with a tiny points_per_vertex the point limit
      // allowed it, and the default milestones overflowed past 2^64 into a disorder.
      {"target near 2^64",
       [](SessionConfig& c) {
         c.target_vertices = 18446744073680191486u;
         c.points_per_vertex = 1e-264;
       },
       "target_vertices"},
      {"alpha_w zero", [](SessionConfig& c) { c.learner.alpha_w = 0; }, "alpha_w"},
      {"alpha_w above 1", [](SessionConfig& c) { c.learner.alpha_w = 1.5; }, "alpha_w"},
      {"milestones not increasing",
       [](SessionConfig& c) {
         c.lod_milestones = {100, 50};
       },
       "lod_milestones[1]"},
      {"milestone above target", [](SessionConfig& c) { c.lod_milestones = {2000}; },
       "lod_milestones[0]"},
      {"milestone below 4", [](SessionConfig& c) { c.lod_milestones = {2}; }, "lod_milestones[0]"},
      {"points_per_vertex zero", [](SessionConfig& c) { c.points_per_vertex = 0; },
       "points_per_vertex"},
      {"refresh too short", [](SessionConfig& c) { c.refresh_interval = absl::Milliseconds(3); },
       "refresh_interval_ms"},
      {"quantization bits", [](SessionConfig& c) { c.draco.position_quantization_bits = 0; },
       "position_quantization_bits"},
      {"colour neighbours", [](SessionConfig& c) { c.colors.neighbours = 65; },
       "color_neighbours: colour neighbours = 65"},
      {"bounds beyond what a float cube can hold",
       [](SessionConfig& c) {
         BoundingBox b;
         b.min = Vec3(-3.3e38, 0, 0);
         b.max = Vec3(3.3e38, 1, 1);
         c.bounds = b;
       },
       "bounds: points from"},
      {"origin not finite", [](SessionConfig& c) { c.origin[1] = INFINITY; },
       "origin.y is inf; it must be finite"},
      {"upload order's name too long",
       [](SessionConfig& c) {
         c.upload_order = UploadOrder{std::string(257, 'x'), 1};
       },
       "upload_order.name has 257 bytes; at most 256"},
      {"inverted bounds",
       [](SessionConfig& c) {
         BoundingBox b;
         b.min = Vec3(1, 0, 0);
         b.max = Vec3(0, 1, 1);
         c.bounds = b;
       },
       "inverted"},
  };
  for (const Case& c : cases) {
    SessionConfig config = Valid();
    c.mutate(config);
    absl::Status status = ResolveSessionConfig(1 << 20, config);
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << c.what << ": " << status;
    EXPECT_THAT(std::string(status.message()), HasSubstr(c.message))
        << c.what << ": the message should name the field";
  }
}

TEST(ResolveSessionConfigTest, RejectsATargetThePointLimitCannotReach) {
  SessionConfig config = Valid();
  config.target_vertices = 1000;
  config.points_per_vertex = 2;
  absl::Status status = ResolveSessionConfig(1999, config);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
  EXPECT_THAT(std::string(status.message()), HasSubstr("more than this server accepts"));
  config = Valid();
  EXPECT_TRUE(ResolveSessionConfig(2000, config).ok()) << "exactly reachable is fine";
}

}  // namespace
}  // namespace neuralmesh::server
