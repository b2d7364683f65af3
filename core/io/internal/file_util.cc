#include "core/io/internal/file_util.h"

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"

namespace neuralmesh::io_internal {

std::string LowercaseExtension(absl::string_view path) {
  const size_t slash = path.find_last_of('/');
  const absl::string_view name = slash == absl::string_view::npos ? path : path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  if (dot == absl::string_view::npos || dot == 0) return "";
  return absl::AsciiStrToLower(std::string(name.substr(dot)));
}

FileFormat FormatFromPath(absl::string_view path) {
  const std::string extension = LowercaseExtension(path);
  if (extension == ".ply") return FileFormat::kPly;
  if (extension == ".obj") return FileFormat::kObj;
  if (extension == ".off") return FileFormat::kOff;
  if (extension == ".stl") return FileFormat::kStl;
  if (extension == ".drc") return FileFormat::kDraco;
  if (extension == ".glb" || extension == ".gltf") return FileFormat::kGltf;
  if (extension == ".xyz" || extension == ".txt" || extension == ".pts") return FileFormat::kXyz;
  if (extension == ".las" || extension == ".laz") return FileFormat::kLas;
  if (extension == ".pcd") return FileFormat::kPcd;
  if (extension == ".ptx") return FileFormat::kPtx;
  if (extension == ".e57") return FileFormat::kE57;
  return FileFormat::kUnknown;
}

absl::Status WithPath(const absl::Status& status, const std::string& path) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat("'", path, "': ", status.message()));
}

absl::Status CannotWrite(const std::string& path, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat("cannot write '", path, "': ", status.message()));
}

}  // namespace neuralmesh::io_internal
