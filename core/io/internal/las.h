// ASPRS LAS 1.0-1.4 point clouds (.las), the exchange format of airborne and terrestrial LiDAR:
// a header, then fixed-size point records of formats 0 to 10.
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAS_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAS_H_

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/las_file_writer.h"
#include "core/io/internal/point_records.h"
#include "core/io/internal/position_collector.h"
#include "core/io/las_cleaning.h"
#include "core/io/las_description.h"
#include "core/io/point_selection.h"

namespace neuralmesh::io_internal {

// Parses a LAS file: the positions of its point records (integer X, Y, Z times the header's
// scale, plus its offset; withheld records left out, and those of the classes outside
// `classes`, or without them those classified as noise, ASPRS classes 7 and 18; all counted
// in ParsedGeometry::left_out) and, for the formats that carry them
// (2, 3, 5, 7, 8, 10), their colours (16-bit channels scaled to 8 bits, or taken as they are
// when no channel of the file exceeds 255, as some writers store 8-bit values). Positions are
// floats, relative to ParsedGeometry::origin where the file's coordinates are too far from 0
// for a float to keep its resolution, the scale (georeferenced data such as UTM:
// OriginKeepingResolution in position_collector.h).
// A LAZ file (laz.h) is read as the LAS file it compresses, with DecompressLaz's errors.
// Returns INVALID_ARGUMENT saying what is wrong for a file without the "LASF" signature, a
// header or records that run past the end of the file, a point format above 10, a record
// shorter than its format, a zero or non-finite scale, or a point count that does not fit the
// file, or points that are all left out.
// With `description`, it also gets DescribeLas's description of the file, from the same pass
// over its records (a LAZ file's chunks are decoded once for both).
absl::StatusOr<ParsedGeometry> ParseLas(absl::string_view data,
                                        const std::optional<LasClasses>& classes = std::nullopt,
                                        LasDescription* description = nullptr);

// The point records of an uncompressed LAS file, read one at a time where they lie: for
// sampling a file without reading it whole (core/sampling/off_core_sampler.h). Holds a view
// of the file's bytes, which must outlive it.
class LasRecords final : public PointRecords {
 public:
  // ParseLas's checks of the header, and its errors for a malformed one (a LAZ file's records
  // are compressed: INVALID_ARGUMENT). `classes` as ParseLas's.
  static absl::StatusOr<std::unique_ptr<LasRecords>> Create(
      absl::string_view data, const std::optional<LasClasses>& classes);
  // The records at `records` (a decoded LAZ chunk: LazChunks) of the LAS file whose header and
  // variable-length records are `header` (LazChunks::las_header); Create's errors for the
  // header. Both must outlive the object.
  static absl::StatusOr<std::unique_ptr<LasRecords>> Create(
      absl::string_view header, absl::string_view records,
      const std::optional<LasClasses>& classes);

  uint64_t size() const override { return count_; }
  // Its integers times the scale, plus the offset, when ParseLas reads it: not withheld, and of
  // a class in `classes`, or without them of no noise class.
  std::optional<Point3d> KeptPoint(uint64_t i) const override;
  const char* Address(uint64_t i) const override { return data_.data() + first_ + i * length_; }
  bool has_colors() const override;
  // The red, green and blue levels of a format with colours.
  std::optional<std::array<uint16_t, 3>> ColorLevels(uint64_t i) const override;
  // Each axis's scale, made positive.
  std::optional<Point3d> Resolution() const override;
  // The header's.
  std::optional<std::pair<Point3d, Point3d>> StatedBounds() const override {
    return std::make_pair(header_low_, header_high_);
  }

 private:
  LasRecords() = default;

