#include "core/io/spread_order.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

TEST(SpreadOrderTest, VisitsEveryRecordOnce) {
  for (uint64_t records :
       {uint64_t{0}, uint64_t{1}, uint64_t{255}, uint64_t{256}, uint64_t{257}, uint64_t{1000},
        uint64_t{256 * 12}, uint64_t{65537}, uint64_t{256 * 1009 + 3}}) {
    SCOPED_TRACE(records);
    const SpreadOrder order(records);
    EXPECT_EQ(order.slots() % SpreadOrder::kBlockRecords, 0u);
    EXPECT_LT(order.slots(), records + SpreadOrder::kBlockRecords + 1);
    std::vector<int> seen(records, 0);
    for (uint64_t slot = 0; slot < order.slots(); ++slot) {
      const uint64_t record = order[slot];
      ASSERT_LT(record, order.slots());
      if (record < records) ++seen[record];
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<int64_t>(records));
  }
}

// SlotOfNth counts the slots of records only, skipping those past the last record wherever
// the order visits the last block.
TEST(SpreadOrderTest, TheNthRecordsSlotSkipsTheSlotsPastTheLastRecord) {
  for (uint64_t block_records : {uint64_t{1}, uint64_t{7}, SpreadOrder::kBlockRecords}) {
    for (uint64_t records : {uint64_t{1}, uint64_t{6}, uint64_t{255}, uint64_t{256}, uint64_t{257},
                             uint64_t{1000}, uint64_t{65537}, uint64_t{99991}}) {
      SCOPED_TRACE(testing::Message() << records << " records in blocks of " << block_records);
      const SpreadOrder order(records, block_records);
      uint64_t k = 0;
      for (uint64_t slot = 0; slot < order.slots(); ++slot) {
        if (order[slot] >= records) continue;
        ASSERT_EQ(order.SlotOfNth(k), slot) << "record number " << k;
        ++k;
      }
      EXPECT_EQ(k, records);
    }
  }
}

TEST(SpreadOrderTest, ReadsEachBlockInOrder) {
  const SpreadOrder order(10000);
  for (uint64_t slot = 0; slot < order.slots(); ++slot) {
    if (slot % SpreadOrder::kBlockRecords == 0) {
      EXPECT_EQ(order[slot] % SpreadOrder::kBlockRecords, 0u);
    } else {
      EXPECT_EQ(order[slot], order[slot - 1] + 1);
    }
  }
}

// The three-distance theorem's promise: after k blocks, no stretch of the file longer than
// 3 / k of it is left unvisited, whatever k.
TEST(SpreadOrderTest, EveryPrefixIsSpreadOverTheWholeFile) {
  for (uint64_t blocks : {uint64_t{100}, uint64_t{4096}, uint64_t{78125}, uint64_t{1000003}}) {
    SCOPED_TRACE(blocks);
    const SpreadOrder order(blocks * SpreadOrder::kBlockRecords);
    std::vector<uint64_t> visited;
    for (uint64_t k = 1; k <= std::min<uint64_t>(blocks, 2000); ++k) {
      visited.push_back(order[(k - 1) * SpreadOrder::kBlockRecords] / SpreadOrder::kBlockRecords);
      if (k < 3) continue;
      std::vector<uint64_t> sorted = visited;
      std::sort(sorted.begin(), sorted.end());
      uint64_t longest = sorted.front() + blocks - sorted.back();  // Around the end.
      for (size_t i = 1; i < sorted.size(); ++i) {
        longest = std::max(longest, sorted[i] - sorted[i - 1]);
      }
      ASSERT_LE(longest, 3 * blocks / k + 1) << "after " << k << " blocks";
    }
  }
}

}  // namespace
}  // namespace neuralmesh
