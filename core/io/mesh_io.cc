#include "core/io/mesh_io.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/io/file_bytes.h"
#include "core/io/file_contents.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/gltf.h"
#include "core/io/internal/obj.h"
#include "core/io/internal/off.h"
#include "core/io/internal/ply.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/stl.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

using io_internal::CannotWrite;
using io_internal::FileFormat;

// Formats of points only (XYZ, LAS, PCD, PTX, E57) and unknown extensions are not mesh formats.
bool IsMeshFormat(FileFormat format) {
  return format != FileFormat::kUnknown && format != FileFormat::kXyz &&
         format != FileFormat::kLas && format != FileFormat::kPcd && format != FileFormat::kPtx &&
         format != FileFormat::kE57;
}

absl::StatusOr<FileFormat> MeshFormat(const std::string& path) {
  const FileFormat format = io_internal::FormatFromPath(path);
  if (!IsMeshFormat(format)) {
    const std::string extension = io_internal::LowercaseExtension(path);
    return absl::InvalidArgumentError(absl::StrCat(
        "'", path, "': ",
        extension.empty() ? std::string("no file extension")
                          : absl::StrCat("unsupported mesh file extension '", extension, "'"),
        "; supported: ", kMeshExtensions));
  }
  return format;
}

absl::StatusOr<TriangleMesh> ParseMesh(FileFormat format, absl::string_view data,
                                       const std::string& path) {
  using io_internal::FaceHandling;
  using io_internal::PositionPrecision;
  if (format == FileFormat::kDraco) return DecodeMesh(std::string_view(data.data(), data.size()));
  const auto parse =
      [&](PositionPrecision precision) -> absl::StatusOr<io_internal::ParsedGeometry> {
    switch (format) {
      case FileFormat::kPly:
        return io_internal::ParsePly(data, FaceHandling::kRead, precision);
      case FileFormat::kObj:
        return io_internal::ParseObj(data, FaceHandling::kRead, precision);
      case FileFormat::kOff:
        return io_internal::ParseOff(data, FaceHandling::kRead, precision);
      case FileFormat::kStl:
        return io_internal::ParseStl(data);
      case FileFormat::kGltf:
        return io_internal::ParseGltf(data, FaceHandling::kRead,
                                      io_internal::GltfBuffersBeside(path));
      case FileFormat::kDraco:
      case FileFormat::kXyz:
      case FileFormat::kLas:
      case FileFormat::kPcd:
      case FileFormat::kPtx:
      case FileFormat::kE57:
      case FileFormat::kUnknown:
        break;
    }
    return absl::InternalError("not a mesh format");
  };
  absl::StatusOr<io_internal::ParsedGeometry> parsed = io_internal::ParseInLeastMemory(parse);
  if (!parsed.ok()) return parsed.status();
  TriangleMesh mesh;
  mesh.positions = std::move(parsed->positions);
  mesh.faces = std::move(parsed->faces);
  mesh.colors = std::move(parsed->colors);
  mesh.origin = parsed->origin;
  return mesh;
}

absl::Status CheckWritable(const TriangleMesh& mesh, FileFormat format) {
  if (mesh.positions.empty()) return absl::InvalidArgumentError("the mesh is empty");
  if (!mesh.colors.empty() && mesh.colors.size() != mesh.positions.size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "there are ", mesh.colors.size(), " colours for ", mesh.positions.size(), " vertices"));
  }
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3f& p = mesh.positions[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return absl::InvalidArgumentError(absl::StrCat("vertex ", i, " has a non-finite coordinate"));
    }
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    for (uint32_t v : mesh.faces[f]) {
      if (v >= mesh.positions.size()) {
        return absl::InvalidArgumentError(absl::StrCat("face ", f, " uses vertex ", v,
                                                       " but the mesh has ", mesh.positions.size(),
                                                       " vertices"));
      }
    }
  }
  if (mesh.faces.empty() && (format == FileFormat::kStl || format == FileFormat::kDraco)) {
    return absl::InvalidArgumentError(
        "the mesh has no faces, and this format stores only triangles");
  }
  return absl::OkStatus();
}

}  // namespace

const char kMeshExtensions[] = ".ply, .obj, .off, .stl, .drc, .glb, .gltf";

bool IsSupportedMeshExtension(std::string_view path) {
  return IsMeshFormat(io_internal::FormatFromPath(absl::string_view(path.data(), path.size())));
}

absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path) {
  NM_ASSIGN_OR_RETURN(const FileFormat format, MeshFormat(path));
  NM_ASSIGN_OR_RETURN(const FileBytes bytes, FileBytes::Read(path));  // Mapped, not copied.
  absl::StatusOr<TriangleMesh> mesh = ParseMesh(format, bytes.data(), path);
  NM_RETURN_IF_ERROR(bytes.CheckSize());
  if (!mesh.ok()) return io_internal::WithPath(mesh.status(), path);
  if (mesh->positions.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "' contains no vertices"));
  }
  return mesh;
}

absl::StatusOr<std::string> FormatMesh(const TriangleMesh& mesh, const std::string& path,
                                       const MeshWriteOptions& options) {
  NM_ASSIGN_OR_RETURN(const FileFormat format, MeshFormat(path));
  const absl::Status writable = CheckWritable(mesh, format);
  if (!writable.ok()) return CannotWrite(path, writable);
  const io_internal::GeometryView view{mesh.positions, {},          {},
                                       mesh.faces,     mesh.colors, mesh.origin};
  std::string data;
  switch (format) {
    case FileFormat::kPly:
      data = io_internal::FormatPly(view);
      break;
    case FileFormat::kObj:
      data = io_internal::FormatObj(view);
      break;
    case FileFormat::kOff:
      data = io_internal::FormatOff(view);
      break;
    case FileFormat::kStl:
      data = io_internal::FormatStl(view);
      break;
    case FileFormat::kDraco: {
      absl::StatusOr<std::string> encoded = EncodeMesh(mesh, options.draco);
      if (!encoded.ok()) return CannotWrite(path, encoded.status());
      data = *std::move(encoded);
      break;
    }
    case FileFormat::kGltf: {
      io_internal::GltfWriteOptions gltf;
      gltf.binary = io_internal::LowercaseExtension(path) == ".glb";
      gltf.draco = options.gltf_draco;
      gltf.draco_options = options.draco;
      absl::StatusOr<std::string> formatted = io_internal::FormatGltf(view, gltf);
      if (!formatted.ok()) return CannotWrite(path, formatted.status());
      data = *std::move(formatted);
      break;
    }
    case FileFormat::kXyz:
    case FileFormat::kLas:
    case FileFormat::kPcd:
    case FileFormat::kPtx:
    case FileFormat::kE57:
    case FileFormat::kUnknown:
      return absl::InternalError("not a mesh format");
  }
  return data;
}

absl::Status WriteMesh(const TriangleMesh& mesh, const std::string& path,
                       const MeshWriteOptions& options) {
  NM_ASSIGN_OR_RETURN(const std::string data, FormatMesh(mesh, path, options));
  return WriteFileContents(path, data);
}

}  // namespace neuralmesh
