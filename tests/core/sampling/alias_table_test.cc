#include "core/sampling/alias_table.h"

#include <cmath>
#include <limits>
#include <vector>

#include "core/random.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

// Pearson's chi-square statistic of `counts` against probabilities proportional to `weights`
// (categories of weight zero must have count zero and are left out).
double ChiSquare(const std::vector<int>& counts, const std::vector<double>& weights) {
  double sum = 0;
  int total = 0;
  for (size_t i = 0; i < weights.size(); ++i) {
    sum += weights[i];
    total += counts[i];
  }
  double chi2 = 0;
  for (size_t i = 0; i < weights.size(); ++i) {
    if (weights[i] == 0) continue;
    const double expected = total * weights[i] / sum;
    chi2 += (counts[i] - expected) * (counts[i] - expected) / expected;
  }
  return chi2;
}

TEST(AliasTableTest, DrawsMatchWeights) {
  const std::vector<double> weights = {1, 2, 0, 3, 4, 0.5, 7.25};
  absl::StatusOr<AliasTable> table = AliasTable::Create(weights);
  ASSERT_TRUE(table.ok()) << table.status();
  EXPECT_EQ(table->size(), weights.size()) << "one cell per weight";
  Random rng(42);
  std::vector<int> counts(weights.size(), 0);
  for (int i = 0; i < 100000; ++i) {
    const size_t index = table->Draw(rng);
    ASSERT_LT(index, weights.size()) << "draw " << i << " is out of range";
    ++counts[index];
  }
  EXPECT_EQ(counts[2], 0) << "an entry of weight zero was drawn";
  // 5 degrees of freedom (6 positive categories): P(chi2 > 25) < 1.5e-4.
  EXPECT_LT(ChiSquare(counts, weights), 25.0) << "draw frequencies do not follow the weights";
}

TEST(AliasTableTest, FloatWeightsMatchToo) {
  const std::vector<float> weights = {3.0f, 1.0f};
  absl::StatusOr<AliasTable> table = AliasTable::Create(weights);
  ASSERT_TRUE(table.ok()) << table.status();
  Random rng(7);
  int first = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) first += table->Draw(rng) == 0;
  EXPECT_NEAR(first / static_cast<double>(n), 0.75, 0.006)
      << "weight 3 against weight 1 should be drawn 3/4 of the time";
}

TEST(AliasTableTest, SkewedWeightsAndManyZeros) {
  // 1000 entries of weight 1, one of weight 1000 and 1000 of weight zero.
  std::vector<double> weights(2001, 0.0);
  for (int i = 0; i < 1000; ++i) weights[2 * i] = 1.0;
  weights[2000] = 1000.0;
  absl::StatusOr<AliasTable> table = AliasTable::Create(weights);
  ASSERT_TRUE(table.ok()) << table.status();
  Random rng(3);
  int heavy = 0;
  int zero_drawn = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const size_t index = table->Draw(rng);
    heavy += index == 2000;
    zero_drawn += weights[index] == 0;
  }
  EXPECT_EQ(zero_drawn, 0) << "entries of weight zero were drawn";
  EXPECT_NEAR(heavy / static_cast<double>(n), 0.5, 0.005)
      << "the entry holding half the total weight should be drawn half the time";
}

TEST(AliasTableTest, SingleWeightAlwaysDrawn) {
  absl::StatusOr<AliasTable> table = AliasTable::Create(std::vector<double>{0.25});
  ASSERT_TRUE(table.ok()) << table.status();
  Random rng(1);
  for (int i = 0; i < 100; ++i) ASSERT_EQ(table->Draw(rng), 0u) << "draw " << i;
}

TEST(AliasTableTest, DeterministicForSeed) {
  absl::StatusOr<AliasTable> table = AliasTable::Create(std::vector<double>{1, 5, 2, 8, 3});
  ASSERT_TRUE(table.ok()) << table.status();
  Random a(99);
  Random b(99);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(table->Draw(a), table->Draw(b)) << "same seed, different draw " << i;
  }
}

// WeightedPointCloudSampler::PrefetchSample loads the draw after the next one, whose generator
// state it knows only because every draw takes the same two numbers.
TEST(AliasTableTest, EveryDrawTakesTwoRandomNumbers) {
  absl::StatusOr<AliasTable> table = AliasTable::Create(std::vector<double>{1, 0, 1e-9, 8, 3});
  ASSERT_TRUE(table.ok()) << table.status();
  Random rng(5);
  for (int i = 0; i < 1000; ++i) {
    Random two_on = rng;
    two_on.NextU64();
    two_on.NextU64();
    table->PrefetchDraw(rng);
    table->Draw(rng);
    Random after = rng;
    ASSERT_EQ(after.NextU64(), two_on.NextU64()) << "draw " << i;
  }
}

// n / sum overflowed for a subnormal sum, and the weight-zero entry was drawn half the time.
TEST(AliasTableTest, AWeightOfZeroIsNeverDrawnEvenBesideSubnormalOnes) {
  const absl::StatusOr<AliasTable> table = AliasTable::Create(std::vector<double>{0, 1e-320});
  ASSERT_TRUE(table.ok()) << table.status();
  Random rng(5);
  for (int i = 0; i < 10000; ++i) ASSERT_EQ(table->Draw(rng), 1u) << "draw " << i;
}

TEST(AliasTableTest, RejectsInvalidWeights) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<std::vector<double>> invalid = {{},       {1, -1},   {1, nan},
                                                    {inf, 1}, {0, 0, 0}, {1e308, 1e308}};
  for (const auto& weights : invalid) {
    const absl::StatusOr<AliasTable> table = AliasTable::Create(weights);
    EXPECT_EQ(table.status().code(), absl::StatusCode::kInvalidArgument)
        << "weights of size " << weights.size() << " should be rejected: " << table.status();
  }
}

}  // namespace
}  // namespace neuralmesh
