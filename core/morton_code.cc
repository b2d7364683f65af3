#include "core/morton_code.h"

#include <algorithm>
#include <cmath>

namespace neuralmesh {
namespace {

constexpr int kBitsPerAxis = 21;  // 3 * 21 bits fit one 64-bit code.

// Spreads the low 21 bits of x so that two zero bits follow each of them.
uint64_t SpreadBits(uint64_t x) {
  x &= (uint64_t{1} << kBitsPerAxis) - 1;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

uint64_t Quantise(double x, double min, double max) {
  constexpr double kCells = static_cast<double>(uint64_t{1} << kBitsPerAxis);
  const double extent = max - min;
  if (!(extent > 0)) return 0;
  const double cell = std::floor((x - min) / extent * kCells);
  if (!(cell > 0)) return 0;  // Also NaN.
  return static_cast<uint64_t>(std::min(cell, kCells - 1));
}

}  // namespace

uint64_t MortonCode(const Vec3& p, const Vec3& min, const Vec3& max) {
  return SpreadBits(Quantise(p[0], min[0], max[0])) |
         SpreadBits(Quantise(p[1], min[1], max[1])) << 1 |
         SpreadBits(Quantise(p[2], min[2], max[2])) << 2;
}

}  // namespace neuralmesh
