#include "core/learning/signal_counters.h"

#include <cmath>
#include <vector>

#include "core/random.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

// The paper's process done literally: each step add 1 to the winner, then multiply every
// counter by alpha_sc. The lazy log-domain counters must pick the same vertex and agree on
// the values (up to the constant factor alpha_sc that the literal order applies once more).
TEST(SignalCountersTest, MatchesTheLiteralProcess) {
  const double alpha = 0.95;
  const int n = 50;
  SignalCounters lazy(alpha);
  std::vector<double> literal(n, 0.0);
  for (int i = 0; i < n; ++i) lazy.Add(i, 0.0, 0);
  Random rng(11);
  uint64_t step = 0;
  for (int round = 0; round < 200; ++round) {
    for (int k = 0; k < 100; ++k) {
      // Skewed winners so that counters differ.
      const int w = static_cast<int>(rng.NextIndex(rng.NextDouble() < 0.5 ? 10 : n));
      ++step;
      lazy.RecordWin(w, step);
      literal[w] += 1;
      for (double& c : literal) c *= alpha;
    }
    int expected = 0;
    for (int i = 1; i < n; ++i) {
      if (literal[i] > literal[expected]) expected = i;
    }
    const int got = lazy.MostActive([](int) { return true; });
    ASSERT_EQ(got, expected) << "round " << round;
    for (int i = 0; i < n; ++i) {
      ASSERT_NEAR(lazy.Value(i, step) * alpha, literal[i], 1e-9 * (1 + literal[i]))
          << "counter " << i << " at round " << round;
    }
  }
}

TEST(SignalCountersTest, SkipsIneligibleAndForgetsRemoved) {
  SignalCounters counters(0.95);
  counters.Add(0, 5.0, 10);
  counters.Add(1, 3.0, 10);
  counters.Add(2, 1.0, 10);
  EXPECT_EQ(counters.MostActive([](int id) { return id != 0; }), 1)
      << "the best eligible counter must be chosen";
  counters.Remove(1);
  EXPECT_EQ(counters.MostActive([](int id) { return id != 0; }), 2);
  counters.RecordWin(1, 11);  // A win of a removed id is ignored.
  counters.Flush();
  EXPECT_FALSE(counters.Contains(1));
  EXPECT_EQ(counters.MostActive([](int) { return false; }), -1) << "nothing eligible";
}

TEST(SignalCountersTest, NoUnderflowAfterLongInactivity) {
  // With plain doubles, 0.95^20000 underflows to zero (the paper's c_M, Eq. 9); the
  // log-domain keys still order vertices by their last activity.
  SignalCounters counters(0.95);
  counters.Add(0, 1.0, 0);
  counters.Add(1, 1.0, 5);
  EXPECT_EQ(counters.MostActive([](int) { return true; }), 1);
  counters.Add(2, 1.0, 3);
  EXPECT_EQ(counters.Value(0, 20000), 0.0) << "the value itself underflows";
  EXPECT_EQ(counters.MostActive([](int) { return true; }), 1)
      << "but the ordering survives: 1 was active last";
}

// Many ids, with removals, splits (Set) and wins in random order, for a fast, the paper's and a
// slow decay: MostActive must always give the id with the largest counter among the eligible
// ones, as a plain scan over all values does. 30,000 touches of about 1,500 ids: the touch log
// is compacted several times on the way.
class SignalCountersScanTest : public testing::TestWithParam<double> {};

TEST_P(SignalCountersScanTest, MostActiveMatchesAScanUnderAddRemoveAndSet) {
  const double alpha = GetParam();
  const int n = 3000;
  SignalCounters counters(alpha);
  std::vector<bool> tracked(n, false);
  Random rng(5);
  uint64_t step = 0;
  for (int i = 0; i < n; i += 2) {
    counters.Add(i, rng.NextDouble(), step);
    tracked[i] = true;
  }
  auto eligible = [](int id) { return id % 7 != 0; };
  for (int round = 0; round < 300; ++round) {
    for (int k = 0; k < 100; ++k) {
      ++step;
      const int id = static_cast<int>(rng.NextIndex(n));
      if (tracked[id]) counters.RecordWin(id, step);
    }
    for (int k = 0; k < 5; ++k) {
      const int id = static_cast<int>(rng.NextIndex(n));
      if (tracked[id] && rng.NextDouble() < 0.5) {
        counters.Remove(id);
        tracked[id] = false;
      } else if (tracked[id]) {
        counters.Flush();
        counters.Set(id, counters.Value(id, step) * rng.NextDouble(), step);
      } else {
        counters.Add(id, rng.NextDouble() * 3, step);
        tracked[id] = true;
      }
    }
    const int got = counters.MostActive(eligible);
    int expected = -1;
    double best = -1;
    for (int i = 0; i < n; ++i) {
      if (!tracked[i] || !eligible(i)) continue;
      const double value = counters.Value(i, step);
      if (value > best) {
        best = value;
        expected = i;
      }
    }
    ASSERT_EQ(got, expected) << "round " << round;
    ASSERT_LE(counters.log_size(), 2 * counters.size() + 4096 + 1) << "round " << round;
  }
}

