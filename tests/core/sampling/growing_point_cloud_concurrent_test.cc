// One thread appends batches to a GrowingPointCloud while others sample it: every sample must
// be a completely written point and sizes must only grow. Also run under ThreadSanitizer
// (label "concurrency").
#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/random.h"
#include "core/sampling/growing_point_cloud.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

constexpr int kTotalPoints = 200000;
constexpr int kReaders = 2;

// Point i is (i, 2i, -i): a torn or unwritten point breaks the pattern.
Vec3f PointFor(int i) { return Vec3f(static_cast<float>(i), 2.f * i, -1.f * i); }

// Batch sizes vary (and straddle the 65536-point chunks); fixed so the test is repeatable.
std::vector<int> BatchStarts() {
  std::vector<int> starts;
  Random rng(17);
  for (int start = 0; start < kTotalPoints;) {
    starts.push_back(start);
    start = std::min(kTotalPoints, start + 1 + static_cast<int>(rng.NextIndex(4000)));
  }
  starts.push_back(kTotalPoints);
  return starts;
}

struct ReaderReport {
  long samples = 0;
  long failures = 0;
  std::string first_failure;

  void Fail(const std::string& what) {
    if (failures++ == 0) first_failure = what;
  }
};

// Samples until `done` and at least kMinSamples times (on a loaded machine the writer may
// finish before a reader is first scheduled), checking each sample against the pattern, the
// size and the box. `allowed(i)` says whether point i may be drawn at all (weight zero may not).
constexpr long kMinSamples = 2000;
template <typename Allowed>
void Read(const GrowingPointCloud& cloud, const std::atomic<bool>& done, uint64_t seed,
          Allowed allowed, ReaderReport* report) {
  Random rng(seed);
  size_t last_size = 0;
  long round = 0;
  while (!done.load(std::memory_order_acquire) || report->samples < kMinSamples) {
    const size_t size_before = cloud.size();
    if (size_before < last_size) {
      report->Fail(absl::StrCat("size went down from ", last_size, " to ", size_before));
    }
    last_size = size_before;
    if (size_before == 0) continue;
    cloud.PrefetchSample(rng);  // Reads what Sample reads, as the learner does.
    const Vec3 p = cloud.Sample(rng);
    ++report->samples;
    const size_t size_after = cloud.size();
    const double x = p[0];
    const long i = std::lround(x);
    if (x != static_cast<double>(i) || p[1] != 2 * x || p[2] != -x) {
      report->Fail(
          absl::StrCat("sample (", p[0], ", ", p[1], ", ", p[2], ") is not a fully written point"));
    } else if (i < 0 || static_cast<size_t>(i) >= size_after) {
      report->Fail(absl::StrCat("sample ", i, " is beyond the size ", size_after));
    } else if (!allowed(static_cast<int>(i))) {
      report->Fail(absl::StrCat("point ", i, " of weight zero was drawn"));
    }
    if (!cloud.Bounds().Contains(p)) {
      report->Fail(absl::StrCat("sample ", i, " lies outside Bounds()"));
    }
    if (++round % 5000 == 0) {
      const PointCloud copy = cloud.Copy();
      for (size_t k = 0; k < copy.size(); ++k) {
        if (copy.positions[k] != PointFor(static_cast<int>(k))) {
          report->Fail(absl::StrCat("Copy() point ", k, " is wrong"));
          break;
        }
      }
      if (!copy.weights.empty() && copy.weights.size() != copy.size()) {
        report->Fail("Copy() has a weight count that does not match");
      }
    }
  }
}

void ExpectClean(const std::vector<ReaderReport>& reports) {
  for (size_t r = 0; r < reports.size(); ++r) {
    EXPECT_EQ(reports[r].failures, 0) << "reader " << r << ": " << reports[r].first_failure;
    EXPECT_GT(reports[r].samples, 0) << "reader " << r << " never sampled";
  }
}

