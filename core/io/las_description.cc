#include "core/io/las_description.h"

#include "absl/strings/str_cat.h"
#include "core/io/file_bytes.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "core/io/las_cleaning.h"
#include "core/status_macros.h"

namespace neuralmesh {

absl::StatusOr<LasDescription> DescribeLasFile(const std::string& path) {
  if (!IsLasPath(path)) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "' is not a .las or .laz file"));
  }
  NM_ASSIGN_OR_RETURN(const FileBytes bytes, FileBytes::Read(path));
  const absl::string_view data = bytes.data();
  absl::StatusOr<LasDescription> description = io_internal::DescribeLas(data);
  NM_RETURN_IF_ERROR(bytes.CheckSize());
  if (!description.ok()) return io_internal::WithPath(description.status(), path);
  description->file_bytes = data.size();
  if (io_internal::IsLaz(data)) {
    absl::StatusOr<std::string> compression = io_internal::DescribeLazCompression(data);
    if (!compression.ok()) return io_internal::WithPath(compression.status(), path);
    description->compression = *std::move(compression);
  }
  return description;
}

}  // namespace neuralmesh