  absl::string_view data_;
  std::optional<LasClasses> classes_;
  uint64_t count_ = 0;
  size_t first_ = 0;
  size_t length_ = 0;
  int format_ = 0;
  Point3d scale_, offset_, header_low_, header_high_;
};

// The number of point records of an uncompressed LAS file, after ParseLas's checks of its
// header (and its errors but the last).
absl::StatusOr<uint64_t> LasRecordCount(absl::string_view data);

// Describes a LAS file (a LAZ file: the LAS file it holds, with its `compression`, and the
// size as stored), with ParseLas's errors for a malformed one.
absl::StatusOr<LasDescription> DescribeLas(absl::string_view data);

// Formats points as a LAS 1.2 file of point format 0, or 2 with their colours (8-bit levels
// times 257 in the 16-bit channels), without variable-length records. The header's offset is
// points.origin; each axis's scale is the power of ten at most 1/2^24 of the farthest
// coordinate from that origin (1e-8 for a unit sphere, 1e-5 for a UTM tile of 1,000 m), so the
// integers keep what the floats hold to half a scale step. Records say return 1 of 1, class 0
// (never classified), intensity 0; the creation date is left zero, so the same points give the
// same bytes. Normals and weights have no place in these formats and are not written.
// Returns INVALID_ARGUMENT for more points than LAS 1.2 counts (2^32 - 1).
absl::StatusOr<std::string> FormatLas(const GeometryView& points);

// A LAS or LAZ file's bytes, and the name by which messages speak of it.
struct LasSource {
  std::string name;
  absl::string_view data;
};

// Writes to `writer` the LAS files `sources` (ParseLas reads each) as one file without their
// outliers, or with them classified as noise: `outliers` holds one flag per point ParseLas
// returns with `classes`, file after file, in their order. Neither side is held whole: a LAZ
// file's records are decoded a wave of chunks at a time, and the records kept go to `writer` a
// few megabytes at a time.
//   kLeftOut: the outliers' records are left out, and so are the withheld, noise and other
//     classes' records that ParseLas leaves out.
//   kClassifiedAsNoise: every record is kept, the outliers' classified as low noise (ASPRS
//     class 7), which ParseLas then leaves out (unless `classes` holds 7); their other flags
//     stay.
// Each record is kept byte for byte (its intensity, returns, GPS time, extra bytes, ...) but
// for its coordinates when several files have different scales or offsets: the file then has
// each axis's finest scale among them and the offset of the file whose header it takes, the
// first of the highest LAS version. That file gives the rest: the header's version and offset,
// the variable-length records (the coordinate system among them) and what follows the points.
// Files of different point formats are joined in the format that holds every field any of
// them holds: formats 0-3 in the one of 0-3 with a GPS time and a colour where one has them,
// with any of formats 6-8 among them in the one of 6-8 with a colour (8: a near infrared)
// where one has it. Their records' fields move into it as they are (LAS 1.4's 4-bit returns,
// 8-bit classes and classification flags take the legacy ones; the scan angle rank in degrees
// becomes the angle in 0.006 degrees), the fields a record lacks zero, its extra bytes after
// them. The header's point counts, counts by return and bounds become those of the records
// written, the starts of what follows the points (LAS 1.3's waveform packets, LAS 1.4's
// extended records) move with their end, and the generating software becomes "neuralmesh
// VERSION". `join`, when given, says how the files were joined.
// Returns ParseLas's errors for a malformed file, named; INVALID_ARGUMENT when `outliers` has
// not one flag per point, or every point is an outlier to leave out; FAILED_PRECONDITION,
// saying why, when the records of several files cannot be put in one file: other extra bytes,
// coordinate system or extended records than the first's, records that point to waveform
// data, coordinates that do not fit 32 bits at the joined scale and offset, or more points
// than the version counts; `writer`'s errors (LazWriter's FAILED_PRECONDITION for a point
// format LAZ is not written in, before anything is written). The errors of the flags, of
// coordinates that do not fit and of a corrupt LAZ chunk come once records have been written.
absl::Status WriteCleanedLasTo(const std::vector<LasSource>& sources,
                               const std::vector<bool>& outliers, LasOutlierRecords records,
                               const std::optional<LasClasses>& classes, LasJoin* join,
                               LasFileWriter* writer);
// The same file, as LAS bytes.
absl::StatusOr<std::string> FormatCleanedLas(
    const std::vector<LasSource>& sources, const std::vector<bool>& outliers,
    LasOutlierRecords records, const std::optional<LasClasses>& classes = std::nullopt,
    LasJoin* join = nullptr);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAS_H_
