// server/points_journal.h: batches written and read back in order, torn and damaged tails,
// and a write that fails leaving the journal as it was.
#include "server/points_journal.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "core/random.h"
#include "tests/testing/file_size_limit.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::server {
namespace {

PointCloud RandomBatch(size_t n, uint64_t seed, bool weights, bool normals) {
  Random rng(seed);
  PointCloud cloud;
  for (size_t i = 0; i < n; ++i) {
    cloud.positions.emplace_back(rng.NextDouble(), rng.NextDouble(), rng.NextDouble());
    if (weights) cloud.weights.push_back(static_cast<float>(rng.NextDouble()));
    if (normals) cloud.normals.emplace_back(0.0f, 0.0f, 1.0f);
  }
  return cloud;
}

bool SameCloud(const PointCloud& a, const PointCloud& b) {
  return a.positions == b.positions && a.weights == b.weights && a.normals == b.normals &&
         a.colors == b.colors;
}

std::vector<PointCloud> ReadAll(const std::string& path, JournalReadResult* result) {
  std::vector<PointCloud> batches;
  absl::StatusOr<JournalReadResult> read = ReadPointsJournal(path, [&](const PointCloud& batch) {
    batches.push_back(batch);
    return absl::OkStatus();
  });
  EXPECT_TRUE(read.ok()) << read.status();
  if (read.ok()) *result = *read;
  return batches;
}

class PointsJournalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = neuralmesh::testing::MakeTempDir("journal") + "/points.journal";
    batches_ = {RandomBatch(100, 1, false, false), RandomBatch(1, 2, true, false),
                RandomBatch(5000, 3, true, true)};
    for (size_t i = 0; i < batches_[2].size(); ++i) {  // The last batch has colours too.
      batches_[2].colors.push_back(
          {static_cast<uint8_t>(i), static_cast<uint8_t>(i >> 8), static_cast<uint8_t>(i % 7)});
    }
    absl::StatusOr<std::unique_ptr<PointsJournal>> journal = PointsJournal::Open(path_, 0, true);
    ASSERT_TRUE(journal.ok()) << journal.status();
    for (const PointCloud& batch : batches_) {
      ASSERT_TRUE((*journal)->Append(batch).ok());
      ends_.push_back((*journal)->size_bytes());
    }
    size_ = ends_.back();
  }

  std::string path_;
  std::vector<PointCloud> batches_;
  std::vector<uint64_t> ends_;  // Where each record ends.
  uint64_t size_ = 0;
};

TEST_F(PointsJournalTest, ReadsEveryBatchBackInOrder) {
  EXPECT_EQ(std::filesystem::file_size(path_), size_);
  JournalReadResult result;
  const std::vector<PointCloud> read = ReadAll(path_, &result);
  ASSERT_EQ(read.size(), batches_.size());
  for (size_t i = 0; i < read.size(); ++i) EXPECT_TRUE(SameCloud(read[i], batches_[i])) << i;
  EXPECT_EQ(result.batches, 3u);
  EXPECT_EQ(result.points, 5101u);
  EXPECT_EQ(result.valid_bytes, size_);
  EXPECT_TRUE(result.damage.empty()) << result.damage;
}

TEST_F(PointsJournalTest, ATornTailIsReportedAndCutOffOnReopening) {
  std::filesystem::resize_file(path_, size_ - 7);
  JournalReadResult result;
  std::vector<PointCloud> read = ReadAll(path_, &result);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_TRUE(absl::StrContains(result.damage, "torn")) << result.damage;

  // Reopened at the whole records, the journal takes new batches after them.
  absl::StatusOr<std::unique_ptr<PointsJournal>> journal =
      PointsJournal::Open(path_, result.valid_bytes, false);
  ASSERT_TRUE(journal.ok()) << journal.status();
  const PointCloud next = RandomBatch(10, 4, false, false);
  ASSERT_TRUE((*journal)->Append(next).ok());
  read = ReadAll(path_, &result);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_TRUE(SameCloud(read[2], next));
  EXPECT_TRUE(result.damage.empty()) << result.damage;
}

