#include "core/io/las_description.h"

#include "absl/strings/str_cat.h"
#include "core/io/file_bytes.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/io/las_cleaning.h"
#include "core/status_macros.h"

namespace neuralmesh {

absl::StatusOr<LasDescription> DescribeLasFile(const std::string& path) {
  if (!IsLasPath(path)) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "' is not a .las or .laz file"));
  }
  NM_ASSIGN_OR_RETURN(const FileBytes bytes, FileBytes::Read(path));
  absl::StatusOr<LasDescription> description = io_internal::DescribeLas(bytes.data());
  NM_RETURN_IF_ERROR(bytes.CheckSize());
  if (!description.ok()) return io_internal::WithPath(description.status(), path);
  return description;
}

}  // namespace neuralmesh
