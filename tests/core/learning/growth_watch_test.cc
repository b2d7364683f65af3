#include "core/learning/growth_watch.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace neuralmesh {
namespace {

using ::testing::HasSubstr;

TEST(GrowthWatchTest, StallsOnlyAfterItsPatienceWithoutANewLargestCount) {
  const uint64_t patience = GrowthWatch::kStallSplits * 100;  // C_vs = 100.
  GrowthWatch watch(100, 4, 0);
  EXPECT_TRUE(watch.Check(10, 1000).ok());
  // Shrinking and growing back to 10 is no growth: the clock runs from step 1000.
  EXPECT_TRUE(watch.Check(8, 1000 + patience / 2).ok());
  EXPECT_TRUE(watch.Check(10, 1000 + patience).ok()) << "patience is not over yet";
  const absl::Status stalled = watch.Check(10, 1001 + patience);
  EXPECT_EQ(stalled.code(), absl::StatusCode::kFailedPrecondition) << stalled;
  EXPECT_THAT(std::string(stalled.message()), HasSubstr("has not grown past 10 vertices in"));

  GrowthWatch growing(100, 4, 0);
  for (uint64_t step = 0; step < 10 * patience; step += patience / 2) {
    EXPECT_TRUE(growing.Check(5 + step / 1000, step).ok()) << "a growing mesh never stalls";
  }
}

}  // namespace
}  // namespace neuralmesh
