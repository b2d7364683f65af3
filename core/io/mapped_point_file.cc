#include "core/io/mapped_point_file.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "core/io/internal/pcd.h"
#include "core/io/internal/ply_vertex_records.h"
#include "core/io/internal/position_collector.h"
#include "core/random.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

using io_internal::Point3d;

// Seeds the probe's draws: the same file gives the same probe.
constexpr uint64_t kProbeSeed = 0x6c61735f70726f62;

Vec3 ToVec3(const Point3d& p) { return Vec3(p[0], p[1], p[2]); }
Point3d ToPoint3d(const Vec3& v) { return {v[0], v[1], v[2]}; }

// The records of the file `data` at `path`, by its extension.
absl::StatusOr<std::unique_ptr<io_internal::PointRecords>> RecordsOf(
    const std::string& path, absl::string_view data, const std::optional<LasClasses>& classes) {
  switch (io_internal::FormatFromPath(path)) {
    case io_internal::FileFormat::kLas: {
      if (io_internal::IsLaz(data)) {
        return absl::InvalidArgumentError(
            "LAZ: its records are compressed in chunks and cannot be read one at a time; read "
            "the file whole, or its decompressed LAS file where it lies");
      }
      absl::StatusOr<std::unique_ptr<io_internal::LasRecords>> las =
          io_internal::LasRecords::Create(data, classes);
      if (!las.ok()) return las.status();
      return std::unique_ptr<io_internal::PointRecords>(*std::move(las));
    }
    case io_internal::FileFormat::kPly:
      return io_internal::PlyVertexRecords(data);
    case io_internal::FileFormat::kPcd:
      return io_internal::PcdPointRecords(data);
    default:
      return absl::InvalidArgumentError(
          "only files whose point records all have one size, uncompressed LAS (.las), binary "
          "PLY (.ply) and binary PCD (.pcd), can be read where they lie");
  }
}

}  // namespace

ProbedPlacement PlaceProbe(const BoundingBox& probed, const io_internal::PointRecords& records) {
  // The stated bounds, unless the probe finds them stale: records outside them, or a box more
  // than twice the probe's (which covers nearly all of a scan's extent).
  const std::optional<Point3d> resolution = records.Resolution();
  const Vec3 step = resolution.has_value() ? ToVec3(*resolution) : Vec3(0, 0, 0);
  BoundingBox bounds = probed;
  if (const auto stated_bounds = records.StatedBounds(); stated_bounds.has_value()) {
    const Vec3 low = ToVec3(stated_bounds->first), high = ToVec3(stated_bounds->second);
    BoundingBox stated;
    stated.Extend(low - step);
    stated.Extend(high + step);
    if (std::isfinite(stated.diagonal()) && stated.Contains(probed.min) &&
        stated.Contains(probed.max) &&
        stated.diagonal() <= 2 * probed.diagonal() + 4 * step.norm()) {
      bounds.Extend(low);
      bounds.Extend(high);
    }
  }
  ProbedPlacement out;
  out.origin =
      resolution.has_value()
          ? io_internal::OriginKeepingResolution(ToPoint3d(bounds.min), ToPoint3d(bounds.max),
                                                 *resolution)
          : io_internal::OriginOfUnstatedResolution(ToPoint3d(bounds.min), ToPoint3d(bounds.max));
  const Vec3 origin = ToVec3(out.origin);
  out.bounds.Extend(bounds.min - origin);
  out.bounds.Extend(bounds.max - origin);
  return out;
}

absl::StatusOr<MappedPointFile> MappedPointFile::Open(const std::string& path,
                                                      const std::optional<LasClasses>& classes) {
  NM_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  const auto invalid = [&path](absl::string_view message) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "': ", message));
  };
  absl::StatusOr<std::unique_ptr<io_internal::PointRecords>> records =
      RecordsOf(path, file.data(), classes);
  if (!records.ok()) return invalid(records.status().message());
  if ((*records)->size() == 0) return invalid("the file has no point records");
  MappedPointFile opened(std::move(file), *std::move(records));
  const io_internal::PointRecords& points = *opened.records_;

  BoundingBox probed;
  int kept = 0;
  uint16_t largest_level = 0;
  Random probe(kProbeSeed);
  for (int i = 0; i < kProbeRecords; ++i) {
    const uint64_t r = probe.NextIndex(points.size());
    const std::optional<Vec3> p = PointOfRecord(points, r, kNoOrigin);
    if (!p.has_value()) continue;
    ++kept;
    probed.Extend(*p);
    if (const auto levels = points.ColorLevels(r); levels.has_value()) {
      largest_level = std::max({largest_level, (*levels)[0], (*levels)[1], (*levels)[2]});
    }
  }
  NM_RETURN_IF_ERROR(opened.CheckSize());
  opened.color_scale_ = LevelScale(largest_level);
  opened.kept_share_ = static_cast<double>(kept) / kProbeRecords;
  if (opened.kept_share_ < kLeastKeptShare) {
    return invalid(absl::StrFormat(
        "%d of %d records drawn at random are points to read (the others %s): reading the "
        "file where it lies would take about %s record reads per point; read it whole",
        kept, kProbeRecords,
        io_internal::FormatFromPath(path) != io_internal::FileFormat::kLas
            ? "have a coordinate no float holds"
        : classes.has_value() ? "withheld, noise or of other classes, or beyond a float's range"
                              : "withheld or noise, or beyond a float's range",
        kept == 0 ? std::string("countless") : absl::StrCat(kProbeRecords / kept)));
  }
  const ProbedPlacement placement = PlaceProbe(probed, points);
  opened.origin_ = placement.origin;
  opened.bounds_ = placement.bounds;
  return opened;
}

}  // namespace neuralmesh
