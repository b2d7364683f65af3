#include "core/io/internal/laz_items.h"

#include <cstring>

namespace neuralmesh::io_internal::laz {
namespace {

uint16_t Load16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
uint32_t Load32(const uint8_t* p) {
  return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}
uint64_t Load64(const uint8_t* p) { return Load32(p) | (uint64_t{Load32(p + 4)} << 32); }
void Store16(uint16_t value, uint8_t* p) {
  p[0] = static_cast<uint8_t>(value);
  p[1] = static_cast<uint8_t>(value >> 8);
}
void Store32(uint32_t value, uint8_t* p) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(value >> (8 * i));
}
void Store64(uint64_t value, uint8_t* p) {
  Store32(static_cast<uint32_t>(value), p);
  Store32(static_cast<uint32_t>(value >> 32), p + 4);
}

// Which of 16 contexts the return r of n returns codes its X, Y and intensity in, and which of
// 8 its Z: first, intermediate and last returns apart, and contexts of their own for the
// combinations that badly written files hold (r or n of 0, r above n).
constexpr uint8_t kReturnContext[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8},  {14, 0, 1, 3, 6, 10, 10, 9},
    {13, 1, 2, 4, 7, 11, 11, 10},    {12, 3, 4, 5, 8, 12, 12, 11},
    {11, 6, 7, 8, 9, 13, 13, 12},    {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
constexpr uint8_t kReturnLevel[8][8] = {{0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6},
                                        {2, 1, 0, 1, 2, 3, 4, 5}, {3, 2, 1, 0, 1, 2, 3, 4},
                                        {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2},
                                        {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0}};

uint8_t Clamp8(int32_t value) {
  return static_cast<uint8_t>(value <= 0 ? 0 : value >= 255 ? 255 : value);
}

// Byte fields of the core record.
constexpr size_t kIntensity = 12, kFlags = 14, kClass = 15, kScanAngle = 16, kUserData = 17,
                 kPointSource = 18;

}  // namespace

SymbolModel& ModelIn(std::optional<SymbolModel>& slot, uint32_t symbols) {
  if (!slot.has_value()) slot.emplace(symbols);
  return *slot;
}

void StreamingMedian5::Add(int32_t v) {
  std::array<int32_t, 5>& x = values_;
  if (high_) {
    if (v < x[2]) {
      x[4] = x[3];
      x[3] = x[2];
      if (v < x[0]) {
        x[2] = x[1];
        x[1] = x[0];
        x[0] = v;
      } else if (v < x[1]) {
        x[2] = x[1];
        x[1] = v;
      } else {
        x[2] = v;
      }
    } else {
      if (v < x[3]) {
        x[4] = x[3];
        x[3] = v;
      } else {
        x[4] = v;
      }
      high_ = false;
    }
  } else {
    if (x[2] < v) {
      x[0] = x[1];
      x[1] = x[2];
      if (x[4] < v) {
        x[2] = x[3];
        x[3] = x[4];
        x[4] = v;
      } else if (x[3] < v) {
        x[2] = x[3];
        x[3] = v;
      } else {
        x[2] = v;
      }
    } else {
      if (x[1] < v) {
        x[0] = x[1];
        x[1] = v;
      } else {
        x[0] = v;
      }
      high_ = true;
    }
  }
}

Point10Coder::Point10Coder() = default;

void Point10Coder::Reset(const uint8_t* first) {
  changed_values_.Reset();
  intensity_.Reset();
  for (SymbolModel& model : scan_angle_) model.Reset();
  for (auto* models : {&flags_, &classes_, &user_data_}) {
    for (std::optional<SymbolModel>& model : *models) {
      if (model.has_value()) model->Reset();
    }
  }
  point_source_.Reset();
  dx_.Reset();
  dy_.Reset();
  z_.Reset();
  std::memcpy(last_.data(), first, kSize);
  // The intensity is predicted from last_intensity_, which starts at 0.
  last_[kIntensity] = last_[kIntensity + 1] = 0;
  last_intensity_.fill(0);
  last_dx_.fill(StreamingMedian5());
  last_dy_.fill(StreamingMedian5());
  last_height_.fill(0);
}

void Point10Coder::Encode(ArithmeticEncoder& encoder, const uint8_t* item) {
  const uint32_t r = item[kFlags] & 7, n = (item[kFlags] >> 3) & 7;
  const uint32_t m = kReturnContext[n][r], l = kReturnLevel[n][r];
  const uint16_t intensity = Load16(item + kIntensity);
  const uint32_t changed =
      ((last_[kFlags] != item[kFlags]) << 5) | ((last_intensity_[m] != intensity) << 4) |
      ((last_[kClass] != item[kClass]) << 3) | ((last_[kScanAngle] != item[kScanAngle]) << 2) |
      ((last_[kUserData] != item[kUserData]) << 1) |
      (Load16(&last_[kPointSource]) != Load16(item + kPointSource));
  encoder.EncodeSymbol(changed_values_, changed);
  if (changed & 32) encoder.EncodeSymbol(ModelIn(flags_[last_[kFlags]]), item[kFlags]);
  if (changed & 16) {
    intensity_.Compress(encoder, last_intensity_[m], intensity, m < 3 ? m : 3);
    last_intensity_[m] = intensity;
  }
  if (changed & 8) encoder.EncodeSymbol(ModelIn(classes_[last_[kClass]]), item[kClass]);
  if (changed & 4) {
    encoder.EncodeSymbol(scan_angle_[(item[kFlags] >> 6) & 1],
                         static_cast<uint8_t>(item[kScanAngle] - last_[kScanAngle]));
  }
  if (changed & 2) encoder.EncodeSymbol(ModelIn(user_data_[last_[kUserData]]), item[kUserData]);
  if (changed & 1) {
    point_source_.Compress(encoder, Load16(&last_[kPointSource]), Load16(item + kPointSource), 0);
  }
  const bool single = n == 1;
  const int32_t dx = static_cast<int32_t>(Load32(item) - Load32(&last_[0]));
  dx_.Compress(encoder, last_dx_[m].Get(), dx, single ? 1 : 0);
  last_dx_[m].Add(dx);
  const int32_t dy = static_cast<int32_t>(Load32(item + 4) - Load32(&last_[4]));
  dy_.Compress(encoder, last_dy_[m].Get(), dy, YContext(dx_.k(), single));
  last_dy_[m].Add(dy);
  const int32_t z = static_cast<int32_t>(Load32(item + 8));
  z_.Compress(encoder, last_height_[l], z, ZContext((dx_.k() + dy_.k()) / 2, single));
  last_height_[l] = z;
  std::memcpy(last_.data(), item, kSize);
}

void Point10Coder::Decode(ArithmeticDecoder& decoder, uint8_t* item) {
  const uint32_t changed = decoder.DecodeSymbol(changed_values_);
  if (changed & 32) {
    last_[kFlags] = static_cast<uint8_t>(decoder.DecodeSymbol(ModelIn(flags_[last_[kFlags]])));
  }
  const uint32_t r = last_[kFlags] & 7, n = (last_[kFlags] >> 3) & 7;
  const uint32_t m = kReturnContext[n][r], l = kReturnLevel[n][r];
  if (changed & 16) {
    last_intensity_[m] =
        static_cast<uint16_t>(intensity_.Decompress(decoder, last_intensity_[m], m < 3 ? m : 3));
  }
  Store16(last_intensity_[m], &last_[kIntensity]);
  if (changed & 8) {
    last_[kClass] = static_cast<uint8_t>(decoder.DecodeSymbol(ModelIn(classes_[last_[kClass]])));
  }
  if (changed & 4) {
    last_[kScanAngle] = static_cast<uint8_t>(
        last_[kScanAngle] + decoder.DecodeSymbol(scan_angle_[(last_[kFlags] >> 6) & 1]));
  }
  if (changed & 2) {
    last_[kUserData] =
        static_cast<uint8_t>(decoder.DecodeSymbol(ModelIn(user_data_[last_[kUserData]])));
  }
  if (changed & 1) {
    Store16(
        static_cast<uint16_t>(point_source_.Decompress(decoder, Load16(&last_[kPointSource]), 0)),
        &last_[kPointSource]);
  }
  const bool single = n == 1;
  const int32_t dx = dx_.Decompress(decoder, last_dx_[m].Get(), single ? 1 : 0);
  Store32(Load32(&last_[0]) + static_cast<uint32_t>(dx), &last_[0]);
  last_dx_[m].Add(dx);
  const int32_t dy = dy_.Decompress(decoder, last_dy_[m].Get(), YContext(dx_.k(), single));
  Store32(Load32(&last_[4]) + static_cast<uint32_t>(dy), &last_[4]);
  last_dy_[m].Add(dy);
  const int32_t z =
      z_.Decompress(decoder, last_height_[l], ZContext((dx_.k() + dy_.k()) / 2, single));
  Store32(static_cast<uint32_t>(z), &last_[8]);
  last_height_[l] = z;
  std::memcpy(item, last_.data(), kSize);
}

namespace {

// The GPS time's multiplier symbols: the difference from the last time as a multiple of the
// last difference, 1 to 499 (500 for any larger), -1 to -9 as 501 to 509 (510 for any
// smaller) and 0; then a time unchanged (version 2 only), a time coded in full (a new
// sequence), and a switch to one of the three other sequences. After a difference of 0 the
// symbols are, in the same order: unchanged (version 2), a difference of 32 bits, in full,
// a switch.
constexpr int32_t kMultiMax = 500;
constexpr int32_t kMultiMin = -10;
constexpr uint32_t kMultiUnchanged = kMultiMax - kMultiMin + 1;  // 511
constexpr uint32_t kMultiSymbols = kMultiMax - kMultiMin + 6;    // 516 (515 in version 3)

// Whether `difference` fits 32 bits, and then it as an int32_t.
bool Fits32(int64_t difference) { return difference == static_cast<int32_t>(difference); }

int32_t Times(int32_t multiplier, int32_t difference) {
  return static_cast<int32_t>(static_cast<uint32_t>(multiplier) *
                              static_cast<uint32_t>(difference));
}

}  // namespace

GpsTimeCoder::GpsTimeCoder(int version)
    : unchanged_symbols_(version == 2 ? 1 : 0),
      multiplier_(kMultiSymbols - 1 + unchanged_symbols_),
      zero_difference_(5 + unchanged_symbols_) {}

int64_t GpsTimeCoder::LoadTime(const uint8_t* item) { return static_cast<int64_t>(Load64(item)); }

void GpsTimeCoder::Reset(int64_t first) {
  multiplier_.Reset();
  zero_difference_.Reset();
  difference_.Reset();
  last_ = next_ = 0;
  last_time_ = {first, 0, 0, 0};
  last_difference_.fill(0);
  extreme_count_.fill(0);
}

void GpsTimeCoder::CountExtreme(int32_t difference) {
  if (++extreme_count_[last_] > 3) {
    last_difference_[last_] = difference;
    extreme_count_[last_] = 0;
  }
}

void GpsTimeCoder::EncodeNewSequence(ArithmeticEncoder& encoder, int64_t time) {
  const uint64_t bits = static_cast<uint64_t>(time);
  difference_.Compress(encoder,
                       static_cast<int32_t>(static_cast<uint64_t>(last_time_[last_]) >> 32),
                       static_cast<int32_t>(bits >> 32), 8);
  encoder.WriteInt(static_cast<uint32_t>(bits));
  next_ = (next_ + 1) & 3;
  last_ = next_;
  last_difference_[last_] = 0;
  extreme_count_[last_] = 0;
  last_time_[last_] = time;
}

void GpsTimeCoder::DecodeNewSequence(ArithmeticDecoder& decoder) {
  const uint32_t high = static_cast<uint32_t>(difference_.Decompress(
      decoder, static_cast<int32_t>(static_cast<uint64_t>(last_time_[last_]) >> 32), 8));
  const uint64_t bits = (uint64_t{high} << 32) | decoder.ReadInt();
  next_ = (next_ + 1) & 3;
  last_ = next_;
  last_time_[last_] = static_cast<int64_t>(bits);
  last_difference_[last_] = 0;
  extreme_count_[last_] = 0;
}

void GpsTimeCoder::Encode(ArithmeticEncoder& encoder, const uint8_t* item) {
  EncodeTime(encoder, static_cast<int64_t>(Load64(item)));
}

void GpsTimeCoder::EncodeTime(ArithmeticEncoder& encoder, int64_t time) {
  const bool after_zero = last_difference_[last_] == 0;
  SymbolModel& model = after_zero ? zero_difference_ : multiplier_;
  // The symbols of a difference of 32 bits after a zero one, and of a time coded in full.
  const uint32_t fits = unchanged_symbols_;
  const uint32_t in_full = after_zero ? fits + 1 : kMultiUnchanged + unchanged_symbols_;
  if (unchanged_symbols_ != 0 && time == last_time_[last_]) {
    encoder.EncodeSymbol(model, after_zero ? 0 : kMultiUnchanged);
    return;
  }
  const int64_t difference64 =
      static_cast<int64_t>(static_cast<uint64_t>(time) - static_cast<uint64_t>(last_time_[last_]));
  if (!Fits32(difference64)) {
    // Another sequence's time, or a new sequence.
    for (uint32_t i = 1; i < 4; ++i) {
      const int64_t other = static_cast<int64_t>(
          static_cast<uint64_t>(time) - static_cast<uint64_t>(last_time_[(last_ + i) & 3]));
      if (Fits32(other)) {
        encoder.EncodeSymbol(model, in_full + i);
        last_ = (last_ + i) & 3;
        EncodeTime(encoder, time);
        return;
      }
    }
    encoder.EncodeSymbol(model, in_full);
    EncodeNewSequence(encoder, time);
    return;
  }
  const int32_t difference = static_cast<int32_t>(difference64);
  if (after_zero) {
    encoder.EncodeSymbol(model, fits);
    difference_.Compress(encoder, 0, difference, 0);
    last_difference_[last_] = difference;
    extreme_count_[last_] = 0;
  } else {
    const int32_t last = last_difference_[last_];
    // The multiplier, rounded as LASzip rounds it (in single precision), clamped to its symbols.
    const float ratio = static_cast<float>(difference) / static_cast<float>(last);
    int32_t multi;
    if (ratio >= static_cast<float>(kMultiMax)) {
      multi = kMultiMax;
    } else if (ratio <= static_cast<float>(kMultiMin)) {
      multi = kMultiMin;
    } else {
      multi = ratio >= 0 ? static_cast<int32_t>(ratio + 0.5f) : static_cast<int32_t>(ratio - 0.5f);
    }
    if (multi == 1) {
      encoder.EncodeSymbol(model, 1);
      difference_.Compress(encoder, last, difference, 1);
      extreme_count_[last_] = 0;
    } else if (multi > 0 && multi < kMultiMax) {
      encoder.EncodeSymbol(model, static_cast<uint32_t>(multi));
      difference_.Compress(encoder, Times(multi, last), difference, multi < 10 ? 2 : 3);
    } else if (multi == kMultiMax) {
      encoder.EncodeSymbol(model, kMultiMax);
      difference_.Compress(encoder, Times(kMultiMax, last), difference, 4);
      CountExtreme(difference);
    } else if (multi < 0 && multi > kMultiMin) {
      encoder.EncodeSymbol(model, static_cast<uint32_t>(kMultiMax - multi));
      difference_.Compress(encoder, Times(multi, last), difference, 5);
    } else if (multi == kMultiMin) {
      encoder.EncodeSymbol(model, static_cast<uint32_t>(kMultiMax - kMultiMin));
      difference_.Compress(encoder, Times(kMultiMin, last), difference, 6);
      CountExtreme(difference);
    } else {  // 0
      encoder.EncodeSymbol(model, 0);
      difference_.Compress(encoder, 0, difference, 7);
      CountExtreme(difference);
    }
  }
  last_time_[last_] = time;
}

void GpsTimeCoder::Decode(ArithmeticDecoder& decoder, uint8_t* item) {
  Store64(static_cast<uint64_t>(DecodeTime(decoder)), item);
}

int64_t GpsTimeCoder::DecodeTime(ArithmeticDecoder& decoder) {
  // Sequence switches are at most three in a row in a valid stream; more are corrupt data,
  // decoded as the time unchanged.
  const uint32_t in_full = kMultiUnchanged + unchanged_symbols_;
  for (int switches = 0; switches < 4; ++switches) {
    if (last_difference_[last_] == 0) {
      const uint32_t symbol = decoder.DecodeSymbol(zero_difference_);
      if (symbol == unchanged_symbols_) {
        last_difference_[last_] = difference_.Decompress(decoder, 0, 0);
        last_time_[last_] =
            static_cast<int64_t>(static_cast<uint64_t>(last_time_[last_]) +
                                 static_cast<uint64_t>(int64_t{last_difference_[last_]}));
        extreme_count_[last_] = 0;
      } else if (symbol == unchanged_symbols_ + 1) {
        DecodeNewSequence(decoder);
      } else if (symbol > unchanged_symbols_ + 1) {
        last_ = (last_ + symbol - unchanged_symbols_ - 1) & 3;
        continue;
      }
      return last_time_[last_];
    }
    const uint32_t symbol = decoder.DecodeSymbol(multiplier_);
    const int32_t last = last_difference_[last_];
    int32_t difference = 0;
    if (symbol == 1) {
      difference = difference_.Decompress(decoder, last, 1);
      extreme_count_[last_] = 0;
    } else if (symbol == 0) {
      difference = difference_.Decompress(decoder, 0, 7);
      CountExtreme(difference);
    } else if (symbol < static_cast<uint32_t>(kMultiMax)) {
      const int32_t multi = static_cast<int32_t>(symbol);
      difference = difference_.Decompress(decoder, Times(multi, last), multi < 10 ? 2 : 3);
    } else if (symbol == static_cast<uint32_t>(kMultiMax)) {
      difference = difference_.Decompress(decoder, Times(kMultiMax, last), 4);
      CountExtreme(difference);
    } else if (symbol < kMultiUnchanged) {
      const int32_t multi = kMultiMax - static_cast<int32_t>(symbol);
      if (multi > kMultiMin) {
        difference = difference_.Decompress(decoder, Times(multi, last), 5);
      } else {
        difference = difference_.Decompress(decoder, Times(kMultiMin, last), 6);
        CountExtreme(difference);
      }
    } else if (symbol < in_full) {  // Unchanged (version 2).
      return last_time_[last_];
    } else if (symbol == in_full) {
      DecodeNewSequence(decoder);
      return last_time_[last_];
    } else {
      last_ = (last_ + symbol - in_full) & 3;
      continue;
    }
    last_time_[last_] = static_cast<int64_t>(static_cast<uint64_t>(last_time_[last_]) +
                                             static_cast<uint64_t>(int64_t{difference}));
    return last_time_[last_];
  }
  return last_time_[last_];
}

RgbModels::RgbModels() : differences(6, SymbolModel(256)) {}

void RgbModels::Reset() {
  changed_bytes.Reset();
  for (SymbolModel& model : differences) model.Reset();
}

uint32_t EncodeRgb(ArithmeticEncoder& encoder, RgbModels& models,
                   const std::array<uint16_t, 3>& last, const std::array<uint16_t, 3>& rgb) {
  uint32_t changed = 0;
  for (int c = 0; c < 3; ++c) {
    changed |= uint32_t{(last[c] & 0x00FF) != (rgb[c] & 0x00FF)} << (2 * c);
    changed |= uint32_t{(last[c] & 0xFF00) != (rgb[c] & 0xFF00)} << (2 * c + 1);
  }
  const bool colored = rgb[0] != rgb[1] || rgb[0] != rgb[2];
  changed |= uint32_t{colored} << 6;
  encoder.EncodeSymbol(models.changed_bytes, changed);
  // Each byte's change from the last record; green's and blue's predicted by red's.
  std::vector<SymbolModel>& differences = models.differences;
  int32_t low = 0, high = 0;
  if (changed & 1) {
    low = (rgb[0] & 0xFF) - (last[0] & 0xFF);
    encoder.EncodeSymbol(differences[0], static_cast<uint8_t>(low));
  }
  if (changed & 2) {
    high = (rgb[0] >> 8) - (last[0] >> 8);
    encoder.EncodeSymbol(differences[1], static_cast<uint8_t>(high));
  }
  if (colored) {
    if (changed & 4) {
      const int32_t corrector = (rgb[1] & 0xFF) - Clamp8(low + (last[1] & 0xFF));
      encoder.EncodeSymbol(differences[2], static_cast<uint8_t>(corrector));
    }
    if (changed & 16) {
      low = (low + (rgb[1] & 0xFF) - (last[1] & 0xFF)) / 2;
      const int32_t corrector = (rgb[2] & 0xFF) - Clamp8(low + (last[2] & 0xFF));
      encoder.EncodeSymbol(differences[4], static_cast<uint8_t>(corrector));
    }
    if (changed & 8) {
      const int32_t corrector = (rgb[1] >> 8) - Clamp8(high + (last[1] >> 8));
      encoder.EncodeSymbol(differences[3], static_cast<uint8_t>(corrector));
    }
    if (changed & 32) {
      high = (high + (rgb[1] >> 8) - (last[1] >> 8)) / 2;
      const int32_t corrector = (rgb[2] >> 8) - Clamp8(high + (last[2] >> 8));
      encoder.EncodeSymbol(differences[5], static_cast<uint8_t>(corrector));
    }
  }
  return changed;
}

std::array<uint16_t, 3> DecodeRgb(ArithmeticDecoder& decoder, RgbModels& models,
                                  const std::array<uint16_t, 3>& last) {
  const uint32_t changed = decoder.DecodeSymbol(models.changed_bytes);
  std::array<uint16_t, 3> rgb;
  auto decode_byte = [&](int model, int32_t predicted) {
    return static_cast<uint8_t>(decoder.DecodeSymbol(models.differences[model]) + predicted);
  };
  rgb[0] = changed & 1 ? decode_byte(0, last[0] & 0xFF) : last[0] & 0xFF;
  rgb[0] |= (changed & 2 ? decode_byte(1, last[0] >> 8) : last[0] >> 8) << 8;
  if (changed & 64) {
    int32_t low = (rgb[0] & 0xFF) - (last[0] & 0xFF);
    rgb[1] = changed & 4 ? decode_byte(2, Clamp8(low + (last[1] & 0xFF))) : last[1] & 0xFF;
    if (changed & 16) {
      low = (low + (rgb[1] & 0xFF) - (last[1] & 0xFF)) / 2;
      rgb[2] = decode_byte(4, Clamp8(low + (last[2] & 0xFF)));
    } else {
      rgb[2] = last[2] & 0xFF;
    }
    int32_t high = (rgb[0] >> 8) - (last[0] >> 8);
    rgb[1] |= (changed & 8 ? decode_byte(3, Clamp8(high + (last[1] >> 8))) : last[1] >> 8) << 8;
    if (changed & 32) {
      high = (high + (rgb[1] >> 8) - (last[1] >> 8)) / 2;
      rgb[2] |= decode_byte(5, Clamp8(high + (last[2] >> 8))) << 8;
    } else {
      rgb[2] |= last[2] & 0xFF00;
    }
  } else {
    rgb[1] = rgb[2] = rgb[0];
  }
  return rgb;
}

void Rgb12Coder::Reset(const uint8_t* first) {
  models_.Reset();
  for (int c = 0; c < 3; ++c) last_[c] = Load16(first + 2 * c);
}

void Rgb12Coder::Encode(ArithmeticEncoder& encoder, const uint8_t* item) {
  std::array<uint16_t, 3> rgb;
  for (int c = 0; c < 3; ++c) rgb[c] = Load16(item + 2 * c);
  EncodeRgb(encoder, models_, last_, rgb);
  last_ = rgb;
}

void Rgb12Coder::Decode(ArithmeticDecoder& decoder, uint8_t* item) {
  last_ = DecodeRgb(decoder, models_, last_);
  for (int c = 0; c < 3; ++c) Store16(last_[c], item + 2 * c);
}

BytesCoder::BytesCoder(size_t count) : models_(count, SymbolModel(256)), last_(count) {}

void BytesCoder::Reset(const uint8_t* first) {
  for (SymbolModel& model : models_) model.Reset();
  std::memcpy(last_.data(), first, last_.size());
}

void BytesCoder::Encode(ArithmeticEncoder& encoder, const uint8_t* item) {
  for (size_t i = 0; i < last_.size(); ++i) {
    encoder.EncodeSymbol(models_[i], static_cast<uint8_t>(item[i] - last_[i]));
    last_[i] = item[i];
  }
}

void BytesCoder::Decode(ArithmeticDecoder& decoder, uint8_t* item) {
  for (size_t i = 0; i < last_.size(); ++i) {
    last_[i] = static_cast<uint8_t>(last_[i] + decoder.DecodeSymbol(models_[i]));
    item[i] = last_[i];
  }
}

}  // namespace neuralmesh::io_internal::laz
