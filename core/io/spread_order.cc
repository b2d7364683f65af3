#include "core/io/spread_order.h"

#include <cmath>
#include <numeric>

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
}

}  // namespace neuralmesh
