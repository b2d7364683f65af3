#include "core/io/internal/laz_integer_coder.h"

#include <limits>

namespace neuralmesh::io_internal::laz {
namespace {

// 2^k - 1 for k from 1 to 32.
uint32_t LowMask(uint32_t k) { return k >= 32 ? 0xFFFFFFFFu : (1u << k) - 1; }

}  // namespace

IntegerCoder::IntegerCoder(uint32_t bits, uint32_t contexts) {
  if (bits >= 1 && bits < 32) {
    corrector_bits_ = bits;
    corrector_range_ = 1u << bits;
    corrector_min_ = -static_cast<int32_t>(corrector_range_ / 2);
    corrector_max_ = static_cast<int32_t>(corrector_range_ / 2 - 1);
  } else {
    corrector_bits_ = 32;
    corrector_range_ = 0;
    corrector_min_ = std::numeric_limits<int32_t>::min();
    corrector_max_ = std::numeric_limits<int32_t>::max();
  }
  bit_lengths_.assign(contexts, SymbolModel(corrector_bits_ + 1));
  for (uint32_t k = 1; k <= corrector_bits_; ++k) {
    correctors_.emplace_back(1u << (k <= kBitsHigh ? k : kBitsHigh));
  }
}

void IntegerCoder::Reset() {
  for (SymbolModel& model : bit_lengths_) model.Reset();
  corrector_0_.Reset();
  for (SymbolModel& model : correctors_) model.Reset();
  k_ = 0;
}

void IntegerCoder::Compress(ArithmeticEncoder& encoder, int32_t predicted, int32_t real,
                            uint32_t context) {
  int32_t corrector =
      static_cast<int32_t>(static_cast<uint32_t>(real) - static_cast<uint32_t>(predicted));
  if (corrector_range_ != 0) {
    if (corrector < corrector_min_) {
      corrector += static_cast<int32_t>(corrector_range_);
    } else if (corrector > corrector_max_) {
      corrector -= static_cast<int32_t>(corrector_range_);
    }
  }
  // The smallest k with the corrector in [-(2^k - 1), 2^k].
  const uint32_t c = static_cast<uint32_t>(corrector);
  uint32_t magnitude = corrector <= 0 ? 0u - c : c - 1;
  k_ = 0;
  while (magnitude != 0) {
    magnitude >>= 1;
    ++k_;
  }
  encoder.EncodeSymbol(bit_lengths_[context], k_);
  if (k_ == 0) {
    encoder.EncodeBit(corrector_0_, c);
    return;
  }
  // Into [0, 2^k - 1]: negatives below 2^(k-1), positives from it.
  uint32_t position = corrector < 0 ? c + LowMask(k_) : c - 1;
  if (k_ <= kBitsHigh) {
    encoder.EncodeSymbol(correctors_[k_ - 1], position);
  } else {
    const uint32_t low_bits = k_ - kBitsHigh;
    encoder.EncodeSymbol(correctors_[k_ - 1], position >> low_bits);
    encoder.WriteBits(low_bits, position & LowMask(low_bits));
  }
}

int32_t IntegerCoder::Decompress(ArithmeticDecoder& decoder, int32_t predicted, uint32_t context) {
  k_ = decoder.DecodeSymbol(bit_lengths_[context]);
  uint32_t corrector;
  if (k_ == 0) {
    corrector = decoder.DecodeBit(corrector_0_);
  } else {
    uint32_t position;
    if (k_ <= kBitsHigh) {
      position = decoder.DecodeSymbol(correctors_[k_ - 1]);
    } else {
      const uint32_t low_bits = k_ - kBitsHigh;
      position = decoder.DecodeSymbol(correctors_[k_ - 1]) << low_bits;
      position |= decoder.ReadBits(low_bits) & LowMask(low_bits);
    }
    corrector = position >= (1u << (k_ - 1)) ? position + 1 : position - LowMask(k_);
  }
  int32_t real = static_cast<int32_t>(static_cast<uint32_t>(predicted) + corrector);
  if (corrector_range_ != 0) {
    if (real < 0) {
      real += static_cast<int32_t>(corrector_range_);
    } else if (static_cast<uint32_t>(real) >= corrector_range_) {
      real -= static_cast<int32_t>(corrector_range_);
    }
  }
  return real;
}

}  // namespace neuralmesh::io_internal::laz
