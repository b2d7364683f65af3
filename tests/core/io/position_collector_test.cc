// PositionCollector keeps positions as floats while each is a float exactly and as doubles from
// the first that is not; either way MoveTo gives what the doubles give: the origin of the
// points' box and each position relative to it, narrowed once.
#include "core/io/internal/position_collector.h"

#include <cmath>
#include <random>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/internal/text.h"
#include "gtest/gtest.h"

namespace neuralmesh::io_internal {
namespace {

// What MoveTo gives for `points`, worked out from their doubles.
ParsedGeometry FromDoubles(const std::vector<Point3d>& points) {
  ParsedGeometry out;
  if (points.empty()) return out;
  Point3d low = points[0], high = points[0];
  for (const Point3d& p : points) {
    for (int c = 0; c < 3; ++c) {
      low[c] = std::min(low[c], p[c]);
      high[c] = std::max(high[c], p[c]);
    }
  }
  out.origin = OriginOfUnstatedResolution(low, high);
  for (const Point3d& p : points) {
    out.positions.push_back(Vec3f(NarrowToFloat(p[0] - out.origin[0]),
                                  NarrowToFloat(p[1] - out.origin[1]),
                                  NarrowToFloat(p[2] - out.origin[2])));
  }
  return out;
}

void ExpectCollectedAlike(const std::vector<Point3d>& points, size_t reserve) {
  PositionCollector collector;
  if (reserve > 0) collector.Reserve(reserve);
  for (const Point3d& p : points) collector.Add(p);
  EXPECT_EQ(collector.size(), points.size());
  ParsedGeometry collected;
  collector.MoveTo(&collected);
  const ParsedGeometry expected = FromDoubles(points);
  EXPECT_EQ(collected.origin, expected.origin);
  EXPECT_EQ(collected.positions, expected.positions);
  EXPECT_EQ(collector.size(), 0u);

  ParsedGeometry given;
  PositionCollector(points).MoveTo(&given);
  EXPECT_EQ(given.origin, expected.origin);
  EXPECT_EQ(given.positions, expected.positions);
}

TEST(PositionCollectorTest, FloatsAndDoublesGiveThePositionsTheDoublesGive) {
  std::mt19937 random(7);
  // A unit-sized scan near 0 and a UTM tile (float-exact coordinates there are a multiple of
  // 1/32 m apart; relative to its origin the floats hold them exactly).
  for (const Point3d& centre : {Point3d{0.1, -0.2, 0.3}, Point3d{500123.0, 4100456.0, 87.0}}) {
    std::uniform_real_distribution<double> around(-5, 5);
    std::vector<Point3d> exact, inexact;
    for (int i = 0; i < 3000; ++i) {
      Point3d p;
      for (int c = 0; c < 3; ++c) p[c] = centre[c] + around(random);
      inexact.push_back(p);
      for (int c = 0; c < 3; ++c) p[c] = static_cast<float>(p[c]);
      exact.push_back(p);
    }
    for (const size_t switch_at : {size_t{0}, size_t{1}, size_t{1500}, size_t{2999}}) {
      SCOPED_TRACE(absl::StrCat("centre ", centre[0], ", doubles from point ", switch_at));
      std::vector<Point3d> mixed = exact;
      for (size_t i = switch_at; i < mixed.size(); i += 7) mixed[i] = inexact[i];
      ExpectCollectedAlike(mixed, 0);
      ExpectCollectedAlike(mixed, mixed.size());
    }
    SCOPED_TRACE("floats only");
    ExpectCollectedAlike(exact, exact.size());
    // Relative to the tile's origin a float keeps more than the floats of the doubles did: a
    // collector that narrowed the doubles on arrival would fail above.
    if (centre[0] > 1000) {
      EXPECT_NE(FromDoubles(exact).positions, FromDoubles(inexact).positions);
    }
  }
  ExpectCollectedAlike({}, 0);
  ExpectCollectedAlike({{1234.5, -0.25, 3}}, 1);
}

// kFloatsNearZero keeps decimals near 0 as floats: right when the origin is 0, and otherwise it
// asks to be read again; decimals far from 0 are kept as doubles from the first.
TEST(PositionCollectorTest, FloatsNearZeroAreKeptUntilTheOriginNeedsDoubles) {
  const auto collect = [](const std::vector<Point3d>& points) {
    PositionCollector collector(PositionPrecision::kFloatsNearZero);
    for (const Point3d& p : points) collector.Add(p);
    ParsedGeometry out;
    collector.MoveTo(&out);
    return out;
  };
  const std::vector<Point3d> near = {{0.1, 0.2, 0.3}, {1.7, -2.9, 0.3}, {2.5, 0.25, -1}};
  ParsedGeometry collected = collect(near);
  EXPECT_FALSE(collected.read_again_exactly);
  EXPECT_EQ(collected.origin, FromDoubles(near).origin);
  EXPECT_EQ(collected.positions, FromDoubles(near).positions);

  // A metre-sized site 3 km out: its origin is not 0, and the floats kept are not its decimals.
  const std::vector<Point3d> site = {{3000.123, 0.5, 0}, {3000.987, 0.25, 1}, {3001.5, 1, 0.5}};
  collected = collect(site);
  EXPECT_TRUE(collected.read_again_exactly);
  EXPECT_TRUE(collected.positions.empty());
  // Exact floats first: still asked again once a decimal came.
  collected = collect({{3000, 0.5, 0}, {3000.987, 0.25, 1}, {3001.5, 1, 0.5}});
  EXPECT_TRUE(collected.read_again_exactly);

  // Far from 0 (a UTM tile): doubles from the first decimal, read once.
  const std::vector<Point3d> tile = {{500000.5, 4100000.25, 100}, {500123.456, 4100234.567, 101.2}};
  collected = collect(tile);
  EXPECT_FALSE(collected.read_again_exactly);
  EXPECT_EQ(collected.origin, FromDoubles(tile).origin);
  EXPECT_EQ(collected.positions, FromDoubles(tile).positions);
}

}  // namespace
}  // namespace neuralmesh::io_internal
