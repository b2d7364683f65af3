#include "core/io/las_cleaning.h"

#include <utility>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/io/file_contents.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "core/status_macros.h"

namespace neuralmesh {

bool IsLasPath(const std::string& path) {
  return io_internal::FormatFromPath(path) == io_internal::FileFormat::kLas;
}

namespace {

absl::Status NotLas(const std::string& path) {
  return absl::InvalidArgumentError(absl::StrCat("'", path, "' is not a .las or .laz file"));
}

// The LAS file at `source`, decompressed when it is LAZ; `file_bytes` gets its size on disk.
absl::StatusOr<std::string> ReadLas(const std::string& source, size_t* file_bytes = nullptr) {
  NM_ASSIGN_OR_RETURN(std::string data, ReadFileContents(source));
  if (file_bytes != nullptr) *file_bytes = data.size();
  if (!io_internal::IsLaz(data)) return data;
  absl::StatusOr<std::string> decompressed = io_internal::DecompressLaz(data);
  if (!decompressed.ok()) return io_internal::WithPath(decompressed.status(), source);
  return decompressed;
}

// Writes the LAS file `las` to `path`, compressed when `path` is .laz; returns the bytes
// written.
absl::StatusOr<size_t> WriteLas(const std::string& path, std::string las) {
  if (io_internal::LowercaseExtension(path) == ".laz") {
    NM_ASSIGN_OR_RETURN(las, io_internal::CompressLas(las));
  }
  NM_RETURN_IF_ERROR(WriteFileContents(path, las));
  return las.size();
}

}  // namespace

absl::StatusOr<LasCopy> CopyLas(const std::string& source, const std::string& path) {
  for (const std::string* file : {&source, &path}) {
    if (!IsLasPath(*file)) return NotLas(*file);
  }
  LasCopy copy;
  NM_ASSIGN_OR_RETURN(std::string las, ReadLas(source, &copy.read_bytes));
  const absl::StatusOr<uint64_t> records = io_internal::LasRecordCount(las);
  if (!records.ok()) return io_internal::WithPath(records.status(), source);
  copy.records = *records;
  NM_ASSIGN_OR_RETURN(copy.written_bytes, WriteLas(path, std::move(las)));
  return copy;
}

absl::Status WriteCleanedLas(const std::vector<std::string>& sources,
                             const std::vector<bool>& outliers, LasOutlierRecords records,
                             const std::string& path, const PointSelection& selection,
                             LasJoin* join) {
  std::vector<std::string> contents;
  contents.reserve(sources.size());
  for (const std::string& source : sources) {
    if (!IsLasPath(source)) return NotLas(source);
    NM_ASSIGN_OR_RETURN(contents.emplace_back(), ReadLas(source));
  }
  std::vector<io_internal::LasSource> files;
  for (size_t i = 0; i < sources.size(); ++i) {
    files.push_back({sources[i], contents[i]});
  }
  NM_ASSIGN_OR_RETURN(
      std::string cleaned,
      io_internal::FormatCleanedLas(files, outliers, records, selection.las_classes, join));
  return WriteLas(path, std::move(cleaned)).status();
}

}  // namespace neuralmesh
