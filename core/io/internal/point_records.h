// The point records of a file whose records all have one size, read one at a time where they
// lie in the file's bytes instead of parsed all at once: what off-core sampling reads
// (core/sampling/off_core_sampler.h). Uncompressed LAS files (las.h), binary PLY files
// (ply_vertex_records.h) and PCD files of binary data (pcd.h) have such records.
#ifndef NEURALMESH_CORE_IO_INTERNAL_POINT_RECORDS_H_
#define NEURALMESH_CORE_IO_INTERNAL_POINT_RECORDS_H_

#include <array>
#include <cstdint>
#include <optional>
#include <utility>

#include "core/io/internal/position_collector.h"
#include "core/rgb.h"

namespace neuralmesh::io_internal {

class PointRecords {
 public:
  virtual ~PointRecords() = default;

  virtual uint64_t size() const = 0;
  // Record i's (< size()) coordinates in the file's frame when reading the file whole would
  // take it as a point; nothing otherwise. Each record is read once, on the sampler's hot path.
  virtual std::optional<Point3d> KeptPoint(uint64_t i) const = 0;
  // Where record i's bytes are (to start loading them).
  virtual const char* Address(uint64_t i) const = 0;
  // Whether the records carry colours.
  virtual bool has_colors() const = 0;
  // Record i's colour channels as levels of 16 bits whose scale the file does not state (LAS:
  // 8-bit levels or 16-bit ones; the reader judges which, LevelScale); nothing for formats that
  // state it (StatedColor) or records without colours.
  virtual std::optional<std::array<uint16_t, 3>> ColorLevels(uint64_t /*i*/) const {
    return std::nullopt;
  }
  // Record i's colour where the file states its channels' scale (PLY: each channel's type; PCD:
  // the bytes of rgb or rgba), as reading the file whole gives it; nothing for formats that do
  // not (ColorLevels) or records without colours.
  virtual std::optional<Rgb> StatedColor(uint64_t /*i*/) const { return std::nullopt; }
  // The coordinates' resolution per axis (a LAS file's scale), or nothing where the file
  // states none.
  virtual std::optional<Point3d> Resolution() const = 0;
  // The smallest and largest coordinates the file states (a LAS header's, which a writer may
  // leave stale), or nothing.
  virtual std::optional<std::pair<Point3d, Point3d>> StatedBounds() const = 0;
};

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_POINT_RECORDS_H_
