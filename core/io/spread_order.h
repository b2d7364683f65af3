// An order of a file's records in which every prefix is spread over the whole file, so that
// the first points of an upload read in this order already outline the whole scan (a server
// learning while they arrive has a coarse mesh of all of it, not of its first strip). Records
// go in blocks of consecutive ones (by default kBlockRecords, a page or two of the file, read in
// order; a LAZ file's chunks: blocks of one), and the blocks are visited along a stride of the
// golden ratio times their count: a Kronecker sequence, whose first k blocks leave gaps of at
// most three lengths between them, the longest under 3 / k of the file (the three-distance
// theorem).
#ifndef NEURALMESH_CORE_IO_SPREAD_ORDER_H_
#define NEURALMESH_CORE_IO_SPREAD_ORDER_H_

#include <cstdint>

namespace neuralmesh {

class SpreadOrder {
 public:
  static constexpr uint64_t kBlockRecords = 256;

  // The order of records 0 .. records - 1 in blocks of `block_records` (> 0).
  explicit SpreadOrder(uint64_t records, uint64_t block_records = kBlockRecords);

  // The positions of the order, 0 .. slots() - 1: every record once, and past the last record
  // the rest of its block (records() or more).
  uint64_t slots() const { return blocks_ * block_records_; }
  uint64_t records() const { return records_; }
  uint64_t block_records() const { return block_records_; }
  // The record at position `slot` (< slots()); records() or more for a slot past the last.
  uint64_t operator[](uint64_t slot) const {
    const uint64_t block = static_cast<uint64_t>(
        static_cast<unsigned __int128>(slot / block_records_) * stride_ % blocks_);
    return block * block_records_ + slot % block_records_;
  }
  // The position of the order's k-th record (k < records()): its k-th slot, not counting the
  // slots past the last record.
  uint64_t SlotOfNth(uint64_t k) const {
    return k < short_block_end_ ? k : k + (block_records_ - short_block_records_);
  }

 private:
  uint64_t records_;
  uint64_t block_records_;
  uint64_t blocks_;
  uint64_t stride_;  // Coprime with blocks_: the order visits each block once.
  // The last block's records, and the slot after them: the slots past the last record follow.
  uint64_t short_block_records_;
  uint64_t short_block_end_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_SPREAD_ORDER_H_
