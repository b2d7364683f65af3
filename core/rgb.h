// An 8-bit RGB colour, as scanners and PLY files carry them, and the conversions the file
// formats need: channels given as fractions in [0, 1] (OBJ, float PLY properties, Draco float
// attributes) or as wider integers (16-bit PLY properties).
#ifndef NEURALMESH_CORE_RGB_H_
#define NEURALMESH_CORE_RGB_H_

#include <array>
#include <cmath>
#include <cstdint>

namespace neuralmesh {

using Rgb = std::array<uint8_t, 3>;

// round(255 * fraction), clamped to [0, 255]; NaN gives 0.
inline uint8_t ChannelFromFraction(double fraction) {
  if (!(fraction > 0)) return 0;
  if (fraction >= 1) return 255;
  return static_cast<uint8_t>(std::lround(fraction * 255.0));
}

// A channel stored as an integer of `max` levels above zero (255 for 8 bits, 65535 for 16),
// rescaled to 8 bits and clamped to [0, 255].
inline uint8_t ChannelFromLevel(double level, double max) {
  return ChannelFromFraction(level / max);
}

// The channel as a fraction in [0, 1].
inline float ChannelFraction(uint8_t channel) { return static_cast<float>(channel) / 255.0f; }

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_RGB_H_
