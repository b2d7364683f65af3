// The adaptive arithmetic (range) coder of LASzip's compressed LAS (LAZ) files, an adaptation
// of Amir Said's FastAC: 32-bit interval arithmetic, adaptive models of bits and of symbols
// whose probabilities are recomputed at growing intervals, and raw bits. Encoder and decoder
// are bit-exact inverses and match LASzip's own, so the files interoperate.
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAZ_ARITHMETIC_CODER_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAZ_ARITHMETIC_CODER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"

namespace neuralmesh::io_internal::laz {

// The adaptive probability of a 0 bit.
class BitModel {
 public:
  BitModel() { Reset(); }
  void Reset();

 private:
  friend class ArithmeticEncoder;
  friend class ArithmeticDecoder;
  void Count(uint32_t bit);

  uint32_t bit_0_count_ = 0;
  uint32_t bit_count_ = 0;
  uint32_t bit_0_probability_ = 0;
  uint32_t bits_until_update_ = 0;
  uint32_t update_cycle_ = 0;
};

// The adaptive distribution of `symbols` symbols (2 to 2048).
class SymbolModel {
 public:
  explicit SymbolModel(uint32_t symbols);
  void Reset();
  uint32_t symbols() const { return static_cast<uint32_t>(counts_.size()); }

 private:
  friend class ArithmeticEncoder;
  friend class ArithmeticDecoder;
  void Count(uint32_t symbol);
  void Update();
  // Starts keeping the decoder's table (models of more than 16 symbols that are decoded).
  void KeepDecoderTable();
  void FillDecoderTable();

  std::vector<uint32_t> distribution_;  // Cumulative, scaled to 2^15.
  std::vector<uint32_t> counts_;
  // For decoding: the first symbol whose interval can hold each 2^table_shift_ of the scaled
  // value, and one entry past the last, so that a search looks at a few symbols only.
  std::vector<uint32_t> decoder_table_;
  uint32_t table_shift_ = 0;
  uint32_t total_count_ = 0;
  uint32_t update_cycle_ = 0;
  uint32_t symbols_until_update_ = 0;
};

// Appends the coded bytes to `out`, from where it stood at construction.
class ArithmeticEncoder {
 public:
  explicit ArithmeticEncoder(std::string* out) : out_(out), start_(out->size()) {}
  void EncodeBit(BitModel& model, uint32_t bit);
  void EncodeSymbol(SymbolModel& model, uint32_t symbol);
  // `bits` (1 to 32) raw bits of `value`.
  void WriteBits(uint32_t bits, uint32_t value);
  void WriteShort(uint16_t value);
  void WriteInt(uint32_t value);
  // Ends the stream: its last bytes, then the zeros a decoder reads ahead. The decoder of the
  // whole stream reads exactly its bytes.
  void Done();

 private:
  void PropagateCarry();
  void Renormalize();

  std::string* out_;
  size_t start_;
  uint32_t base_ = 0;
  uint32_t length_ = 0xFFFFFFFFu;
};

// Decodes what ArithmeticEncoder wrote to `in`. Reads past its end give zeros and are counted,
// so that a truncated or corrupt stream decodes to garbage, never out of bounds.
class ArithmeticDecoder {
 public:
  explicit ArithmeticDecoder(absl::string_view in);
  uint32_t DecodeBit(BitModel& model);
  uint32_t DecodeSymbol(SymbolModel& model);
  uint32_t ReadBits(uint32_t bits);
  uint16_t ReadShort();
  uint32_t ReadInt();
  // Bytes read from the input, and past its end.
  size_t consumed() const { return next_; }
  size_t overrun() const { return overrun_; }

 private:
  uint8_t NextByte();
  void Renormalize();

  absl::string_view in_;
  size_t next_ = 0;
  size_t overrun_ = 0;
  uint32_t value_ = 0;
  uint32_t length_ = 0xFFFFFFFFu;
};

}  // namespace neuralmesh::io_internal::laz

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAZ_ARITHMETIC_CODER_H_
