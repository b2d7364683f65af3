#include "core/io/internal/laz_layered_items.h"

#include <algorithm>
#include <cstdlib>
#include <utility>

#include "core/io/internal/binary.h"

namespace neuralmesh::io_internal::laz {
namespace {

template <typename T>
T Get(const uint8_t* p) {
  return LoadScalar<T>(reinterpret_cast<const char*>(p), /*big_endian=*/false);
}

// Which of 6 contexts X and Y are predicted in, by the number of returns n (row) and the return
// number r (column): LASzip's table, single, first, last and intermediate returns apart.
constexpr uint8_t kReturnMap[16][16] = {{0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5},
                                        {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
                                        {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3},
                                        {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                        {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                        {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                        {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                        {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
                                        {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4},
                                        {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
                                        {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4},
                                        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
                                        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4},
                                        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
                                        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5},
                                        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};

// Which of 8 contexts Z is predicted in: how far the return is from the last one, at most 7.
uint32_t ReturnLevel(uint32_t n, uint32_t r) {
  return std::min<uint32_t>(static_cast<uint32_t>(std::abs(static_cast<int>(n - r))), 7);
}

// Single (3), first (1), last (2) or intermediate (0) return. LASzip's sources number first
// and last both ways round (its version 3 reader as here; its version 4 writer and laz-perf
// the other way): the numbering only names the intensity's contexts, alike on both sides, so
// the bytes are the same.
uint32_t ReturnKind(uint32_t n, uint32_t r) { return (r == 1 ? 1 : 0) + (r >= n ? 2 : 0); }

enum Point14Layer : size_t {
  kReturnsXY,
  kZ,
  kClassification,
  kFlags,
  kIntensity,
  kScanAngle,
  kUserData,
  kPointSource,
  kGpsTime,
  kPoint14Layers
};

}  // namespace

Layers::Layers(size_t count)
    : bytes_(count), encoders_(count), decoders_(count), changed_(count, false) {}

void Layers::StartEncoding() {
  for (size_t i = 0; i < count(); ++i) {
    bytes_[i].clear();
    encoders_[i].emplace(&bytes_[i]);
    changed_[i] = false;
  }
}

void Layers::FinishEncoding(std::vector<std::string>* layers) {
  for (size_t i = 0; i < count(); ++i) {
    encoders_[i]->Done();
    layers->push_back(changed_[i] ? std::move(bytes_[i]) : std::string());
  }
}

void Layers::StartDecoding(const absl::string_view* layers) {
  for (size_t i = 0; i < count(); ++i) {
    decoders_[i].reset();
    if (!layers[i].empty()) decoders_[i].emplace(layers[i]);
  }
}

size_t Layers::overrun() const {
  size_t most = 0;
  for (const std::optional<ArithmeticDecoder>& decoder : decoders_) {
    if (decoder.has_value()) most = std::max(most, decoder->overrun());
  }
  return most;
}

Point14 Point14::Load(const uint8_t* record) {
  Point14 p;
  p.x = Get<int32_t>(record);
  p.y = Get<int32_t>(record + 4);
  p.z = Get<int32_t>(record + 8);
  p.intensity = Get<uint16_t>(record + 12);
  p.return_number = record[14] & 0x0F;
  p.returns = record[14] >> 4;
  p.flags = static_cast<uint8_t>((record[15] & 0x0F) | ((record[15] >> 2) & 0x30));
  p.channel = (record[15] >> 4) & 3;
  p.classification = record[16];
  p.user_data = record[17];
  p.scan_angle = Get<int16_t>(record + 18);
  p.point_source = Get<uint16_t>(record + 20);
  p.gps_time = Get<int64_t>(record + 22);
  return p;
}

void Point14::Store(uint8_t* record) const {
  StoreLittleEndian(x, record);
  StoreLittleEndian(y, record + 4);
  StoreLittleEndian(z, record + 8);
  StoreLittleEndian(intensity, record + 12);
  record[14] = static_cast<uint8_t>((return_number & 0x0F) | (returns << 4));
  record[15] = static_cast<uint8_t>((flags & 0x0F) | ((channel & 3) << 4) | ((flags & 0x30) << 2));
  record[16] = classification;
  record[17] = user_data;
  StoreLittleEndian(scan_angle, record + 18);
  StoreLittleEndian(point_source, record + 20);
  StoreLittleEndian(gps_time, record + 22);
}

// The models and last values of one scanner channel.
struct Point14Coder::Channel {
  void Reset(const Point14& first) {
    for (SymbolModel& model : changed_values) model.Reset();
    scanner_channel.Reset();
    return_number_gps_same.Reset();
    for (auto* models : {&number_of_returns, &return_number}) {
      for (std::optional<SymbolModel>& model : *models) {
        if (model.has_value()) model->Reset();
      }
    }
    for (auto* models : {&classification, &flags, &user_data}) {
      for (std::optional<SymbolModel>& model : *models) {
        if (model.has_value()) model->Reset();
      }
    }
    for (IntegerCoder* coder : {&dx, &dy, &z, &intensity, &scan_angle, &point_source}) {
      coder->Reset();
    }
    gps_time.Reset(first.gps_time);
    last_dx.fill(StreamingMedian5());
    last_dy.fill(StreamingMedian5());
    last_z.fill(first.z);
    last_intensity.fill(first.intensity);
    last = first;
    last_gps_time_changed = false;
  }

  // Which fields changed, by the last record's kind of return and whether its time changed.
  std::vector<SymbolModel> changed_values = std::vector<SymbolModel>(8, SymbolModel(128));
  SymbolModel scanner_channel{3};  // The new channel's distance from this one, less 1.
  std::array<std::optional<SymbolModel>, 16> number_of_returns, return_number;  // By the last.
  SymbolModel return_number_gps_same{13};
  IntegerCoder dx{32, 2}, dy{32, 22}, z{32, 20};
  std::array<std::optional<SymbolModel>, 64> classification, flags, user_data;
  IntegerCoder intensity{16, 4}, scan_angle{16, 2}, point_source{16, 1};
  GpsTimeCoder gps_time{3};
  std::array<StreamingMedian5, 12> last_dx, last_dy;
  std::array<int32_t, 8> last_z{};
  std::array<uint16_t, 8> last_intensity{};
  Point14 last;
  bool last_gps_time_changed = false;
};

Point14Coder::Point14Coder(int version) : version_(version), layers_(kPoint14Layers) {}
Point14Coder::~Point14Coder() = default;

void Point14Coder::StartChannel(uint32_t channel, const Point14& last) {
  if (channels_[channel] == nullptr) channels_[channel] = std::make_unique<Channel>();
  channels_[channel]->Reset(last);
  in_chunk_[channel] = true;
}

void Point14Coder::StartEncoding(const uint8_t* first, uint32_t& channel) {
  layers_.StartEncoding();
  // LASzip writes the returns, X and Y, and Z whether they change or not.
  layers_.MarkChanged(kReturnsXY);
  layers_.MarkChanged(kZ);
  const Point14 point = Point14::Load(first);
  in_chunk_.fill(false);
  current_ = channel = point.channel;
  StartChannel(current_, point);
}

void Point14Coder::StartDecoding(const uint8_t* first, uint32_t& channel,
                                 const absl::string_view* layers) {
  layers_.StartDecoding(layers);
  const Point14 point = Point14::Load(first);
  in_chunk_.fill(false);
  current_ = channel = point.channel;
  StartChannel(current_, point);
}

void Point14Coder::Encode(const uint8_t* item, uint32_t& channel) {
  const Point14 p = Point14::Load(item);
  Channel* c = channels_[current_].get();
  const uint32_t last_kind =
      ReturnKind(c->last.returns, c->last.return_number) + (c->last_gps_time_changed ? 4 : 0);
  // The fields are compared with the last record of the record's own channel.
  const bool switched = p.channel != current_;
  const Point14& base =
      switched && in_chunk_[p.channel] ? channels_[p.channel]->last : channels_[current_]->last;
  const bool point_source_changed = p.point_source != base.point_source;
  const bool gps_time_changed = p.gps_time != base.gps_time;
  const bool scan_angle_changed = p.scan_angle != base.scan_angle;
  const uint32_t last_n = base.returns, last_r = base.return_number;
  const uint32_t n = p.returns, r = p.return_number;
  uint32_t changed = (uint32_t{switched} << 6) | (uint32_t{point_source_changed} << 5) |
                     (uint32_t{gps_time_changed} << 4) | (uint32_t{scan_angle_changed} << 3) |
                     (uint32_t{n != last_n} << 2);
  if (r != last_r) {
    changed |= r == ((last_r + 1) & 15) ? 1 : r == ((last_r + 15) & 15) ? 2 : 3;
  }
  ArithmeticEncoder& xy = layers_.encoder(kReturnsXY);
  xy.EncodeSymbol(c->changed_values[last_kind], changed);
  if (switched) {
    xy.EncodeSymbol(c->scanner_channel, (p.channel + 4 - current_ - 1) & 3);
    if (!in_chunk_[p.channel]) StartChannel(p.channel, c->last);
    current_ = channel = p.channel;
    c = channels_[current_].get();
  }
  if (version_ >= 4) channel = current_;
  Point14& last = c->last;
  if (changed & 4) xy.EncodeSymbol(ModelIn(c->number_of_returns[last_n], 16), n);
  if ((changed & 3) == 3) {
    if (gps_time_changed) {
      xy.EncodeSymbol(ModelIn(c->return_number[last_r], 16), r);
    } else {
      xy.EncodeSymbol(c->return_number_gps_same, (r + 16 - last_r - 2) & 15);
    }
  }
  const uint32_t m = kReturnMap[n][r], l = ReturnLevel(n, r), kind = ReturnKind(n, r);
  const bool single = n == 1;
  const uint32_t xy_context = (m << 1) | (gps_time_changed ? 1 : 0);
  const int32_t dx =
      static_cast<int32_t>(static_cast<uint32_t>(p.x) - static_cast<uint32_t>(last.x));
  c->dx.Compress(xy, c->last_dx[xy_context].Get(), dx, single ? 1 : 0);
  c->last_dx[xy_context].Add(dx);
  const int32_t dy =
      static_cast<int32_t>(static_cast<uint32_t>(p.y) - static_cast<uint32_t>(last.y));
  c->dy.Compress(xy, c->last_dy[xy_context].Get(), dy, YContext(c->dx.k(), single));
  c->last_dy[xy_context].Add(dy);

  c->z.Compress(layers_.encoder(kZ), c->last_z[l], p.z,
                ZContext((c->dx.k() + c->dy.k()) / 2, single));
  c->last_z[l] = p.z;

  if (p.classification != last.classification) layers_.MarkChanged(kClassification);
  const uint32_t class_context = ((last.classification & 0x1Fu) << 1) + (kind == 3 ? 1 : 0);
  layers_.encoder(kClassification)
      .EncodeSymbol(ModelIn(c->classification[class_context]), p.classification);

  if (p.flags != last.flags) layers_.MarkChanged(kFlags);
  layers_.encoder(kFlags).EncodeSymbol(ModelIn(c->flags[last.flags], 64), p.flags);

  if (p.intensity != last.intensity) layers_.MarkChanged(kIntensity);
  const uint32_t intensity_context = (kind << 1) | (gps_time_changed ? 1 : 0);
  c->intensity.Compress(layers_.encoder(kIntensity), c->last_intensity[intensity_context],
                        p.intensity, kind);
  c->last_intensity[intensity_context] = p.intensity;

  if (scan_angle_changed) {
    layers_.MarkChanged(kScanAngle);
    c->scan_angle.Compress(layers_.encoder(kScanAngle), last.scan_angle, p.scan_angle,
                           gps_time_changed ? 1 : 0);
  }
  if (p.user_data != last.user_data) layers_.MarkChanged(kUserData);
  layers_.encoder(kUserData).EncodeSymbol(ModelIn(c->user_data[last.user_data / 4]), p.user_data);
  if (point_source_changed) {
    layers_.MarkChanged(kPointSource);
    c->point_source.Compress(layers_.encoder(kPointSource), last.point_source, p.point_source, 0);
  }
  if (gps_time_changed) {
    layers_.MarkChanged(kGpsTime);
    c->gps_time.EncodeTime(layers_.encoder(kGpsTime), p.gps_time);
  }
  last = p;
  c->last_gps_time_changed = gps_time_changed;
}

void Point14Coder::Decode(uint8_t* item, uint32_t& channel) {
  Channel* c = channels_[current_].get();
  const uint32_t last_kind =
      ReturnKind(c->last.returns, c->last.return_number) + (c->last_gps_time_changed ? 4 : 0);
  ArithmeticDecoder& xy = layers_.decoder(kReturnsXY);
  const uint32_t changed = xy.DecodeSymbol(c->changed_values[last_kind]);
  if (changed & 64) {
    const uint32_t next = (current_ + xy.DecodeSymbol(c->scanner_channel) + 1) & 3;
    if (!in_chunk_[next]) StartChannel(next, c->last);
    current_ = channel = next;
    c = channels_[current_].get();
    c->last.channel = static_cast<uint8_t>(next);
  }
  if (version_ >= 4) channel = current_;
  Point14& last = c->last;
  const bool gps_time_changed = (changed & 16) != 0;
  const uint32_t last_n = last.returns, last_r = last.return_number;
  const uint32_t n =
      changed & 4 ? xy.DecodeSymbol(ModelIn(c->number_of_returns[last_n], 16)) : last_n;
  uint32_t r = last_r;
  switch (changed & 3) {
    case 1:
      r = (last_r + 1) & 15;
      break;
    case 2:
      r = (last_r + 15) & 15;
      break;
    case 3:
      r = gps_time_changed ? xy.DecodeSymbol(ModelIn(c->return_number[last_r], 16))
                           : (last_r + xy.DecodeSymbol(c->return_number_gps_same) + 2) & 15;
      break;
  }
  last.returns = static_cast<uint8_t>(n);
  last.return_number = static_cast<uint8_t>(r);
  const uint32_t m = kReturnMap[n][r], l = ReturnLevel(n, r), kind = ReturnKind(n, r);
  const bool single = n == 1;
  const uint32_t xy_context = (m << 1) | (gps_time_changed ? 1 : 0);
  const int32_t dx = c->dx.Decompress(xy, c->last_dx[xy_context].Get(), single ? 1 : 0);
  last.x = static_cast<int32_t>(static_cast<uint32_t>(last.x) + static_cast<uint32_t>(dx));
  c->last_dx[xy_context].Add(dx);
  const int32_t dy =
      c->dy.Decompress(xy, c->last_dy[xy_context].Get(), YContext(c->dx.k(), single));
  last.y = static_cast<int32_t>(static_cast<uint32_t>(last.y) + static_cast<uint32_t>(dy));
  c->last_dy[xy_context].Add(dy);

  if (layers_.present(kZ)) {
    last.z = c->z.Decompress(layers_.decoder(kZ), c->last_z[l],
                             ZContext((c->dx.k() + c->dy.k()) / 2, single));
    c->last_z[l] = last.z;
  }
  if (layers_.present(kClassification)) {
    const uint32_t class_context = ((last.classification & 0x1Fu) << 1) + (kind == 3 ? 1 : 0);
    last.classification = static_cast<uint8_t>(
        layers_.decoder(kClassification).DecodeSymbol(ModelIn(c->classification[class_context])));
  }
  if (layers_.present(kFlags)) {
    last.flags = static_cast<uint8_t>(
        layers_.decoder(kFlags).DecodeSymbol(ModelIn(c->flags[last.flags], 64)));
  }
  if (layers_.present(kIntensity)) {
    const uint32_t intensity_context = (kind << 1) | (gps_time_changed ? 1 : 0);
    last.intensity = static_cast<uint16_t>(c->intensity.Decompress(
        layers_.decoder(kIntensity), c->last_intensity[intensity_context], kind));
    c->last_intensity[intensity_context] = last.intensity;
  }
  if (layers_.present(kScanAngle) && (changed & 8) != 0) {
    last.scan_angle = static_cast<int16_t>(c->scan_angle.Decompress(
        layers_.decoder(kScanAngle), last.scan_angle, gps_time_changed ? 1 : 0));
  }
  if (layers_.present(kUserData)) {
    last.user_data = static_cast<uint8_t>(
        layers_.decoder(kUserData).DecodeSymbol(ModelIn(c->user_data[last.user_data / 4])));
  }
  if (layers_.present(kPointSource) && (changed & 32) != 0) {
    last.point_source = static_cast<uint16_t>(
        c->point_source.Decompress(layers_.decoder(kPointSource), last.point_source, 0));
  }
  if (layers_.present(kGpsTime) && gps_time_changed) {
    last.gps_time = c->gps_time.DecodeTime(layers_.decoder(kGpsTime));
  }
  last.Store(item);
  c->last_gps_time_changed = gps_time_changed;
}

struct Rgb14Coder::Channel {
  void Reset(const std::array<uint16_t, 4>& first) {
    rgb.Reset();
    nir_changed.Reset();
    for (SymbolModel& model : nir) model.Reset();
    last = first;
  }

  RgbModels rgb;
  SymbolModel nir_changed{4};
  std::vector<SymbolModel> nir = std::vector<SymbolModel>(2, SymbolModel(256));  // Low, high.
  std::array<uint16_t, 4> last{};  // Red, green, blue, near infrared.
};

Rgb14Coder::Rgb14Coder(bool near_infrared, int version)
    : near_infrared_(near_infrared), layers_(near_infrared ? 2 : 1), channels_(version) {}
Rgb14Coder::~Rgb14Coder() = default;

namespace {

std::array<uint16_t, 4> LoadColor(const uint8_t* item, size_t size) {
  std::array<uint16_t, 4> color{};
  for (size_t i = 0; i < size / 2; ++i) color[i] = Get<uint16_t>(item + 2 * i);
  return color;
}

}  // namespace

void Rgb14Coder::StartEncoding(const uint8_t* first, uint32_t channel) {
  layers_.StartEncoding();
  channels_.Start(channel, LoadColor(first, size()));
}

void Rgb14Coder::StartDecoding(const uint8_t* first, uint32_t channel,
                               const absl::string_view* layers) {
  layers_.StartDecoding(layers);
  channels_.Start(channel, LoadColor(first, size()));
}

void Rgb14Coder::Encode(const uint8_t* item, uint32_t channel) {
  Channel& predictor = channels_.Switch(channel);
  Channel& c = channels_.models();
  const std::array<uint16_t, 4> color = LoadColor(item, size());
  const std::array<uint16_t, 3> last_rgb = {predictor.last[0], predictor.last[1],
                                            predictor.last[2]};
  if (EncodeRgb(layers_.encoder(0), c.rgb, last_rgb, {color[0], color[1], color[2]}) != 0) {
    layers_.MarkChanged(0);
  }
  if (near_infrared_) {
    const uint16_t last = predictor.last[3], nir = color[3];
    const uint32_t changed = uint32_t{(last & 0x00FF) != (nir & 0x00FF)} |
                             (uint32_t{(last & 0xFF00) != (nir & 0xFF00)} << 1);
    ArithmeticEncoder& encoder = layers_.encoder(1);
    encoder.EncodeSymbol(c.nir_changed, changed);
    if (changed & 1) {
      encoder.EncodeSymbol(c.nir[0], static_cast<uint8_t>((nir & 0xFF) - (last & 0xFF)));
    }
    if (changed & 2) encoder.EncodeSymbol(c.nir[1], static_cast<uint8_t>((nir >> 8) - (last >> 8)));
    if (changed != 0) layers_.MarkChanged(1);
  }
  predictor.last = color;
}

void Rgb14Coder::Decode(uint8_t* item, uint32_t channel) {
  Channel& predictor = channels_.Switch(channel);
  Channel& c = channels_.models();
  if (layers_.present(0)) {
    const std::array<uint16_t, 3> rgb = DecodeRgb(
        layers_.decoder(0), c.rgb, {predictor.last[0], predictor.last[1], predictor.last[2]});
    std::copy(rgb.begin(), rgb.end(), predictor.last.begin());
  }
  if (near_infrared_ && layers_.present(1)) {
    ArithmeticDecoder& decoder = layers_.decoder(1);
    const uint16_t last = predictor.last[3];
    const uint32_t changed = decoder.DecodeSymbol(c.nir_changed);
    const uint32_t low = changed & 1
                             ? static_cast<uint8_t>(decoder.DecodeSymbol(c.nir[0]) + (last & 0xFF))
                             : last & 0xFF;
    const uint32_t high = changed & 2
                              ? static_cast<uint8_t>(decoder.DecodeSymbol(c.nir[1]) + (last >> 8))
                              : last >> 8;
    predictor.last[3] = static_cast<uint16_t>(low | (high << 8));
  }
  for (size_t i = 0; i < size() / 2; ++i) StoreLittleEndian(predictor.last[i], item + 2 * i);
}

struct Bytes14Coder::Channel {
  void Reset(const std::vector<uint8_t>& first) {
    if (models.size() != first.size()) models.assign(first.size(), SymbolModel(256));
    for (SymbolModel& model : models) model.Reset();
    last = first;
  }

  std::vector<SymbolModel> models;
  std::vector<uint8_t> last;
};

Bytes14Coder::Bytes14Coder(size_t count, int version)
    : count_(count), layers_(count), channels_(version) {}
Bytes14Coder::~Bytes14Coder() = default;

void Bytes14Coder::StartEncoding(const uint8_t* first, uint32_t channel) {
  layers_.StartEncoding();
  channels_.Start(channel, std::vector<uint8_t>(first, first + count_));
}

void Bytes14Coder::StartDecoding(const uint8_t* first, uint32_t channel,
                                 const absl::string_view* layers) {
  layers_.StartDecoding(layers);
  channels_.Start(channel, std::vector<uint8_t>(first, first + count_));
}

void Bytes14Coder::Encode(const uint8_t* item, uint32_t channel) {
  Channel& predictor = channels_.Switch(channel);
  Channel& c = channels_.models();
  for (size_t i = 0; i < count_; ++i) {
    const uint8_t difference = static_cast<uint8_t>(item[i] - predictor.last[i]);
    layers_.encoder(i).EncodeSymbol(c.models[i], difference);
    if (difference != 0) {
      layers_.MarkChanged(i);
      predictor.last[i] = item[i];
    }
  }
}

void Bytes14Coder::Decode(uint8_t* item, uint32_t channel) {
  Channel& predictor = channels_.Switch(channel);
  Channel& c = channels_.models();
  for (size_t i = 0; i < count_; ++i) {
    if (layers_.present(i)) {
      predictor.last[i] =
          static_cast<uint8_t>(predictor.last[i] + layers_.decoder(i).DecodeSymbol(c.models[i]));
    }
    item[i] = predictor.last[i];
  }
}

}  // namespace neuralmesh::io_internal::laz
