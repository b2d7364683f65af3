#include "core/io/las_cleaning.h"

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/io/file_contents.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/status_macros.h"

namespace neuralmesh {

absl::Status WriteCleanedLas(const std::vector<std::string>& sources,
                             const std::vector<bool>& outliers, LasOutlierRecords records,
                             const std::string& path, const PointSelection& selection) {
  std::vector<std::string> contents;
  contents.reserve(sources.size());
  for (const std::string& source : sources) {
    if (io_internal::FormatFromPath(source) != io_internal::FileFormat::kLas) {
      return absl::InvalidArgumentError(absl::StrCat("'", source, "' is not a .las file"));
    }
    NM_ASSIGN_OR_RETURN(contents.emplace_back(), ReadFileContents(source));
  }
  std::vector<io_internal::LasSource> files;
  for (size_t i = 0; i < sources.size(); ++i) {
    files.push_back({sources[i], contents[i]});
  }
  NM_ASSIGN_OR_RETURN(
      const std::string cleaned,
      io_internal::FormatCleanedLas(files, outliers, records, selection.las_classes));
  return WriteFileContents(path, cleaned);
}

}  // namespace neuralmesh
