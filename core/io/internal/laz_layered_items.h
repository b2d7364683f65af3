// LASzip's layered coders (item versions 3 and 4) for the records of LAS 1.4's point formats 6
// to 8: the 30 bytes every record starts with (POINT14), the colour (RGB14), the colour and
// near infrared (RGBNIR14), and extra bytes (BYTE14).
//
// Unlike the coders of laz_items.h, these code each field (or group of fields) into a layer of
// its own, an arithmetic-coded stream per chunk, and leave out a layer whose field never
// changes within the chunk. They keep their models and last values apart per scanner channel
// (the record's 2-bit channel, up to four scanners of one system): POINT14 codes a switch of
// channel and predicts from the channel's own last record. A channel first seen within a chunk
// starts from the last record of the channel before it.
//
// The items after POINT14 (colour, extra bytes) take their channel from it as LASzip passes it
// on: the new channel in a record that switches, channel 0 in every other record (LASzip's
// reader and writer start each record's context at 0, and POINT14 sets it only at a switch).
// So for a scanner other than 0 they switch back and forth; files of several channels must be
// coded so to be read by LASzip. And at their switch to a channel seen before in the chunk, they
// predict that one record from, and store it as, the last record of the channel they leave.
// Version 4 (newer LASzip) fixes both: POINT14 passes every record's own channel on, and a
// switch predicts from the new channel's last record. Versions 3 and 4 are read and written;
// every LAZ reader reads version 3, only newer LASzip version 4 (laz-perf reads it as 3).
//
// One instance either encodes or decodes. A chunk starts with its first record, which the chunk
// holds raw (Start*); the others are coded one by one; encoding ends with the layers' bytes.
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAZ_LAYERED_ITEMS_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAZ_LAYERED_ITEMS_H_

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"
#include "core/io/internal/laz_arithmetic_coder.h"
#include "core/io/internal/laz_integer_coder.h"
#include "core/io/internal/laz_items.h"

namespace neuralmesh::io_internal::laz {

// The layers of one item in one chunk: an encoder per layer while encoding, a decoder per layer
// present while decoding.
class Layers {
 public:
  explicit Layers(size_t count);
  size_t count() const { return bytes_.size(); }

  // Every layer empty and left out until MarkChanged.
  void StartEncoding();
  ArithmeticEncoder& encoder(size_t layer) { return *encoders_[layer]; }
  void MarkChanged(size_t layer) { changed_[layer] = true; }
  // Ends the encoders and appends each layer's bytes to `layers`, empty for one left out.
  void FinishEncoding(std::vector<std::string>* layers);

  // `layers` points to count() layers' bytes, empty for one left out.
  void StartDecoding(const absl::string_view* layers);
  bool present(size_t layer) const { return decoders_[layer].has_value(); }
  ArithmeticDecoder& decoder(size_t layer) { return *decoders_[layer]; }
  // The most bytes any layer's decoder read past its layer's end (a truncated or corrupt one).
  size_t overrun() const;

 private:
  std::vector<std::string> bytes_;
  std::vector<std::optional<ArithmeticEncoder>> encoders_;
  std::vector<std::optional<ArithmeticDecoder>> decoders_;
  std::vector<bool> changed_;
};

// The fields of the first 30 bytes of a record of formats 6 to 10.
struct Point14 {
  int32_t x = 0, y = 0, z = 0;
  uint16_t intensity = 0;
  uint8_t return_number = 0, returns = 0;  // 4 bits each.
  // Classification flags (bits 0-3), the scan direction (bit 4) and the edge of the flight line
  // (bit 5), as LASzip codes them together.
  uint8_t flags = 0;
  uint8_t channel = 0;  // The scanner channel, 0 to 3.
  uint8_t classification = 0, user_data = 0;
  int16_t scan_angle = 0;
  uint16_t point_source = 0;
  int64_t gps_time = 0;  // The double's bits.

  static Point14 Load(const uint8_t* record);
  void Store(uint8_t* record) const;
};

// POINT14 in nine layers: the returns, scanner channel, X and Y; Z; the classification; the
// flags; the intensity; the scan angle; the user data; the point source; the GPS time.
class Point14Coder {
 public:
  static constexpr size_t kSize = 30;
  explicit Point14Coder(int version);
  ~Point14Coder();
  Layers& layers() { return layers_; }

