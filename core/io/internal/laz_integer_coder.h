// LASzip's integer compressor: an integer coded as its difference from a prediction, the
// difference's bit length k as a symbol (in one of several contexts), then the difference
// within [-(2^k - 1), 2^k] as a symbol of up to 8 bits and, past those, raw bits.
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAZ_INTEGER_CODER_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAZ_INTEGER_CODER_H_

#include <cstdint>
#include <vector>

#include "core/io/internal/laz_arithmetic_coder.h"

namespace neuralmesh::io_internal::laz {

// Integers of `bits` bits (1 to 32; below 32 the differences wrap around), predicted in
// `contexts` contexts. One instance either compresses or decompresses.
class IntegerCoder {
 public:
  IntegerCoder(uint32_t bits, uint32_t contexts);
  // Back to the models' initial state (a new chunk).
  void Reset();

  void Compress(ArithmeticEncoder& encoder, int32_t predicted, int32_t real, uint32_t context);
  int32_t Decompress(ArithmeticDecoder& decoder, int32_t predicted, uint32_t context);
  // The bit length k of the last difference coded, a context for other fields.
  uint32_t k() const { return k_; }

 private:
  static constexpr uint32_t kBitsHigh = 8;

  uint32_t corrector_bits_;
  uint32_t corrector_range_;  // 0 for 32 bits.
  int32_t corrector_min_;
  int32_t corrector_max_;
  uint32_t k_ = 0;
  std::vector<SymbolModel> bit_lengths_;  // One per context.
  BitModel corrector_0_;                  // k = 0: the difference is 0 or 1.
  std::vector<SymbolModel> correctors_;   // k = 1 to corrector_bits_, at index k - 1.
};

}  // namespace neuralmesh::io_internal::laz

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAZ_INTEGER_CODER_H_
