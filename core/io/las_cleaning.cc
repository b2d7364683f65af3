#include "core/io/las_cleaning.h"

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/io/file_contents.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/status_macros.h"

namespace neuralmesh {

absl::Status WriteCleanedLas(const std::string& source, const std::vector<bool>& outliers,
                             LasOutlierRecords records, const std::string& path,
                             const PointSelection& selection) {
  if (io_internal::FormatFromPath(source) != io_internal::FileFormat::kLas) {
    return absl::InvalidArgumentError(absl::StrCat("'", source, "' is not a .las file"));
  }
  NM_ASSIGN_OR_RETURN(const std::string data, ReadFileContents(source));
  absl::StatusOr<std::string> cleaned =
      io_internal::FormatCleanedLas(data, outliers, records, selection.las_classes);
  if (!cleaned.ok()) return io_internal::WithPath(cleaned.status(), source);
  return WriteFileContents(path, *cleaned);
}

}  // namespace neuralmesh
