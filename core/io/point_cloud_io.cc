#include "core/io/point_cloud_io.h"

#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/io/file_bytes.h"
#include "core/io/file_contents.h"
#include "core/io/internal/e57.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/geometry_data.h"
#include "core/io/internal/gltf.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "core/io/internal/obj.h"
#include "core/io/internal/off.h"
#include "core/io/internal/pcd.h"
#include "core/io/internal/ply.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/ptx.h"
#include "core/io/internal/xyz.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

using io_internal::FileFormat;

bool IsReadable(FileFormat format) {
  return format != FileFormat::kUnknown && format != FileFormat::kStl;
}

bool IsWritable(FileFormat format) {
  return format == FileFormat::kPly || format == FileFormat::kXyz || format == FileFormat::kPtx ||
         format == FileFormat::kLas || format == FileFormat::kPcd || format == FileFormat::kE57 ||
         format == FileFormat::kDraco || format == FileFormat::kGltf;
}

absl::Status UnsupportedExtension(const std::string& path, const char* supported) {
  const std::string extension = io_internal::LowercaseExtension(path);
  return absl::InvalidArgumentError(absl::StrCat(
      "'", path, "': ",
      extension.empty() ? std::string("no file extension")
                        : absl::StrCat("unsupported point cloud file extension '", extension, "'"),
      "; supported: ", supported));
}

absl::StatusOr<PointCloud> ParsePointCloud(FileFormat format, absl::string_view data,
                                           const std::string& path, PointsLeftOut* left_out,
                                           const PointSelection& selection, LasDescription* las) {
  *left_out = {};
  using io_internal::FaceHandling;
  using io_internal::PositionPrecision;
  if (format == FileFormat::kDraco) {
    return DecodePointCloud(std::string_view(data.data(), data.size()));
  }
  const auto parse =
      [&](PositionPrecision precision) -> absl::StatusOr<io_internal::ParsedGeometry> {
    switch (format) {
      case FileFormat::kPly:
        return io_internal::ParsePly(data, FaceHandling::kSkip, precision);
      case FileFormat::kXyz:
        return io_internal::ParseXyz(data, precision);
      case FileFormat::kLas:
        return io_internal::ParseLas(data, selection.las_classes, las);
      case FileFormat::kPcd:
        return io_internal::ParsePcd(data, precision);
      case FileFormat::kPtx:
        return io_internal::ParsePtx(data, precision);
      case FileFormat::kE57:
        return io_internal::ParseE57(data, precision);
      case FileFormat::kObj:
        return io_internal::ParseObj(data, FaceHandling::kSkip, precision);
      case FileFormat::kOff:
        return io_internal::ParseOff(data, FaceHandling::kSkip, precision);
      case FileFormat::kGltf:
        return io_internal::ParseGltf(data, FaceHandling::kSkip,
                                      io_internal::GltfBuffersBeside(path));
      case FileFormat::kDraco:
      case FileFormat::kStl:
      case FileFormat::kUnknown:
        break;
    }
    return absl::InternalError("not a point cloud format");
  };
  absl::StatusOr<io_internal::ParsedGeometry> parsed = io_internal::ParseInLeastMemory(parse);
  if (!parsed.ok()) return parsed.status();
  PointCloud cloud;
  cloud.positions = std::move(parsed->positions);
  cloud.normals = std::move(parsed->normals);
  cloud.weights = std::move(parsed->weights);
  cloud.colors = std::move(parsed->colors);
  cloud.origin = parsed->origin;
  *left_out = parsed->left_out;
  return cloud;
}

}  // namespace

bool IsReadablePointCloudExtension(std::string_view path) {
  return IsReadable(io_internal::FormatFromPath(absl::string_view(path.data(), path.size())));
}

const char kReadablePointCloudExtensions[] =
    ".ply, .xyz, .txt, .pts, .ptx, .las, .laz, .pcd, .e57, .obj, .off, .drc, .glb, .gltf";
const char kWritablePointCloudExtensions[] =
    ".ply, .xyz, .txt, .pts, .ptx, .las, .laz, .pcd, .e57, .drc, .glb, .gltf";

