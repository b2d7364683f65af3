// Positions as a reader parses them, kept in double until the last one is known: then the
// origin is chosen and they become floats relative to it. Georeferenced data (UTM eastings of
// 500,000 m, northings of 4,100,000 m) would lose centimetres in a float, and the learner's
// float arithmetic far more; relative to an origin near the points they keep their detail.
#ifndef NEURALMESH_CORE_IO_INTERNAL_POSITION_COLLECTOR_H_
#define NEURALMESH_CORE_IO_INTERNAL_POSITION_COLLECTOR_H_

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include "core/io/internal/geometry_data.h"

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

class PositionCollector {
 public:
  PositionCollector() = default;
  // Takes positions already gathered (each narrowing to a finite float, as for Add).
  explicit PositionCollector(std::vector<Point3d> positions) : positions_(std::move(positions)) {}

  void Reserve(size_t count) { positions_.reserve(count); }
  // `p` must narrow to a finite float (the readers check, to name the offending line).
  void Add(const Point3d& p) { positions_.push_back(p); }
  size_t size() const { return positions_.size(); }
  const Point3d& operator[](size_t i) const { return positions_[i]; }

  // Sets out->positions to the positions relative to out->origin, chosen by
  // OriginKeepingResolution with the step of a file that states none: 1/65,536 of the bounding
  // box's longest side, or on an axis where that box is smaller than a float's step (a single
  // point), of that step. Clears the collector.
  void MoveTo(ParsedGeometry* out);

 private:
  std::vector<Point3d> positions_;
};

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_POSITION_COLLECTOR_H_