TEST_F(PointsJournalTest, ADamagedRecordEndsTheReading) {
  // The last byte of the middle record's payload, flipped.
  std::fstream file(path_, std::ios::in | std::ios::out | std::ios::binary);
  file.seekg(static_cast<std::streamoff>(ends_[1] - 1));
  const char byte = static_cast<char>(file.get());
  file.seekp(static_cast<std::streamoff>(ends_[1] - 1));
  file.put(static_cast<char>(byte ^ 0xff));
  file.close();
  JournalReadResult result;
  const std::vector<PointCloud> read = ReadAll(path_, &result);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_TRUE(SameCloud(read[0], batches_[0]));
  EXPECT_FALSE(result.damage.empty());
  EXPECT_EQ(result.valid_bytes, ends_[0]);
}

TEST_F(PointsJournalTest, GarbageAfterTheRecordsIsNoRecord) {
  std::ofstream(path_, std::ios::app | std::ios::binary) << std::string(40, '\0');
  JournalReadResult result;
  EXPECT_EQ(ReadAll(path_, &result).size(), 3u);
  EXPECT_TRUE(absl::StrContains(result.damage, "no record header")) << result.damage;
  EXPECT_EQ(result.valid_bytes, size_);
}

TEST_F(PointsJournalTest, AFailedWriteLeavesTheJournalAsItWas) {
  absl::StatusOr<std::unique_ptr<PointsJournal>> journal =
      PointsJournal::Open(path_, size_, false);
  ASSERT_TRUE(journal.ok()) << journal.status();
  // A file size limit just above the journal: the next batch fits only partly.
  absl::Status failed;
  {
    neuralmesh::testing::ScopedFileSizeLimit limit(size_ + 1000);
    failed = (*journal)->Append(RandomBatch(1000, 5, false, false));
  }
  EXPECT_EQ(failed.code(), absl::StatusCode::kResourceExhausted) << failed;
  EXPECT_TRUE(absl::StrContains(failed.message(), path_)) << failed;
  EXPECT_EQ(std::filesystem::file_size(path_), size_);

  // And the next write goes where the failed one began.
  const PointCloud next = RandomBatch(1000, 6, false, false);
  ASSERT_TRUE((*journal)->Append(next).ok());
  JournalReadResult result;
  const std::vector<PointCloud> read = ReadAll(path_, &result);
  ASSERT_EQ(read.size(), 4u);
  EXPECT_TRUE(SameCloud(read[3], next));
  EXPECT_TRUE(result.damage.empty()) << result.damage;
}

TEST(PointsJournalReadTest, AMissingFileIsNotFound) {
  const absl::StatusOr<JournalReadResult> read = ReadPointsJournal(
      neuralmesh::testing::MakeTempDir("missing") + "/none",
      [](const PointCloud&) { return absl::OkStatus(); });
  EXPECT_EQ(read.status().code(), absl::StatusCode::kNotFound);
}

TEST(PointsJournalReadTest, AVisitorsErrorStopsTheReading) {
  const std::string path = neuralmesh::testing::MakeTempDir("visitor") + "/points.journal";
  absl::StatusOr<std::unique_ptr<PointsJournal>> journal = PointsJournal::Open(path, 0, false);
  ASSERT_TRUE(journal.ok());
  ASSERT_TRUE((*journal)->Append(RandomBatch(3, 7, false, false)).ok());
  ASSERT_TRUE((*journal)->Append(RandomBatch(3, 8, false, false)).ok());
  int visits = 0;
  const absl::StatusOr<JournalReadResult> read =
      ReadPointsJournal(path, [&](const PointCloud&) {
        ++visits;
        return absl::InvalidArgumentError("no thanks");
      });
  EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(visits, 1);
}

}  // namespace
}  // namespace neuralmesh::server
