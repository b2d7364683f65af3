// The smallest float above a float, as std::nextafter(f, +infinity) gives it, but inline: the
// library call cost a third of the time of a win in SignalCounters::Flush, which rounds a bound
// up to a float at every touch.
#ifndef NEURALMESH_CORE_NEXT_FLOAT_H_
#define NEURALMESH_CORE_NEXT_FLOAT_H_

#include <cstdint>
#include <cstring>
#include <limits>

namespace neuralmesh {

inline float NextFloatUp(float f) {
  if (!(f < std::numeric_limits<float>::infinity())) return f;  // +inf and NaN.
  if (f == 0) return std::numeric_limits<float>::denorm_min();   // From +0 and from -0.
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  bits += f > 0 ? 1u : ~0u;  // The magnitude one step up above zero, one step down below.
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_NEXT_FLOAT_H_
