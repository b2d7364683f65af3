#include "core/io/internal/laz_arithmetic_coder.h"

#include <algorithm>

namespace neuralmesh::io_internal::laz {
namespace {

// The interval's length stays between 2^24 and 2^32 - 1; bit models scale their probability
// to 2^13, symbol models their distribution to 2^15.
constexpr uint32_t kMinLength = 0x01000000u;
constexpr uint32_t kBitLengthShift = 13;
constexpr uint32_t kBitMaxCount = 1u << kBitLengthShift;
constexpr uint32_t kSymbolLengthShift = 15;
constexpr uint32_t kSymbolMaxCount = 1u << kSymbolLengthShift;

}  // namespace

void BitModel::Reset() {
  bit_0_count_ = 1;
  bit_count_ = 2;
  bit_0_probability_ = 1u << (kBitLengthShift - 1);
  update_cycle_ = bits_until_update_ = 4;
}

void BitModel::Count(uint32_t bit) {
  if (bit == 0) ++bit_0_count_;
  if (--bits_until_update_ != 0) return;
  if ((bit_count_ += update_cycle_) > kBitMaxCount) {
    bit_count_ = (bit_count_ + 1) >> 1;
    bit_0_count_ = (bit_0_count_ + 1) >> 1;
    if (bit_0_count_ == bit_count_) ++bit_count_;
  }
  const uint32_t scale = 0x80000000u / bit_count_;
  bit_0_probability_ = (bit_0_count_ * scale) >> (31 - kBitLengthShift);
  update_cycle_ = (5 * update_cycle_) >> 2;
  if (update_cycle_ > 64) update_cycle_ = 64;
  bits_until_update_ = update_cycle_;
}

SymbolModel::SymbolModel(uint32_t symbols) : distribution_(symbols), counts_(symbols) { Reset(); }

void SymbolModel::Reset() {
  const uint32_t symbols = this->symbols();
  total_count_ = 0;
  update_cycle_ = symbols;
  for (uint32_t& count : counts_) count = 1;
  Update();
  symbols_until_update_ = update_cycle_ = (symbols + 6) >> 1;
}

void SymbolModel::Count(uint32_t symbol) {
  ++counts_[symbol];
  if (--symbols_until_update_ == 0) Update();
}

void SymbolModel::Update() {
  const uint32_t symbols = this->symbols();
  if ((total_count_ += update_cycle_) > kSymbolMaxCount) {
    total_count_ = 0;
    for (uint32_t& count : counts_) total_count_ += (count = (count + 1) >> 1);
  }
  const uint32_t scale = 0x80000000u / total_count_;
  uint32_t sum = 0;
  for (uint32_t k = 0; k < symbols; ++k) {
    distribution_[k] = (scale * sum) >> (31 - kSymbolLengthShift);
    sum += counts_[k];
  }
  if (!decoder_table_.empty()) FillDecoderTable();
  update_cycle_ = (5 * update_cycle_) >> 2;
  const uint32_t max_cycle = (symbols + 6) << 3;
  if (update_cycle_ > max_cycle) update_cycle_ = max_cycle;
  symbols_until_update_ = update_cycle_;
}

void SymbolModel::KeepDecoderTable() {
  uint32_t table_bits = 3;
  while (symbols() > (1u << (table_bits + 2))) ++table_bits;
  decoder_table_.assign((size_t{1} << table_bits) + 2, 0);
  table_shift_ = kSymbolLengthShift - table_bits;
  FillDecoderTable();
}

void SymbolModel::FillDecoderTable() {
  const uint32_t table_size = static_cast<uint32_t>(decoder_table_.size()) - 2;
  uint32_t s = 0;
  for (uint32_t k = 0; k < symbols(); ++k) {
    const uint32_t w = distribution_[k] >> table_shift_;
    while (s < w) decoder_table_[++s] = k - 1;
  }
  decoder_table_[0] = 0;
  while (s <= table_size) decoder_table_[++s] = symbols() - 1;
}

void ArithmeticEncoder::EncodeBit(BitModel& model, uint32_t bit) {
  const uint32_t x = model.bit_0_probability_ * (length_ >> kBitLengthShift);
  if (bit == 0) {
    length_ = x;
  } else {
    const uint32_t before = base_;
    base_ += x;
    length_ -= x;
    if (before > base_) PropagateCarry();
  }
  if (length_ < kMinLength) Renormalize();
  model.Count(bit);
}

void ArithmeticEncoder::EncodeSymbol(SymbolModel& model, uint32_t symbol) {
  const uint32_t before = base_;
  if (symbol == model.symbols() - 1) {
    const uint32_t x = model.distribution_[symbol] * (length_ >> kSymbolLengthShift);
    base_ += x;
    length_ -= x;
  } else {
    length_ >>= kSymbolLengthShift;
    const uint32_t x = model.distribution_[symbol] * length_;
    base_ += x;
    length_ = model.distribution_[symbol + 1] * length_ - x;
  }
  if (before > base_) PropagateCarry();
  if (length_ < kMinLength) Renormalize();
  model.Count(symbol);
}

void ArithmeticEncoder::WriteBits(uint32_t bits, uint32_t value) {
  if (bits > 19) {
    WriteShort(static_cast<uint16_t>(value & 0xFFFF));
    value >>= 16;
    bits -= 16;
  }
  const uint32_t before = base_;
  base_ += value * (length_ >>= bits);
  if (before > base_) PropagateCarry();
  if (length_ < kMinLength) Renormalize();
}

void ArithmeticEncoder::WriteShort(uint16_t value) {
  const uint32_t before = base_;
  base_ += uint32_t{value} * (length_ >>= 16);
  if (before > base_) PropagateCarry();
  if (length_ < kMinLength) Renormalize();
}

void ArithmeticEncoder::WriteInt(uint32_t value) {
  WriteShort(static_cast<uint16_t>(value & 0xFFFF));
  WriteShort(static_cast<uint16_t>(value >> 16));
}

void ArithmeticEncoder::Done() {
  // One or two last bytes, then zeros up to the four bytes the decoder reads ahead, so that it
  // ends exactly at the stream's end (LASzip's readers check that a chunk ends where the next
  // starts).
  const uint32_t before = base_;
  const bool one_byte = length_ > 2 * kMinLength;
  if (one_byte) {
    base_ += kMinLength;
    length_ = kMinLength >> 1;
  } else {
    base_ += kMinLength >> 1;
    length_ = kMinLength >> 9;
  }
  if (before > base_) PropagateCarry();
  Renormalize();
  out_->append(one_byte ? 3 : 2, '\0');
}

void ArithmeticEncoder::PropagateCarry() {
  for (size_t p = out_->size(); p > start_; --p) {
    char& byte = (*out_)[p - 1];
    if (static_cast<uint8_t>(byte) != 0xFF) {
      byte = static_cast<char>(static_cast<uint8_t>(byte) + 1);
      return;
    }
    byte = 0;
  }
}

void ArithmeticEncoder::Renormalize() {
  do {
    out_->push_back(static_cast<char>(base_ >> 24));
    base_ <<= 8;
  } while ((length_ <<= 8) < kMinLength);
}

ArithmeticDecoder::ArithmeticDecoder(absl::string_view in) : in_(in) {
  for (int i = 0; i < 4; ++i) value_ = (value_ << 8) | NextByte();
}

uint8_t ArithmeticDecoder::NextByte() {
  if (next_ < in_.size()) return static_cast<uint8_t>(in_[next_++]);
  ++overrun_;
  return 0;
}

void ArithmeticDecoder::Renormalize() {
  do {
    value_ = (value_ << 8) | NextByte();
  } while ((length_ <<= 8) < kMinLength);
}

uint32_t ArithmeticDecoder::DecodeBit(BitModel& model) {
  const uint32_t x = model.bit_0_probability_ * (length_ >> kBitLengthShift);
  const uint32_t bit = value_ >= x ? 1 : 0;
  if (bit == 0) {
    length_ = x;
  } else {
    value_ -= x;
    length_ -= x;
  }
  if (length_ < kMinLength) Renormalize();
  model.Count(bit);
  return bit;
}

uint32_t ArithmeticDecoder::DecodeSymbol(SymbolModel& model) {
  // The symbol whose scaled interval holds the value, by bisection: over the symbols the
  // decoder table leaves, or over all of them for small models.
  if (model.decoder_table_.empty() && model.symbols() > 16) model.KeepDecoderTable();
  const std::vector<uint32_t>& distribution = model.distribution_;
  const uint32_t last = model.symbols() - 1;
  uint32_t symbol = 0, x = 0, y = length_;
  length_ >>= kSymbolLengthShift;
  if (!model.decoder_table_.empty()) {
    // value_ < length_ before the shift, so the scaled value is below 2^15 + 2^6 and its entry
    // at most the table's size.
    const uint32_t scaled = value_ / length_;
    const size_t entry =
        std::min<size_t>(scaled >> model.table_shift_, model.decoder_table_.size() - 2);
    symbol = model.decoder_table_[entry];
    uint32_t n = model.decoder_table_[entry + 1] + 1;
    while (n > symbol + 1) {
      const uint32_t k = (symbol + n) >> 1;
      if (distribution[k] > scaled) {
        n = k;
      } else {
        symbol = k;
      }
    }
    x = distribution[symbol] * length_;
    if (symbol != last) y = distribution[symbol + 1] * length_;
  } else {
    uint32_t n = last + 1;
    uint32_t k = n >> 1;
    do {
      const uint32_t z = length_ * distribution[k];
      if (z > value_) {
        n = k;
        y = z;
      } else {
        symbol = k;
        x = z;
      }
    } while ((k = (symbol + n) >> 1) != symbol);
  }
  value_ -= x;
  length_ = y - x;
  if (length_ < kMinLength) Renormalize();
  model.Count(symbol);
  return symbol;
}

uint32_t ArithmeticDecoder::ReadBits(uint32_t bits) {
  if (bits > 19) {
    const uint32_t lower = ReadShort();
    const uint32_t upper = ReadBits(bits - 16);
    return (upper << 16) | lower;
  }
  const uint32_t value = value_ / (length_ >>= bits);
  value_ -= length_ * value;
  if (length_ < kMinLength) Renormalize();
  return value;
}

uint16_t ArithmeticDecoder::ReadShort() {
  const uint32_t value = value_ / (length_ >>= 16);
  value_ -= length_ * value;
  if (length_ < kMinLength) Renormalize();
  return static_cast<uint16_t>(value);
}

uint32_t ArithmeticDecoder::ReadInt() {
  const uint32_t lower = ReadShort();
  const uint32_t upper = ReadShort();
  return (upper << 16) | lower;
}

}  // namespace neuralmesh::io_internal::laz
