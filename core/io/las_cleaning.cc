#include "core/io/las_cleaning.h"

#include <memory>
#include <utility>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/io/byte_sink.h"
#include "core/io/file_bytes.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/io/internal/las_file_writer.h"
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

bool IsLazPath(const std::string& path) { return io_internal::LowercaseExtension(path) == ".laz"; }

// The writer of a LAS file to `out`: compressed when `path` is .laz.
std::unique_ptr<io_internal::LasFileWriter> LasWriterFor(const std::string& path, ByteSink* out) {
  if (IsLazPath(path)) return std::make_unique<io_internal::LazWriter>(out);
  return std::make_unique<io_internal::PlainLasWriter>(out);
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
  const bool to_laz = IsLazPath(path);
  absl::StatusOr<uint64_t> records;
  if (from_laz) {
    const absl::StatusOr<io_internal::LazChunks> chunks = io_internal::LazChunks::Open(data);
    records = chunks.ok() ? absl::StatusOr<uint64_t>(chunks->records()) : chunks.status();
  } else {
    records = io_internal::LasRecordCount(data);
  }
  if (!records.ok()) return io_internal::WithPath(records.status(), source);
  copy.records = *records;

  // Written a wave of chunks at a time: neither side is held whole.
  FileSink out(path);
  absl::Status status;
  if (from_laz && to_laz) {
    status = io_internal::RecompressLazTo(data, &out);
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
  // Each file where it lies (read whole when it is the one `path` names, which writing
  // replaces); LAZ files' chunks are decoded as the records are written.
  std::vector<FileBytes> bytes(sources.size());
  std::vector<io_internal::LasSource> files;
  for (size_t i = 0; i < sources.size(); ++i) {
    if (!IsLasPath(sources[i])) return NotLas(sources[i]);
    NM_ASSIGN_OR_RETURN(bytes[i], FileBytes::ReadToReplace(sources[i], path));
    files.push_back({sources[i], bytes[i].data()});
  }
  FileSink out(path);
  const std::unique_ptr<io_internal::LasFileWriter> writer = LasWriterFor(path, &out);
  absl::Status status = io_internal::WriteCleanedLasTo(files, outliers, records,
                                                       selection.las_classes, join, writer.get());
  if (status.ok()) status = out.Close();
  // A file that shrank while it was read explains what was read past its new end.
  for (const FileBytes& file : bytes) NM_RETURN_IF_ERROR(file.CheckSize());
  return status;
}

}  // namespace neuralmesh