TEST(GrowingPointCloudConcurrentTest, ReadersOnlySeeFullyWrittenPoints) {
  GrowingPointCloud cloud;
  const std::vector<int> starts = BatchStarts();
  std::atomic<bool> done{false};
  std::vector<ReaderReport> reports(kReaders);
  std::vector<std::thread> readers;
  for (int r = 0; r < kReaders; ++r) {
    readers.emplace_back([&, r] {
      Read(
          cloud, done, 100 + r, [](int) { return true; }, &reports[r]);
    });
  }
  absl::Status writer_status;
  for (size_t b = 0; b + 1 < starts.size() && writer_status.ok(); ++b) {
    std::vector<Vec3f> batch;
    for (int i = starts[b]; i < starts[b + 1]; ++i) batch.push_back(PointFor(i));
    writer_status = cloud.Append(batch);
  }
  done.store(true, std::memory_order_release);
  for (std::thread& reader : readers) reader.join();

  EXPECT_TRUE(writer_status.ok()) << writer_status;
  EXPECT_EQ(cloud.size(), static_cast<size_t>(kTotalPoints)) << "every batch should be in";
  ExpectClean(reports);
}

// Appends every batch, point i with the weight `weight_of(i)` (none: a batch without weights;
// the points of a batch agree), while readers sample from seeds seed, seed + 1, ...; then
// checks that every batch is in, that the weights read back (1 where a batch had none) and
// what the readers saw.
template <typename WeightOf>
void AppendWeightedWhileSampled(uint64_t seed, WeightOf weight_of) {
  GrowingPointCloud cloud;
  const std::vector<int> starts = BatchStarts();
  auto allowed = [&weight_of](int i) { return weight_of(i).value_or(1.0f) > 0; };

  std::atomic<bool> done{false};
  std::vector<ReaderReport> reports(kReaders);
  std::vector<std::thread> readers;
  for (int r = 0; r < kReaders; ++r) {
    readers.emplace_back([&, r] { Read(cloud, done, seed + r, allowed, &reports[r]); });
  }
  absl::Status writer_status;
  for (size_t b = 0; b + 1 < starts.size() && writer_status.ok(); ++b) {
    std::vector<Vec3f> batch;
    std::vector<float> weights;
    for (int i = starts[b]; i < starts[b + 1]; ++i) {
      batch.push_back(PointFor(i));
      if (const std::optional<float> w = weight_of(i)) weights.push_back(*w);
    }
    writer_status = cloud.Append(batch, weights);
  }
  done.store(true, std::memory_order_release);
  for (std::thread& reader : readers) reader.join();

  EXPECT_TRUE(writer_status.ok()) << writer_status;
  ASSERT_EQ(cloud.size(), static_cast<size_t>(kTotalPoints)) << "every batch should be in";
  const PointCloud copy = cloud.Copy();
  ASSERT_EQ(copy.weights.size(), copy.size()) << "weights were switched on";
  for (int i = 0; i < kTotalPoints; ++i) {
    ASSERT_EQ(copy.weights[i], weight_of(i).value_or(1.0f)) << "weight of point " << i;
  }
  ExpectClean(reports);
}

// Weights switch on halfway through: the earlier points are given weight 1 while readers
// sample, and points whose index is a multiple of 7 in weighted batches weigh zero.
TEST(GrowingPointCloudConcurrentTest, WeightsArrivingMidwayStayConsistent) {
  const std::vector<int> starts = BatchStarts();
  const size_t first_weighted = starts.size() / 2;
  // Odd batches from the middle on carry weights; the others do not (weight 1).
  std::vector<bool> weighted_point(kTotalPoints, false);
  for (size_t b = first_weighted; b + 1 < starts.size(); b += 2) {
    for (int i = starts[b]; i < starts[b + 1]; ++i) weighted_point[i] = true;
  }
  AppendWeightedWhileSampled(200, [&weighted_point](int i) -> std::optional<float> {
    if (!weighted_point[i]) return std::nullopt;
    return i % 7 == 0 ? 0.0f : 1.0f + i % 3;
  });
}

