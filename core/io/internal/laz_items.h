// LASzip's coders (item version 2) for the parts of a LAS point record of formats 0 to 3: the
// 20 bytes every record starts with (POINT10), the GPS time (GPSTIME11), the colour (RGB12)
// and the extra bytes (BYTE). Each predicts its fields from the records before it in the chunk
// and codes what the prediction missed; Reset starts a chunk from its first record, which the
// chunk holds raw. Decode is Encode's exact inverse, as in LASzip. The GPS time's and the
// colour's coding serve the layered coders of formats 6 to 8 too (laz_layered_items.h).
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAZ_ITEMS_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAZ_ITEMS_H_

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/io/internal/laz_arithmetic_coder.h"
#include "core/io/internal/laz_integer_coder.h"

namespace neuralmesh::io_internal::laz {

// The model in `slot`, of `symbols` symbols, made on first use; a coder resets the models it
// made at a chunk's start.
SymbolModel& ModelIn(std::optional<SymbolModel>& slot, uint32_t symbols = 256);

// The context of Y from X's bit length k (even values, 20 and above alike), and of Z from
// their mean; plus 1 for single returns. POINT10 and POINT14 alike.
inline uint32_t YContext(uint32_t k, bool single) {
  return (single ? 1 : 0) + (k < 20 ? k & ~1u : 20);
}
inline uint32_t ZContext(uint32_t k, bool single) {
  return (single ? 1 : 0) + (k < 18 ? k & ~1u : 18);
}

// The median of the last five values added (three at first, zeros before any).
class StreamingMedian5 {
 public:
  void Add(int32_t value);
  int32_t Get() const { return values_[2]; }

 private:
  std::array<int32_t, 5> values_{};
  bool high_ = true;
};

// X, Y, Z, intensity, returns and flags, class, scan angle, user data and point source: the
// first 20 bytes of formats 0-5.
class Point10Coder {
 public:
  static constexpr size_t kSize = 20;
  Point10Coder();
  void Reset(const uint8_t* first);
  void Encode(ArithmeticEncoder& encoder, const uint8_t* item);
  void Decode(ArithmeticDecoder& decoder, uint8_t* item);

 private:
  // Which of the fields other than X, Y and Z differ from the last record's.
  SymbolModel changed_values_{64};
  IntegerCoder intensity_{16, 4};
  std::array<SymbolModel, 2> scan_angle_{SymbolModel(256), SymbolModel(256)};
  // By the last record's value of the byte; made when first needed.
  std::array<std::optional<SymbolModel>, 256> flags_, classes_, user_data_;
  IntegerCoder point_source_{16, 1};
  IntegerCoder dx_{32, 2};
  IntegerCoder dy_{32, 22};
  IntegerCoder z_{32, 20};

  std::array<uint8_t, kSize> last_{};
  std::array<uint16_t, 16> last_intensity_{};
  std::array<StreamingMedian5, 16> last_dx_, last_dy_;
  std::array<int32_t, 8> last_height_{};
};

// The GPS time, a double coded through its bits as an integer, in up to four interleaved
// sequences (several scanners or flight lines). Version 2 (GPSTIME11) codes every record's
// time, an unchanged one too; version 3 (a layer of POINT14) only the times that changed, with
// one symbol fewer.
class GpsTimeCoder {
 public:
  static constexpr size_t kSize = 8;
  explicit GpsTimeCoder(int version);
  void Reset(const uint8_t* first) { Reset(LoadTime(first)); }
  void Reset(int64_t first);
  void Encode(ArithmeticEncoder& encoder, const uint8_t* item);
  void Decode(ArithmeticDecoder& decoder, uint8_t* item);
  // The time's bits; version 3 codes only a time other than the last one.
  void EncodeTime(ArithmeticEncoder& encoder, int64_t time);
  int64_t DecodeTime(ArithmeticDecoder& decoder);

 private:
  static int64_t LoadTime(const uint8_t* item);
  // Starts a new sequence at `time`, coded in full.
  void EncodeNewSequence(ArithmeticEncoder& encoder, int64_t time);
  void DecodeNewSequence(ArithmeticDecoder& decoder);
  // Counts a difference far from the last one; the fourth in a row becomes the new one.
  void CountExtreme(int32_t difference);

  // 1 where an unchanged time has a symbol of its own (version 2), else 0: the symbols of the
  // cases after it are this much higher.
  uint32_t unchanged_symbols_;
  SymbolModel multiplier_;
  SymbolModel zero_difference_;
  IntegerCoder difference_{32, 9};
  uint32_t last_ = 0, next_ = 0;
  std::array<int64_t, 4> last_time_{};
  std::array<int32_t, 4> last_difference_{};
  std::array<int32_t, 4> extreme_count_{};
};

// Red, green and blue, 16 bits each, coded byte by byte as their change from `last`, green and
// blue predicted from red's change. RGB12 codes a record's colour so; RGB14 too, in a layer.
struct RgbModels {
  RgbModels();
  void Reset();
  SymbolModel changed_bytes{128};
  std::vector<SymbolModel> differences;  // Red low, red high, green low, high, blue low, high.
};
// Returns which bytes changed (0: the colour is `last`).
uint32_t EncodeRgb(ArithmeticEncoder& encoder, RgbModels& models,
                   const std::array<uint16_t, 3>& last, const std::array<uint16_t, 3>& rgb);
std::array<uint16_t, 3> DecodeRgb(ArithmeticDecoder& decoder, RgbModels& models,
                                  const std::array<uint16_t, 3>& last);

class Rgb12Coder {
 public:
  static constexpr size_t kSize = 6;
  void Reset(const uint8_t* first);
  void Encode(ArithmeticEncoder& encoder, const uint8_t* item);
  void Decode(ArithmeticDecoder& decoder, uint8_t* item);

 private:
  RgbModels models_;
  std::array<uint16_t, 3> last_{};
};

// Extra bytes, each coded as its change from the last record's.
class BytesCoder {
 public:
  explicit BytesCoder(size_t count);
  size_t size() const { return last_.size(); }
  void Reset(const uint8_t* first);
  void Encode(ArithmeticEncoder& encoder, const uint8_t* item);
  void Decode(ArithmeticDecoder& decoder, uint8_t* item);

 private:
  std::vector<SymbolModel> models_;
  std::vector<uint8_t> last_;
};

}  // namespace neuralmesh::io_internal::laz

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAZ_ITEMS_H_
