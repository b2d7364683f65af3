#include "core/next_float.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

uint32_t Bits(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

float FromBits(uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

// Bitwise what std::nextafter(f, +infinity) gives, NaN for NaN.
void ExpectSameAsNextafter(float f) {
  const float expected = std::nextafter(f, std::numeric_limits<float>::infinity());
  const float got = NextFloatUp(f);
  if (std::isnan(expected)) {
    EXPECT_TRUE(std::isnan(got)) << "bits " << Bits(f);
  } else {
    EXPECT_EQ(Bits(got), Bits(expected)) << "bits " << Bits(f) << ", value " << f;
  }
}

TEST(NextFloatUpTest, MatchesNextafterAtTheSpecialValues) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  constexpr float kMax = std::numeric_limits<float>::max();
  constexpr float kMin = std::numeric_limits<float>::min();
  constexpr float kDenorm = std::numeric_limits<float>::denorm_min();
  for (const float f : {0.0f, -0.0f, kDenorm, -kDenorm, kMin, -kMin, kMax, -kMax, kInf, -kInf,
                        1.0f, -1.0f, std::numeric_limits<float>::quiet_NaN()}) {
    ExpectSameAsNextafter(f);
  }
}

// Every 9973rd bit pattern (a prime stride, so every exponent and sign is met), about 430,000
// floats of both signs, subnormals and NaNs included. (All 2^32 matched when checked once.)
TEST(NextFloatUpTest, MatchesNextafterAcrossTheBitPatterns) {
  for (uint64_t bits = 0; bits < (uint64_t{1} << 32); bits += 9973) {
    ExpectSameAsNextafter(FromBits(static_cast<uint32_t>(bits)));
    if (HasFailure()) return;
  }
}

}  // namespace
}  // namespace neuralmesh