  // Start* set `channel` to the first record's scanner channel; Encode and Decode set it to the
  // record's channel, in version 3 only when it switches channels. It is the channel the items
  // after POINT14 code the record in.
  void StartEncoding(const uint8_t* first, uint32_t& channel);
  void Encode(const uint8_t* item, uint32_t& channel);
  void StartDecoding(const uint8_t* first, uint32_t& channel, const absl::string_view* layers);
  void Decode(uint8_t* item, uint32_t& channel);

 private:
  struct Channel;
  void StartChannel(uint32_t channel, const Point14& last);

  int version_;
  Layers layers_;
  std::array<std::unique_ptr<Channel>, 4> channels_;
  std::array<bool, 4> in_chunk_{};
  uint32_t current_ = 0;
};

// The models and last values of an item after POINT14, one set per scanner channel, switched
// as LASzip switches them (above). `Channel` holds `Last last` and has Reset(last), which resets
// its models and takes those last values; it may be incomplete here.
template <typename Channel, typename Last>
class ChannelContexts {
 public:
  explicit ChannelContexts(int version) : version_(version) {}

  // A chunk starts in `channel` with `first`'s values; the other channels are unseen.
  void Start(uint32_t channel, const Last& first) {
    in_chunk_.fill(false);
    current_ = channel;
    StartChannel(channel, first);
  }
  // Switches to `channel` for a record and returns the channel whose last values the record is
  // predicted from and stored as: at a switch to a channel seen before in the chunk, the one
  // left in version 3. models() codes it.
  Channel& Switch(uint32_t channel) {
    Channel* predictor = channels_[current_].get();
    if (channel != current_) {
      current_ = channel;
      if (!in_chunk_[channel]) {
        StartChannel(channel, predictor->last);
        predictor = channels_[channel].get();
      } else if (version_ >= 4) {
        predictor = channels_[channel].get();
      }
    }
    return *predictor;
  }
  Channel& models() { return *channels_[current_]; }

 private:
  void StartChannel(uint32_t channel, const Last& last) {
    if (channels_[channel] == nullptr) channels_[channel] = std::make_unique<Channel>();
    channels_[channel]->Reset(last);
    in_chunk_[channel] = true;
  }

  int version_;
  std::array<std::unique_ptr<Channel>, 4> channels_;
  std::array<bool, 4> in_chunk_{};
  uint32_t current_ = 0;
};

// RGB14 (red, green and blue in one layer) or RGBNIR14 (and the near infrared in a second).
class Rgb14Coder {
 public:
  Rgb14Coder(bool near_infrared, int version);
  ~Rgb14Coder();
  size_t size() const { return near_infrared_ ? 8 : 6; }
  Layers& layers() { return layers_; }

  // `channel` is the channel POINT14 passes on.
  void StartEncoding(const uint8_t* first, uint32_t channel);
  void Encode(const uint8_t* item, uint32_t channel);
  void StartDecoding(const uint8_t* first, uint32_t channel, const absl::string_view* layers);
  void Decode(uint8_t* item, uint32_t channel);

 private:
  struct Channel;

  bool near_infrared_;
  Layers layers_;
  ChannelContexts<Channel, std::array<uint16_t, 4>> channels_;  // Red, green, blue, infrared.
};

// BYTE14: each extra byte in a layer of its own, coded as its change from the last record's.
class Bytes14Coder {
 public:
  Bytes14Coder(size_t count, int version);
  ~Bytes14Coder();
  size_t size() const { return count_; }
  Layers& layers() { return layers_; }

  void StartEncoding(const uint8_t* first, uint32_t channel);
  void Encode(const uint8_t* item, uint32_t channel);
  void StartDecoding(const uint8_t* first, uint32_t channel, const absl::string_view* layers);
  void Decode(uint8_t* item, uint32_t channel);

 private:
  struct Channel;

  size_t count_;
  Layers layers_;
  ChannelContexts<Channel, std::vector<uint8_t>> channels_;
};

}  // namespace neuralmesh::io_internal::laz

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAZ_LAYERED_ITEMS_H_
