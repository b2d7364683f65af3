// A point file whose records all have one size (uncompressed LAS, binary PLY, binary PCD),
// mapped into memory and read one record at a time where it lies, never whole: what off-core
// sampling (core/sampling/off_core_sampler.h) and the upload of a file read where it lies
// (client/point_upload.h) read. Opening it draws a probe of records to learn where the points
// lie and what share of the records are points.
#ifndef NEURALMESH_CORE_IO_MAPPED_POINT_FILE_H_
#define NEURALMESH_CORE_IO_MAPPED_POINT_FILE_H_

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/bounding_box.h"
#include "core/io/internal/point_records.h"
#include "core/io/mapped_file.h"
#include "core/io/point_selection.h"
#include "core/origin.h"
#include "core/rgb.h"

namespace neuralmesh {

// Where a file's points lie, judged from a probe of them.
struct ProbedPlacement {
  // The bounds the file states (a LAS header's) where the probe finds them fresh (no probed
  // point outside them, and no more than twice the probe's box), else the probe's; relative to
  // `origin`.
  BoundingBox bounds;
  // Where the points' (0, 0, 0) lies in the file's coordinates, chosen from the bounds as
  // reading the file whole chooses it from its points: with the file's resolution (a LAS
  // file's scale) or, where it states none, PositionCollector's rule.
  Origin origin = kNoOrigin;
};

// The placement of the points of `records` whose probe, in the file's coordinates, has the box
// `probed` (not empty).
ProbedPlacement PlaceProbe(const BoundingBox& probed, const io_internal::PointRecords& records);

class MappedPointFile {
 public:
  // Records drawn when the file is opened, to see what share of them is kept and where they
  // lie.
  static constexpr int kProbeRecords = 4096;
  // The least share of the probe that must be kept: below it a point would take more than 100
  // record reads.
  static constexpr double kLeastKeptShare = 0.01;

  // Maps the uncompressed LAS, binary PLY or binary PCD file at `path` (by its extension);
  // `classes` as ParseLas's, for LAS. Returns MappedFile's errors (NOT_FOUND for a missing
  // file); INVALID_ARGUMENT, naming the file and saying why, for a LAZ file (its records are
  // compressed in chunks: none can be read alone), another format, the errors of
  // io_internal::LasRecords::Create, PlyVertexRecords and PcdPointRecords, a file without
  // point records, and one where less than kLeastKeptShare of the probe is kept (read such a
  // file whole).
  static absl::StatusOr<MappedPointFile> Open(
      const std::string& path, const std::optional<LasClasses>& classes = std::nullopt);

  uint64_t records() const { return records_->size(); }
  // Record i's (< records()) position relative to origin() when reading the file whole takes it
  // as a point; nothing for a record reading the file leaves out (LAS: withheld, noise, or of a
  // class not asked for, as io_internal::ParseLas; PCD: no position) or refuses the file for
  // (PLY: a non-finite coordinate; any: a coordinate, relative to origin(), beyond a float's
  // range). Reads the record once.
  std::optional<Vec3> Point(uint64_t i) const { return PointOfRecord(*records_, i, origin_); }
  // Whether the learner can take `p`: coordinates that a float holds, as the readers require,
  // so that no mesh gets an infinite vertex.
  static bool Learnable(const Vec3& p) {
    constexpr double kLargestFloat = std::numeric_limits<float>::max();
    return std::fabs(p[0]) <= kLargestFloat && std::fabs(p[1]) <= kLargestFloat &&
           std::fabs(p[2]) <= kLargestFloat;
  }
  // Record i of `records` relative to `origin` when reading the file whole takes it as a point
  // (Point's rules, for any records: a LAZ file's decoded chunk too).
  static std::optional<Vec3> PointOfRecord(const io_internal::PointRecords& records, uint64_t i,
                                           const Origin& origin) {
    const std::optional<io_internal::Point3d> p = records.KeptPoint(i);
    if (!p.has_value()) return std::nullopt;
    const Vec3 point((*p)[0] - origin[0], (*p)[1] - origin[1], (*p)[2] - origin[2]);
    if (!Learnable(point)) return std::nullopt;
    return point;
  }
  // Record i's colour when the file has colours, as reading the file whole gives it (PLY, PCD:
  // PointRecords::StatedColor), except that LAS levels are judged to be of 8 or 16 bits from
  // the largest level of the probe's records instead of all of them (LevelScale); nothing
  // otherwise.
  std::optional<Rgb> Color(uint64_t i) const {
    if (const std::optional<Rgb> stated = records_->StatedColor(i); stated.has_value()) {
      return stated;
    }
    const std::optional<std::array<uint16_t, 3>> levels = records_->ColorLevels(i);
    if (!levels.has_value()) return std::nullopt;
    return RgbFromLevels(*levels, color_scale_);
  }
  // Starts loading record i.
  void Prefetch(uint64_t i) const { __builtin_prefetch(records_->Address(i)); }

  // The probe's placement (PlaceProbe): records outside bounds() are points all the same.
  const BoundingBox& bounds() const { return bounds_; }
  const Origin& origin() const { return origin_; }
  bool has_colors() const { return records_->has_colors(); }
  // The share of the probe's records that are points.
  double kept_share() const { return kept_share_; }
  // MappedFile::CheckSize: whether the records read so far are the file's.
  absl::Status CheckSize() const { return file_.CheckSize(); }

 private:
  MappedPointFile(MappedFile file, std::unique_ptr<io_internal::PointRecords> records)
      : file_(std::move(file)), records_(std::move(records)) {}

  MappedFile file_;  // Its mapping stays where it is when this object moves.
  std::unique_ptr<io_internal::PointRecords> records_;  // A view of file_'s bytes.
  Origin origin_ = kNoOrigin;
  BoundingBox bounds_;
  double kept_share_ = 0;
  double color_scale_ = 255;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_MAPPED_POINT_FILE_H_
