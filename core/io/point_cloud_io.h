// Reads and writes point clouds (positions, optional normals, weights and colours) in PLY, XYZ,
// OBJ, OFF and Draco files, and reads them from glTF, chosen by the file-name extension
// (case-insensitive).
#ifndef NEURALMESH_CORE_IO_POINT_CLOUD_IO_H_
#define NEURALMESH_CORE_IO_POINT_CLOUD_IO_H_

#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/io/draco_codec.h"
#include "core/io/las_description.h"
#include "core/io/point_selection.h"
#include "core/point_cloud.h"

namespace neuralmesh {

// The extensions ReadPointCloud handles, for messages: ".ply, .xyz, .txt, .pts, .ptx, .las,
// .pcd, .e57, .obj, .off, .drc, .glb, .gltf".
extern const char kReadablePointCloudExtensions[];
// The extensions WritePointCloud handles, for messages: ".ply, .xyz, .txt, .pts, .ptx, .las,
// .pcd, .e57, .drc, .glb, .gltf".
extern const char kWritablePointCloudExtensions[];

// True when ReadPointCloud handles the extension of `path` (kReadablePointCloudExtensions).
bool IsReadablePointCloudExtension(std::string_view path);

// True when WritePointCloud handles the extension of `path` (kWritablePointCloudExtensions).
bool IsWritablePointCloudExtension(std::string_view path);

// What WritePointCloud keeps of a cloud besides its positions in the format of `path`: all of
// it, except in LAS and PTX (colours only) and E57 (no weights); nothing for an extension it
// does not write.
struct WrittenPointAttributes {
  bool normals = false;
  bool weights = false;
  bool colors = false;
};
WrittenPointAttributes PointAttributesWrittenTo(std::string_view path);

// How WritePointCloud stores the points of a PCD file (its DATA line).
enum class PcdData {
  kBinary,            // Point records, as in memory: the fastest to read and write.
  kBinaryCompressed,  // Field by field, LZF-compressed: smaller, as PCL's maps are kept.
  kAscii,             // Text lines.
};

struct PointCloudWriteOptions {
  DracoOptions draco;               // .drc: quantization and speed.
  PcdData pcd = PcdData::kBinary;  // .pcd.
};

// Reads the points at `path`; faces in the file are skipped without being checked:
//   .ply  ASCII or binary (either byte order): 'vertex' x, y, z of any scalar type; nx, ny, nz
//         when all present; the first of confidence, weight, quality, intensity, scalar as
//         weights; red, green, blue (or r, g, b) as colours.
//   .xyz, .txt, .pts  "x y z [nx ny nz] [w]", "x y z r g b", "x y z i r g b" (PTS) lines
//         and others a header comment names ("# x y z nx ny nz r g b w"); see internal/xyz.h.
//   .ptx  Leica PTX scans, each moved by its transformation; colours when every point has
//         them; empty grid cells (0 0 0) left out and counted in `left_out`; see
//         internal/ptx.h.
//   .las  LAS 1.0-1.4 point records of formats 0-10, with colours where the format has them;
//         withheld points are left out, and so are those of classes outside
//         selection.las_classes or, without them, those classified as noise (classes 7 and
//         18); all counted in `left_out` when it is given.
//   .pcd  PCL's Point Cloud Data (ascii, binary, binary_compressed): x y z, normal_x normal_y
//         normal_z, rgb or rgba, confidence/weight/quality as weights; points without a
//         position (NaN) left out and counted in `left_out`; see internal/pcd.h.
//   .e57  ASTM E57: every scan, from cartesian or spherical coordinates, moved by its pose;
//         colours and surface normals when every scan has them; invalid points left out and
//         counted in `left_out`; see internal/e57.h.
//   .obj  the 'v' lines, 'v x y z r g b' with colours ('vn' is ignored: OBJ normals belong to
//         face corners).
//   .off  the vertices of OFF, COFF (with colours), NOFF (with normals), STOFF.
//   .drc  a Draco point cloud, or the points of a Draco mesh.
//   .glb, .gltf  the vertices of every mesh primitive the default scene draws, placed by their
//         nodes, with COLOR_0 colours, NORMAL normals and _WEIGHT weights (see internal/gltf.h);
//         vertices at identical positions merged (as ReadMesh).
// Georeferenced coordinates, too far from zero for a float to keep their resolution, are read
// relative to PointCloud::origin (internal/position_collector.h; Draco: its metadata).
// Returns NOT_FOUND when the file cannot be opened or read; INVALID_ARGUMENT for an
// unsupported extension (listing the supported ones), an empty file, a file with no points,
// malformed content (the message gives the line or byte offset and what was expected), or a
// cloud that fails ValidatePointCloud (e.g. negative weights).
// For a LAS or LAZ file, `las` (when given) gets DescribeLasFile's description of it, taken in
// the same pass over its records.
absl::StatusOr<PointCloud> ReadPointCloud(const std::string& path,
                                          PointsLeftOut* left_out = nullptr,
                                          const PointSelection& selection = {},
                                          LasDescription* las = nullptr);

// Writes `cloud` to `path`, replacing any file there: binary little-endian .ply (float x, y, z,
// nx, ny, nz, confidence and uchar red, green, blue as present), "x y z [nx ny nz] [r g b] [w]"
// text for .xyz/.txt/.pts (a header comment names the columns), PTX of one scan ("x y z
// intensity [r g b]", intensity 0.5; no normals or weights: internal/ptx.h), LAS 1.2 of point
// format 0 or 2 (with colours; no normals or weights: internal/las.h), PCD (x y z, normal_x
// normal_y normal_z, rgb, confidence as present; options.pcd picks binary, binary_compressed
// or ascii data), E57 of one scan (scaled integer coordinates, colours, normals; no weights:
// internal/e57.h), .drc encoded with options.draco, or glTF 2.0 POINTS (.glb, or .gltf with
// its buffer embedded) with COLOR_0, NORMAL (unit length) and _WEIGHT attributes as present.
// The positions are written with cloud.origin put back (PLY and PCD doubles, exact text (XYZ,
// PTX), the LAS and E57 offsets, a glTF node's translation, Draco metadata).
// Returns INVALID_ARGUMENT for an unsupported extension, an empty cloud, a cloud that fails
// ValidatePointCloud, more points than LAS counts, or invalid Draco options; otherwise the
// status of the write ("cannot write 'path': reason").
absl::Status WritePointCloud(const PointCloud& cloud, const std::string& path,
                             const PointCloudWriteOptions& options = {});

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_POINT_CLOUD_IO_H_
