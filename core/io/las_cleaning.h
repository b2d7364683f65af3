// Cleaning LAS files of their outliers without losing what a PointCloud does not hold: the
// records are copied, not read and written again, so each keeps its class, intensity,
// returns, GPS time and extra bytes, and the file its scale, offset and coordinate system.
// Several files (the tiles of a survey) are joined into one the same way, and one file with
// nothing to remove is copied whole, compressed (LAZ) or not.
#ifndef NEURALMESH_CORE_IO_LAS_CLEANING_H_
#define NEURALMESH_CORE_IO_LAS_CLEANING_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/io/point_selection.h"

namespace neuralmesh {

// What becomes of the outliers' records.
enum class LasOutlierRecords {
  kLeftOut,            // Removed, with the withheld and noise records the readers leave out.
  kClassifiedAsNoise,  // Kept, as low noise (ASPRS class 7), which the readers leave out.
};

// How WriteCleanedLas put the records of its sources in one file.
struct LasJoin {
  // The source whose header the file has (its offset, variable-length records, and what follows
  // the points): the first of the highest LAS version among them.
  size_t header_source = 0;
  int version_minor = 0;  // LAS 1.version_minor.
  int point_format = 0;
  // Whether records of other point formats were converted to point_format.
  bool converted = false;
};

// Whether `path` names a LAS file: .las, or .laz for one compressed by LASzip
// (internal/laz.h).
bool IsLasPath(const std::string& path);

// What CopyLas copied: the records, and the file's bytes before and after.
struct LasCopy {
  uint64_t records = 0;
  size_t read_bytes = 0;
  size_t written_bytes = 0;
};

// Writes the LAS or LAZ file at `source` to `path` as LAS or LAZ by its extension (as laszip
// does): every record byte for byte, noise and withheld ones too, and the header and
// variable-length records as they were (but the compression: its point format bits, LASzip's
// record and the offsets that move with it; internal/laz.h).
// Returns NOT_FOUND when `source` cannot be read; INVALID_ARGUMENT when either path is not
// .las or .laz, or the source is malformed (ParseLas's and DecompressLaz's errors, named);
// FAILED_PRECONDITION for records of the waveform formats (4, 5, 9, 10) to a .laz `path`,
// which are not written as LAZ here; otherwise the status of the write.
absl::StatusOr<LasCopy> CopyLas(const std::string& source, const std::string& path);

// Writes to `path` the LAS files at `sources`, one after another, without their outliers, or
// with them classified as noise (internal/las.h, FormatCleanedLas): `outliers` holds one flag
// per point ReadPointCloud reads from the sources with `selection`, file after file, in their
// order; with kLeftOut, the records it does not read are left out too. Every other record is
// copied byte for byte (but for its coordinates, put on the finest scale, when the files'
// scales or offsets differ, and its fields, moved into the point format that holds every
// source's, when their formats differ), and the header keeps the version, offset and
// variable-length records of the first file of the highest version; its counts and bounds
// become the records written. `join`, when given, says how (LasJoin).
// Returns NOT_FOUND when a source cannot be read; INVALID_ARGUMENT when one is not a LAS file
// ReadPointCloud reads, or `outliers` has not one flag per point, or flags every point to
// leave out; FAILED_PRECONDITION, saying why, when the records of several files cannot be put
// in one file (another coordinate system or extra bytes than the first's, waveform records,
// ...: FormatCleanedLas) or when `path` is .laz and the records' point format
// is one LAZ is not written in here (the waveform formats); otherwise the status of the write.
// Sources may be LAZ (.laz), read as the LAS files they compress; a .laz `path` is written as
// LAZ (internal/laz.h). The file is written as its sources are read, a few megabytes of records
// at a time: an error found before the first records leaves any file at `path` as it was, one
// found on the way (the flags' count, coordinates that do not fit) leaves no file there.
absl::Status WriteCleanedLas(const std::vector<std::string>& sources,
                             const std::vector<bool>& outliers, LasOutlierRecords records,
                             const std::string& path, const PointSelection& selection = {},
                             LasJoin* join = nullptr);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_LAS_CLEANING_H_