WrittenPointAttributes PointAttributesWrittenTo(std::string_view path) {
  const FileFormat format =
      io_internal::FormatFromPath(absl::string_view(path.data(), path.size()));
  if (!IsWritable(format)) return {};
  const bool positions_and_colors = format == FileFormat::kLas || format == FileFormat::kPtx;
  return {/*normals=*/!positions_and_colors,
          /*weights=*/!positions_and_colors && format != FileFormat::kE57,
          /*colors=*/true};
}

bool IsWritablePointCloudExtension(std::string_view path) {
  return IsWritable(io_internal::FormatFromPath(absl::string_view(path.data(), path.size())));
}

absl::StatusOr<PointCloud> ReadPointCloud(const std::string& path, PointsLeftOut* left_out,
                                          const PointSelection& selection, LasDescription* las) {
  const FileFormat format = io_internal::FormatFromPath(path);
  if (!IsReadable(format)) {
    return UnsupportedExtension(path, kReadablePointCloudExtensions);
  }
  // Scans of up to billions of bytes are read where they lie, not copied (every parser reads
  // only within the bytes it is given: the fuzz targets check it).
  NM_ASSIGN_OR_RETURN(const FileBytes bytes, FileBytes::Read(path));
  PointsLeftOut ignored;
  absl::StatusOr<PointCloud> cloud = ParsePointCloud(
      format, bytes.data(), path, left_out != nullptr ? left_out : &ignored, selection, las);
  // A file that shrank while it was read explains what was read past its new end.
  NM_RETURN_IF_ERROR(bytes.CheckSize());
  if (!cloud.ok()) return io_internal::WithPath(cloud.status(), path);
  if (cloud->empty()) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "' contains no points"));
  }
  NM_RETURN_IF_ERROR(io_internal::WithPath(ValidatePointCloud(*cloud), path));
  return cloud;
}

absl::Status WritePointCloud(const PointCloud& cloud, const std::string& path,
                             const PointCloudWriteOptions& options) {
  const FileFormat format = io_internal::FormatFromPath(path);
  if (!IsWritable(format)) {
    return UnsupportedExtension(path, kWritablePointCloudExtensions);
  }
  const absl::Status valid = cloud.empty() ? absl::InvalidArgumentError("the point cloud is empty")
                                           : ValidatePointCloud(cloud);
  if (!valid.ok()) return io_internal::CannotWrite(path, valid);
  const io_internal::GeometryView view{cloud.positions, cloud.normals, cloud.weights, {},
                                       cloud.colors,    cloud.origin};
  std::string data;
  if (format == FileFormat::kPly) {
    data = io_internal::FormatPly(view);
  } else if (format == FileFormat::kXyz) {
    data = io_internal::FormatXyz(view);
  } else if (format == FileFormat::kPtx) {
    data = io_internal::FormatPtx(view);
  } else if (format == FileFormat::kPcd) {
    absl::StatusOr<std::string> formatted = io_internal::FormatPcd(view, options.pcd);
    if (!formatted.ok()) return io_internal::CannotWrite(path, formatted.status());
    data = *std::move(formatted);
  } else if (format == FileFormat::kE57) {
    data = io_internal::FormatE57(view);
  } else if (format == FileFormat::kLas) {
    absl::StatusOr<std::string> formatted = io_internal::FormatLas(view);
    if (formatted.ok() && io_internal::LowercaseExtension(path) == ".laz") {
      formatted = io_internal::CompressLas(*formatted);
    }
    if (!formatted.ok()) return io_internal::CannotWrite(path, formatted.status());
    data = *std::move(formatted);
  } else if (format == FileFormat::kGltf) {
    io_internal::GltfWriteOptions gltf;
    gltf.binary = io_internal::LowercaseExtension(path) == ".glb";
    absl::StatusOr<std::string> formatted = io_internal::FormatGltf(view, gltf);
    if (!formatted.ok()) return io_internal::CannotWrite(path, formatted.status());
    data = *std::move(formatted);
  } else {
    absl::StatusOr<std::string> encoded = EncodePointCloud(cloud, options.draco);
    if (!encoded.ok()) return io_internal::CannotWrite(path, encoded.status());
    data = *std::move(encoded);
  }
  return WriteFileContents(path, data);
}

}  // namespace neuralmesh
