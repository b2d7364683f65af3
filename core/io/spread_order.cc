#include "core/io/spread_order.h"

#include <cmath>
#include <numeric>
#include <utility>

namespace neuralmesh {

SpreadOrder::SpreadOrder(uint64_t records, uint64_t block_records)
    : records_(records),
      block_records_(block_records),
      blocks_(records / block_records + (records % block_records != 0)) {
  if (blocks_ == 0) blocks_ = 1;
  const long double inverse_golden_ratio = (std::sqrt(5.0L) - 1) / 2;
  stride_ = static_cast<uint64_t>(std::llround(inverse_golden_ratio * blocks_));
  if (stride_ == 0) stride_ = 1;
  while (std::gcd(stride_, blocks_) != 1) ++stride_;
  // The last block is visited at the position p with p * stride = blocks - 1 (mod blocks): p is
  // blocks - 1 times the stride's inverse, found by the extended Euclidean algorithm.
  __int128 r0 = blocks_, r1 = stride_, t0 = 0, t1 = 1;
  while (r1 != 0) {
    const __int128 q = r0 / r1;
    r0 -= q * r1;
    std::swap(r0, r1);
    t0 -= q * t1;
    std::swap(t0, t1);
  }
  const __int128 inverse = (t0 % static_cast<__int128>(blocks_) + blocks_) % blocks_;
  const uint64_t position =
      static_cast<uint64_t>(inverse * static_cast<__int128>(blocks_ - 1) % blocks_);
  short_block_records_ = records_ - (blocks_ - 1) * block_records_;
  short_block_end_ = position * block_records_ + short_block_records_;
}

}  // namespace neuralmesh
