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

// Three levels of `max` above zero each (ChannelFromLevel), as 8-bit channels.
inline Rgb RgbFromLevels(const std::array<uint16_t, 3>& levels, double max) {
  return {ChannelFromLevel(levels[0], max), ChannelFromLevel(levels[1], max),
          ChannelFromLevel(levels[2], max)};
}

// The full scale of integer colour levels that do not say how many bits they use (LAS: 8-bit
// levels in 16-bit fields, or 16-bit ones), from the largest: 255 when none exceeds it, else
// 65535. For ChannelFromLevel.
inline double LevelScale(uint16_t largest_level) { return largest_level <= 255 ? 255.0 : 65535.0; }

// The full scale of the colour channels of a text file that does not say which it uses, from
// its largest channel: 1 when none exceeds 1 (fractions, as MeshLab and CloudCompare write
// them), else 255 (0-255 levels). For ChannelFromLevel.
inline double TextChannelScale(float largest_channel) {
  return largest_channel <= 1.0f ? 1.0 : 255.0;
}

// The channel as a fraction in [0, 1].
inline float ChannelFraction(uint8_t channel) { return static_cast<float>(channel) / 255.0f; }

// Channels are sRGB-encoded, as scanners and PLY files store them; glTF stores vertex colours
// as linear light. The two conversions follow IEC 61966-2-1's transfer function.

// The linear light, in [0, 1], of an sRGB-encoded channel.
inline double LinearFromSrgb(uint8_t channel) {
  const double c = channel / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// The sRGB-encoded channel nearest to linear light `linear`, clamped to [0, 1]; NaN gives 0.
// Exact back from LinearFromSrgb rounded to 16 bits.
inline uint8_t SrgbFromLinear(double linear) {
  if (!(linear > 0)) return 0;
  if (linear >= 1) return 255;
  return ChannelFromFraction(linear <= 0.0031308 ? 12.92 * linear
                                                 : 1.055 * std::pow(linear, 1 / 2.4) - 0.055);
}

// LinearFromSrgb(channel) as a normalized 16-bit integer, as glTF files store vertex colours:
// 8 bits of linear light would merge the darkest sRGB levels.
inline uint16_t LinearShortFromSrgb(uint8_t channel) {
  return static_cast<uint16_t>(std::lround(LinearFromSrgb(channel) * 65535.0));
}

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_RGB_H_
