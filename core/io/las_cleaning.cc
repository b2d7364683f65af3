#include "core/io/las_cleaning.h"

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

absl::StatusOr<LasCopy> CopyLas(const std::string& source, const std::string& path) {
  for (const std::string* file : {&source, &path}) {
    if (!IsLasPath(*file)) {
      return absl::InvalidArgumentError(absl::StrCat("'", *file, "' is not a .las or .laz file"));
    }
  }
  NM_ASSIGN_OR_RETURN(std::string data, ReadFileContents(source));
  LasCopy copy;
  copy.read_bytes = data.size();
  if (io_internal::IsLaz(data)) {
    absl::StatusOr<std::string> decompressed = io_internal::DecompressLaz(data);
    if (!decompressed.ok()) return io_internal::WithPath(decompressed.status(), source);
    data = *std::move(decompressed);
  }
  const absl::StatusOr<uint64_t> records = io_internal::LasRecordCount(data);
  if (!records.ok()) return io_internal::WithPath(records.status(), source);
  copy.records = *records;
  if (io_internal::LowercaseExtension(path) == ".laz") {
    NM_ASSIGN_OR_RETURN(data, io_internal::CompressLas(data));
  }
  copy.written_bytes = data.size();
  NM_RETURN_IF_ERROR(WriteFileContents(path, data));
  return copy;
}

absl::Status WriteCleanedLas(const std::vector<std::string>& sources,
                             const std::vector<bool>& outliers, LasOutlierRecords records,
                             const std::string& path, const PointSelection& selection) {
  std::vector<std::string> contents;
  contents.reserve(sources.size());
  for (const std::string& source : sources) {
    if (!IsLasPath(source)) {
      return absl::InvalidArgumentError(absl::StrCat("'", source, "' is not a .las or .laz file"));
    }
    std::string& data = contents.emplace_back();
    NM_ASSIGN_OR_RETURN(data, ReadFileContents(source));
    if (io_internal::IsLaz(data)) {
      absl::StatusOr<std::string> decompressed = io_internal::DecompressLaz(data);
      if (!decompressed.ok()) return io_internal::WithPath(decompressed.status(), source);
      data = *std::move(decompressed);
    }
  }
  std::vector<io_internal::LasSource> files;
  for (size_t i = 0; i < sources.size(); ++i) {
    files.push_back({sources[i], contents[i]});
  }
  NM_ASSIGN_OR_RETURN(
      std::string cleaned,
      io_internal::FormatCleanedLas(files, outliers, records, selection.las_classes));
  if (io_internal::LowercaseExtension(path) == ".laz") {
    NM_ASSIGN_OR_RETURN(cleaned, io_internal::CompressLas(cleaned));
  }
  return WriteFileContents(path, cleaned);
}

}  // namespace neuralmesh
