// Cleaning a LAS file of its outliers without losing what a PointCloud does not hold: the
// records are copied, not read and written again, so each keeps its class, intensity,
// returns, GPS time and extra bytes, and the file its scale, offset and coordinate system.
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

// Writes to `path` the LAS file at `source` without its outliers, or with them classified as
// noise (internal/las.h, FormatCleanedLas): `outliers` holds one flag per point ReadPointCloud
// reads from `source` with `selection`, in its order; with kLeftOut, the records it does not
// read are left out too. Every other record is copied byte for byte, and the
// header keeps its version, point format, scale, offset and variable-length records; with
// kLeftOut its counts and bounds become the kept points'.
// Returns NOT_FOUND when `source` cannot be read; INVALID_ARGUMENT when it is not a LAS file
// ReadPointCloud reads, or `outliers` has not one flag per point, or flags every point to
// leave out; otherwise the status of the write.
absl::Status WriteCleanedLas(const std::string& source, const std::vector<bool>& outliers,
                             LasOutlierRecords records, const std::string& path,
                             const PointSelection& selection = {});

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_LAS_CLEANING_H_