// Every batch carries weights, from the first on, spread over many weight classes (2^-40 to
// 2^40, exact powers of two and values between them) with a zero weight for every seventh
// point, point 0 included (so a sample of the origin out of nothing shows as a failure): new
// classes appear while readers sample, and each batch adds to classes that readers are reading.
TEST(GrowingPointCloudConcurrentTest, WeightClassesGrowWhileSampled) {
  AppendWeightedWhileSampled(400, [](int i) -> std::optional<float> {
    return i % 7 == 0 ? 0.0f : std::ldexp(1.0f + (i % 5) / 5.0f, i % 81 - 40);
  });
}

// Two writers append concurrently: appends serialise, each batch lands contiguously, and
// readers still only see fully written points.
TEST(GrowingPointCloudConcurrentTest, ConcurrentAppendsKeepBatchesWhole) {
  GrowingPointCloud cloud;
  const std::vector<int> starts = BatchStarts();  // Ids of writer w are offset by w * total.
  constexpr int kWriters = 2;
  std::atomic<bool> done{false};
  std::vector<ReaderReport> reports(kReaders);
  std::vector<std::thread> readers;
  for (int r = 0; r < kReaders; ++r) {
    readers.emplace_back([&, r] {
      Random rng(300 + r);
      while (!done.load(std::memory_order_acquire) || reports[r].samples < kMinSamples) {
        if (cloud.empty()) continue;
        const Vec3 p = cloud.Sample(rng);
        ++reports[r].samples;
        if (p[1] != 2 * p[0] || p[2] != -p[0] || p[0] != std::floor(p[0])) {
          reports[r].Fail(absl::StrCat("sample (", p[0], ", ", p[1], ", ", p[2],
                                       ") is not a fully written point"));
        }
        if (!cloud.Bounds().Contains(p)) reports[r].Fail("a sample lies outside Bounds()");
      }
    });
  }
  std::vector<absl::Status> writer_status(kWriters);
  std::vector<std::thread> writers;
  for (int w = 0; w < kWriters; ++w) {
    writers.emplace_back([&, w] {
      for (size_t b = 0; b + 1 < starts.size() && writer_status[w].ok(); ++b) {
        std::vector<Vec3f> batch;
        for (int i = starts[b]; i < starts[b + 1]; ++i)
          batch.push_back(PointFor(w * kTotalPoints + i));
        writer_status[w] = cloud.Append(batch);
      }
    });
  }
  for (std::thread& writer : writers) writer.join();
  done.store(true, std::memory_order_release);
  for (std::thread& reader : readers) reader.join();

  for (int w = 0; w < kWriters; ++w) EXPECT_TRUE(writer_status[w].ok()) << writer_status[w];
  const PointCloud copy = cloud.Copy();
  ASSERT_EQ(copy.size(), static_cast<size_t>(kWriters * kTotalPoints)) << "every batch is in";
  std::vector<bool> batch_start(kTotalPoints + 1, false);
  for (int start : starts) batch_start[start] = true;
  std::vector<int> next_id(kWriters, 0);  // Per writer, the id expected next (order kept).
  for (size_t k = 0; k < copy.size(); ++k) {
    const int id = static_cast<int>(copy.positions[k][0]);
    const int w = id / kTotalPoints;
    ASSERT_EQ(copy.positions[k], PointFor(id)) << "point " << k << " is torn";
    ASSERT_TRUE(w >= 0 && w < kWriters) << "point " << k << " has an unknown id " << id;
    ASSERT_EQ(id % kTotalPoints, next_id[w]) << "writer " << w << "'s points are out of order";
    ++next_id[w];
    if (k + 1 < copy.size() && static_cast<int>(copy.positions[k + 1][0]) != id + 1) {
      ASSERT_TRUE(batch_start[id % kTotalPoints + 1])
          << "another writer's points cut into a batch after id " << id;
    }
  }
  ExpectClean(reports);
}

}  // namespace
}  // namespace neuralmesh
