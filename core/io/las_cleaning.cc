#include "core/io/las_cleaning.h"

#include <utility>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/io/byte_sink.h"
#include "core/io/file_bytes.h"
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

// The bytes of the LAS file at `source`: the file where it lies (FileBytes; read whole when it
// is the file `path` names, which writing replaces), or decompressed into `decompressed` when
// it is LAZ.
absl::StatusOr<absl::string_view> ReadLas(const std::string& source, const std::string& path,
                                          FileBytes* bytes, std::string* decompressed) {
  NM_ASSIGN_OR_RETURN(*bytes, FileBytes::ReadToReplace(source, path));
  if (!io_internal::IsLaz(bytes->data())) return bytes->data();
  absl::StatusOr<std::string> las = io_internal::DecompressLaz(bytes->data());
  if (!las.ok()) return io_internal::WithPath(las.status(), source);
  *decompressed = *std::move(las);
  return absl::string_view(*decompressed);
}

// Writes the LAS file `las` to `path`, compressed when `path` is .laz.
absl::Status WriteLas(const std::string& path, absl::string_view las) {
  FileSink out(path);
  NM_RETURN_IF_ERROR(io_internal::LowercaseExtension(path) == ".laz"
                         ? io_internal::CompressLasTo(las, &out)
                         : out.Append(las));
  return out.Close();
}

}  // namespace

absl::StatusOr<LasCopy> CopyLas(const std::string& source, const std::string& path) {
  for (const std::string* file : {&source, &path}) {
    if (!IsLasPath(*file)) return NotLas(*file);
  }
  LasCopy copy;
  // A file copied onto itself is read whole first: writing it cuts its mapping short.
  NM_ASSIGN_OR_RETURN(const FileBytes bytes, FileBytes::ReadToReplace(source, path));
  const absl::string_view data = bytes.data();
  copy.read_bytes = data.size();
  const bool from_laz = io_internal::IsLaz(data);
  const bool to_laz = io_internal::LowercaseExtension(path) == ".laz";
  absl::StatusOr<uint64_t> records;
  if (from_laz) {
    const absl::StatusOr<io_internal::LazChunks> chunks = io_internal::LazChunks::Open(data);
    records = chunks.ok() ? absl::StatusOr<uint64_t>(chunks->records()) : chunks.status();
  } else {
    records = io_internal::LasRecordCount(data);
  }
  if (!records.ok()) return io_internal::WithPath(records.status(), source);
  copy.records = *records;

  // Written a wave of chunks at a time: neither side is held whole, but for LAZ to LAZ, whose
  // records are decompressed whole to be compressed again.
  FileSink out(path);
  absl::Status status;
  if (from_laz && to_laz) {
    absl::StatusOr<std::string> las = io_internal::DecompressLaz(data);
    status = las.ok() ? io_internal::CompressLasTo(*las, &out) : las.status();
  } else if (from_laz) {
    status = io_internal::DecompressLazTo(data, &out);
  } else if (to_laz) {
    status = io_internal::CompressLasTo(data, &out);
  } else {
    status = out.Append(data);
  }
  if (status.ok()) status = out.Close();
  // A file that shrank while it was read explains what was read past its new end.
  NM_RETURN_IF_ERROR(bytes.CheckSize());
  // The sink's errors name `path`, and FAILED_PRECONDITION says what is not written as LAZ; the
  // others are the source's.
  if (!status.ok() && out.status().ok() && !absl::IsFailedPrecondition(status)) {
    return io_internal::WithPath(status, source);
  }
  NM_RETURN_IF_ERROR(status);
  copy.written_bytes = out.size();
  return copy;
}

absl::Status WriteCleanedLas(const std::vector<std::string>& sources,
                             const std::vector<bool>& outliers, LasOutlierRecords records,
                             const std::string& path, const PointSelection& selection,
                             LasJoin* join) {
  // Each file where it lies, or decompressed (LAZ).
  std::vector<FileBytes> bytes(sources.size());
  std::vector<std::string> decompressed(sources.size());
  std::vector<io_internal::LasSource> files;
  for (size_t i = 0; i < sources.size(); ++i) {
    if (!IsLasPath(sources[i])) return NotLas(sources[i]);
    NM_ASSIGN_OR_RETURN(const absl::string_view las,
                        ReadLas(sources[i], path, &bytes[i], &decompressed[i]));
    files.push_back({sources[i], las});
  }
  NM_ASSIGN_OR_RETURN(
      std::string cleaned,
      io_internal::FormatCleanedLas(files, outliers, records, selection.las_classes, join));
  // A file that shrank while it was read explains what was read past its new end.
  for (const FileBytes& file : bytes) NM_RETURN_IF_ERROR(file.CheckSize());
  return WriteLas(path, cleaned);
}

}  // namespace neuralmesh