INSTANTIATE_TEST_SUITE_P(Decays, SignalCountersScanTest, testing::Values(0.5, 0.95, 0.999));

// The most active eligible vertex was last touched long before every recent winner, which are
// all ineligible: the search must walk back past them, and the log's compaction (10,000 wins
// of 10 ids) must keep the old touches.
TEST(SignalCountersTest, FindsAnOldEligibleVertexBehindIneligibleWinners) {
  const double alpha = 0.95;
  SignalCounters counters(alpha);
  const double initial[5] = {0.5, 4.0, 2.0, 3.0, 1.0};
  for (int id = 0; id < 5; ++id) counters.Add(id, initial[id], 0);
  for (int id = 5; id < 15; ++id) counters.Add(id, 1.0, 0);
  for (uint64_t step = 1; step <= 10000; ++step) {
    counters.RecordWin(5 + static_cast<int>(step % 10), step);
  }
  auto old_only = [](int id) { return id < 5; };
  EXPECT_EQ(counters.MostActive(old_only), 1);
  EXPECT_LT(counters.log_size(), 4096u) << "the log was compacted (10,015 touches)";
  counters.Remove(1);
  EXPECT_EQ(counters.MostActive(old_only), 3);
  EXPECT_EQ(counters.MostActive([](int id) { return id >= 5; }), 5)
      << "the winner of step 10000 (10000 % 10 = 0) has the highest counter";
}

// After the touch log has been compacted several times, under wins, removals and re-adds,
// every tracked id is still in it: a search that only it passes finds it (and finds none for a
// removed id), whether its last touch was recent or is older than every compaction.
TEST(SignalCountersTest, CompactionKeepsEveryTrackedIdFindable) {
  const int n = 2000;
  SignalCounters counters(0.95);
  std::vector<bool> tracked(n, true);
  for (int id = 0; id < n; ++id) counters.Add(id, 1.0, 0);
  Random rng(17);
  uint64_t step = 0;
  for (int round = 0; round < 400; ++round) {
    for (int k = 0; k < 100; ++k) {
      ++step;
      // Most wins on a tenth of the ids, so that many ids keep only their first touch.
      const int id = static_cast<int>(rng.NextIndex(rng.NextDouble() < 0.9 ? n / 10 : n));
      if (tracked[id]) counters.RecordWin(id, step);
    }
    const int changed = static_cast<int>(rng.NextIndex(n));
    if (tracked[changed]) {
      counters.Remove(changed);
    } else {
      counters.Add(changed, 0.5, step);
    }
    tracked[changed] = !tracked[changed];
    counters.Flush();
  }
  ASSERT_LT(counters.log_size(), 40000u) << "the log was compacted (40,000 wins)";
  for (int id = 0; id < n; ++id) {
    ASSERT_EQ(counters.MostActive([id](int v) { return v == id; }), tracked[id] ? id : -1)
        << "id " << id;
  }
}

// A win in the step of the counter's last touch is not decayed first: it can lift the counter
// above every value given so far (20 + 1 here, with 1 / (1 - 0.95) = 20), and the search must
// still walk back to it past a later, smaller counter.
TEST(SignalCountersTest, AWinInTheStepOfTheLastTouchRaisesTheBound) {
  SignalCounters counters(0.95);
  counters.Add(0, 20.0, 5);
  counters.RecordWin(0, 5);
  counters.Flush();
  EXPECT_DOUBLE_EQ(counters.Value(0, 5), 21.0);
  counters.Add(1, 20.2, 5);
  EXPECT_EQ(counters.MostActive([](int) { return true; }), 0);
}

// Counters of 0 (ln 0 = -inf) still give an eligible vertex when no other is left.
TEST(SignalCountersTest, ZeroCountersAreStillFound) {
  SignalCounters counters(0.95);
  counters.Add(0, 0.0, 3);
  counters.Add(1, 0.0, 4);
  counters.Add(2, 2.0, 4);
  EXPECT_EQ(counters.MostActive([](int id) { return id != 2; }) < 2, true);
  EXPECT_EQ(counters.MostActive([](int id) { return id == 0; }), 0);
  EXPECT_EQ(counters.Value(0, 10), 0.0);
}

// A win long after the previous one takes a shortcut (the old counter is below what a double
// can add to 1); its counter must be bitwise the one a fresh counter of 1 gets, and a win
// shortly after the previous one must still add the decayed counter.
TEST(SignalCountersTest, WinsAfterLongAndShortGapsGiveExactCounters) {
  const double alpha = 0.95;
  SignalCounters counters(alpha);
  SignalCounters fresh(alpha);
  counters.Add(0, 1.0, 0);
  counters.RecordWin(0, 5000);  // 0.95^5000: far below 2^-53.
  counters.Flush();
  fresh.Add(0, 1.0, 5000);
  EXPECT_EQ(counters.Value(0, 5000), fresh.Value(0, 5000));
  EXPECT_EQ(counters.Value(0, 6000), fresh.Value(0, 6000));

  counters.RecordWin(0, 5100);  // 0.95^100 = 0.0059: must count.
  counters.Flush();
  EXPECT_NEAR(counters.Value(0, 5100), 1.0 + std::pow(alpha, 100), 1e-12);
}

}  // namespace
}  // namespace neuralmesh
