// Positions as a reader parses them, kept in double until the last one is known: then the
// origin is chosen and they become floats relative to it. Georeferenced data (UTM eastings of
// 500,000 m, northings of 4,100,000 m) would lose centimetres in a float, and the learner's
// float arithmetic far more; relative to an origin near the points they keep their detail.
#ifndef NEURALMESH_CORE_IO_INTERNAL_POSITION_COLLECTOR_H_
#define NEURALMESH_CORE_IO_INTERNAL_POSITION_COLLECTOR_H_

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/text.h"

namespace neuralmesh::io_internal {

using Point3d = std::array<double, 3>;

// Per axis, where to put position 0 so that floats keep the data's resolution `step` (the
// finest difference the data resolve, e.g. a LAS file's scale): zero while a float's step at
// the farthest coordinate is at most half of `step`, otherwise the points' minimum `low`
// rounded down to a multiple of 1,000, when that brings them nearer to 0. `low` and `high` are
// the points' bounds; a zero `step` never moves the axis, nor do coordinates beyond 2^40
// (1.1e12, where a double keeps no more than a float relative to such an origin).
Point3d OriginKeepingResolution(const Point3d& low, const Point3d& high, const Point3d& step);

// The power of ten at most 1/2^24 of `farthest` (the largest magnitude of an axis's coordinates
// relative to the origin): the scale of integer coordinates (LAS, E57) that keep what floats
// hold, a float keeping 24 bits. 0.001 for an axis that is zero everywhere.
double IntegerScaleKeepingFloats(double farthest);

// OriginKeepingResolution for points in the box `low`-`high` of a file that states no
// resolution (PositionCollector::MoveTo's rule, below).
Point3d OriginOfUnstatedResolution(const Point3d& low, const Point3d& high);

// How a PositionCollector keeps positions until the last one, and with it the origin, is known.
enum class PositionPrecision {
  // As floats while each is a float exactly (a binary file of float coordinates: 12 bytes a
  // point), as doubles from the first that is not (24 bytes a point; the floats kept before it
  // widen to their values exactly): MoveTo gives what doubles give.
  kExact,
  // As kExact, but a position that a float does not hold exactly (a text file's decimals) is
  // kept as a float too when the first such position lies within kNearZero of 0 on every axis:
  // MoveTo gives what doubles give when the origin comes out 0, as it does for most data, and
  // otherwise sets ParsedGeometry::read_again_exactly. Data far from 0 (georeferenced) keep
  // doubles from the first inexact position, and are read once.
  kFloatsNearZero,
};

class PositionCollector {
 public:
  // Beyond this distance from 0, kFloatsNearZero keeps doubles (UTM eastings start at 166,000).
  static constexpr double kNearZero = 65536;

  explicit PositionCollector(PositionPrecision precision = PositionPrecision::kExact)
      : precision_(precision) {}
  // Takes positions already gathered (each narrowing to a finite float, as for Add).
  explicit PositionCollector(std::vector<Point3d> positions);

  void Reserve(size_t count);
  // `p` must narrow to a finite float (the readers check, to name the offending line).
  void Add(const Point3d& p) {
    for (int c = 0; c < 3; ++c) {
      low_[c] = std::min(low_[c], p[c]);
      high_[c] = std::max(high_[c], p[c]);
    }
    const Vec3f narrowed(Narrowed(p[0]), Narrowed(p[1]), Narrowed(p[2]));
    const bool exact = narrowed[0] == p[0] && narrowed[1] == p[1] && narrowed[2] == p[2];
    if (doubles_.empty() && (exact || inexact_ || KeepsInexactFloat(p))) {
      inexact_ |= !exact;
      floats_.push_back(narrowed);
    } else {
      AddDouble(p);
    }
  }
  size_t size() const { return floats_.size() + doubles_.size(); }

  // Sets out->positions to the positions relative to out->origin, chosen by
  // OriginKeepingResolution with the step of a file that states none: 1/65,536 of the bounding
  // box's longest side, or on an axis where that box is smaller than a float's step (a single
  // point), of that step (or sets out->read_again_exactly: kFloatsNearZero). Clears the
  // collector.
  void MoveTo(ParsedGeometry* out);

 private:
  // NarrowToFloat(value), without its call for a value within a float's range (a cast rounds
  // it alike): every coordinate of every point comes here.
  static float Narrowed(double value) {
    return std::fabs(value) <= std::numeric_limits<float>::max() ? static_cast<float>(value)
                                                                 : NarrowToFloat(value);
  }
  // Whether the first position a float does not hold exactly is kept as a float.
  bool KeepsInexactFloat(const Point3d& p) const {
    return precision_ == PositionPrecision::kFloatsNearZero && std::fabs(p[0]) <= kNearZero &&
           std::fabs(p[1]) <= kNearZero && std::fabs(p[2]) <= kNearZero;
  }
  // Adds `p` as a double, widening the floats kept so far (all exact) first.
  void AddDouble(const Point3d& p);

  PositionPrecision precision_ = PositionPrecision::kExact;
  std::vector<Vec3f> floats_;     // While every position is a float exactly, or inexact_.
  std::vector<Point3d> doubles_;  // From the first that is not (the floats before it first).
  bool inexact_ = false;          // Whether floats_ holds a position a float does not hold.
  size_t reserved_ = 0;
  Point3d low_ = {INFINITY, INFINITY, INFINITY};
  Point3d high_ = {-INFINITY, -INFINITY, -INFINITY};
};

// What parse(precision) reads, in the least memory that gives the positions doubles give: with
// kFloatsNearZero, and again with kExact when the first reading says so (read_again_exactly).
template <typename Parse>
absl::StatusOr<ParsedGeometry> ParseInLeastMemory(const Parse& parse) {
  absl::StatusOr<ParsedGeometry> parsed = parse(PositionPrecision::kFloatsNearZero);
  if (parsed.ok() && parsed->read_again_exactly) {
    parsed = absl::StatusOr<ParsedGeometry>();  // Its memory first.
    parsed = parse(PositionPrecision::kExact);
  }
  return parsed;
}

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_POSITION_COLLECTOR_H_
