// Cleaning LAS files of their outliers without losing what a PointCloud does not hold: the
// records are copied, not read and written again, so each keeps its class, intensity,
// returns, GPS time and extra bytes, and the file its scale, offset and coordinate system.
// Several files (the tiles of a survey) are joined into one the same way.
#ifndef NEURALMESH_CORE_IO_LAS_CLEANING_H_
#define NEURALMESH_CORE_IO_LAS_CLEANING_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/io/point_selection.h"

namespace neuralmesh {

// What becomes of the outliers' records.
enum class LasOutlierRecords {
  kLeftOut,            // Removed, with the withheld and noise records the readers leave out.
  kClassifiedAsNoise,  // Kept, as low noise (ASPRS class 7), which the readers leave out.
};

// Whether `path` names a LAS file: .las, or .laz for one compressed by LASzip
// (internal/laz.h).
bool IsLasPath(const std::string& path);

// Writes to `path` the LAS files at `sources`, one after another, without their outliers, or
// with them classified as noise (internal/las.h, FormatCleanedLas): `outliers` holds one flag
// per point ReadPointCloud reads from the sources with `selection`, file after file, in their
// order; with kLeftOut, the records it does not read are left out too. Every other record is
// copied byte for byte (but for its coordinates, put on the finest scale, when the files'
// scales or offsets differ), and the header keeps the first file's version, point format,
// offset and variable-length records; its counts and bounds become the records written.
// Returns NOT_FOUND when a source cannot be read; INVALID_ARGUMENT when one is not a LAS file
// ReadPointCloud reads, or `outliers` has not one flag per point, or flags every point to
// leave out; FAILED_PRECONDITION, saying why, when the records of several files cannot be put
// in one file (another version, point format, record length, coordinate system, extra bytes
// than the first's, ...: FormatCleanedLas) or when `path` is .laz and the records' point format
// is not one LAZ is written in here (4 to 10); otherwise the status of the write.
// Sources may be LAZ (.laz), read as the LAS files they compress; a .laz `path` is written as
// LAZ (internal/laz.h).
absl::Status WriteCleanedLas(const std::vector<std::string>& sources,
                             const std::vector<bool>& outliers, LasOutlierRecords records,
                             const std::string& path, const PointSelection& selection = {});

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_LAS_CLEANING_H_
