#include "core/io/internal/position_collector.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/io/internal/text.h"

namespace neuralmesh::io_internal {
namespace {

// A float keeps a resolution `step` up to this many steps from zero (24 bits; half a step of
// error at most).
constexpr double kFloatExactSteps = 1 << 22;

// Beyond this distance from zero (1.1e12; a double's step there is 2.4e-4) no data are
// georeferenced: an origin would not keep a resolution that the doubles themselves lost, and
// the origin plus a float could not be held exactly.
constexpr double kFarthestOrigin = 1099511627776.0;  // 2^40

// The steps of a float's significand between a power of two and the next.
constexpr double kFloatSteps = 1 << 24;

// The resolution assumed for a file that states none: 1/65,536 of the bounding box's longest
// side, finer than a reconstruction resolves by far (a mesh of 100,000 vertices has edges of
// about 1/300 of it). Origins are then taken for points farther from 0 than 64 such sides.
constexpr double kUnstatedStepsPerSide = 1 << 16;

}  // namespace

double IntegerScaleKeepingFloats(double farthest) {
  if (!(farthest > 0)) return 0.001;
  return std::pow(10.0, std::floor(std::log10(farthest / kFloatSteps)));
}

Point3d OriginKeepingResolution(const Point3d& low, const Point3d& high, const Point3d& step) {
  Point3d origin = {0, 0, 0};
  for (int c = 0; c < 3; ++c) {
    const double far = std::max(std::fabs(low[c]), std::fabs(high[c]));
    if (!(step[c] > 0) || !(far > kFloatExactSteps * step[c]) || !(far <= kFarthestOrigin)) {
      continue;
    }
    const double candidate = std::floor(low[c] / 1000) * 1000;
    if (std::max(std::fabs(low[c] - candidate), std::fabs(high[c] - candidate)) < far) {
      origin[c] = candidate;
    }
  }
  return origin;
}

Point3d OriginOfUnstatedResolution(const Point3d& low, const Point3d& high) {
  double side = 0;
  for (int c = 0; c < 3; ++c) side = std::max(side, high[c] - low[c]);
  // Points that a float cannot tell apart where they are (a box smaller than a float's step,
  // or a single point) take the step of that box: the same whether their doubles or the
  // floats they became are read, so that what is written reads back alike.
  Point3d step;
  for (int c = 0; c < 3; ++c) {
    const double far = std::max(std::fabs(low[c]), std::fabs(high[c]));
    step[c] = std::max(side, far / kFloatSteps) / kUnstatedStepsPerSide;
  }
  return OriginKeepingResolution(low, high, step);
}

PositionCollector::PositionCollector(std::vector<Point3d> positions) {
  for (const Point3d& p : positions) {
    for (int c = 0; c < 3; ++c) {
      low_[c] = std::min(low_[c], p[c]);
      high_[c] = std::max(high_[c], p[c]);
    }
  }
  doubles_ = std::move(positions);
}

void PositionCollector::Reserve(size_t count) {
  reserved_ = count;
  if (doubles_.empty()) {
    floats_.reserve(count);
  } else {
    doubles_.reserve(count);
  }
}

void PositionCollector::AddDouble(const Point3d& p) {
  if (doubles_.empty()) {
    doubles_.reserve(std::max(reserved_, floats_.size() + 1));
    for (const Vec3f& f : floats_) doubles_.push_back({f[0], f[1], f[2]});
    std::vector<Vec3f>().swap(floats_);
  }
  doubles_.push_back(p);
}

void PositionCollector::MoveTo(ParsedGeometry* out) {
  out->origin = {0, 0, 0};
  if (size() > 0) out->origin = OriginOfUnstatedResolution(low_, high_);
  const Point3d& origin = out->origin;
  out->read_again_exactly = inexact_ && origin != Point3d{0, 0, 0};
  if (out->read_again_exactly) {
    out->positions.clear();
  } else if (doubles_.empty()) {
    // Each float is its position exactly: relative to the origin, in place.
    out->positions = std::move(floats_);
    if (origin != Point3d{0, 0, 0}) {
      for (Vec3f& p : out->positions) {
        for (int c = 0; c < 3; ++c) p[c] = NarrowToFloat(double{p[c]} - origin[c]);
      }
    }
  } else {
    out->positions.resize(doubles_.size());
    for (size_t i = 0; i < doubles_.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        // Nearer to 0 than the coordinate itself, which narrows to a finite float.
        out->positions[i][c] = NarrowToFloat(doubles_[i][c] - origin[c]);
      }
    }
  }
  *this = PositionCollector();
}

}  // namespace neuralmesh::io_internal
