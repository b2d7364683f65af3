// What the `neuralmesh` commands read: point clouds, meshes and the built-in implicit
// surfaces (builtin:NAME), turned into the target space P of the learner (Section 2.1) or
// into points to upload.
#ifndef NEURALMESH_CLIENT_INPUTS_H_
#define NEURALMESH_CLIENT_INPUTS_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/analysis/color_source.h"
#include "core/analysis/statistical_outliers.h"
#include "core/io/mapped_laz_file.h"
#include "core/io/mapped_point_file.h"
#include "core/io/point_selection.h"
#include "core/point_cloud.h"
#include "core/sampling/sampler.h"
#include "core/triangle_mesh.h"

namespace neuralmesh::client {

// How the target space is sampled.
enum class SamplingMode {
  kUniform,    // A point cloud, every point equally likely (Section 2.1).
  kWeighted,   // A point cloud, in proportion to its per-point weights (Section 4.1).
  kArea,       // A triangle mesh, area-uniform (remeshing, Section 4.1).
  kCurvature,  // A triangle mesh, denser where it is curved (Section 4.1).
};

// Parses uniform|weighted|area|curvature; INVALID_ARGUMENT otherwise.
absl::StatusOr<SamplingMode> ParseSamplingMode(absl::string_view name);

// A target space and a line that describes it.
struct TargetSpace {
  std::unique_ptr<Sampler> sampler;
  std::string description;  // "35947 points from bunny.ply (uniform)".
  // The input's colours, when it carries them and colours were asked for; else null.
  std::unique_ptr<ColorSource> colors;
  // Where the sampled positions' (0, 0, 0) lies in the input's coordinates (georeferenced
  // data: PointCloud::origin); the learned meshes carry it.
  Origin origin = kNoOrigin;
};

// The target space of `inputs`: builtin:NAME (its implicit surface; `mode` must be uniform),
// point cloud files (.ply .xyz .ptx .las .pcd .e57 .obj .off .drc .glb; uniform or weighted;
// several are learned as one, LoadPointClouds), or a triangle mesh file for area and curvature
// sampling. Returns NOT_FOUND for a missing file and INVALID_ARGUMENT for an empty or malformed
// one, an unknown extension or builtin name, a sampling mode the input cannot provide, or
// several inputs that are not all point cloud files; each message names the file.
// With `outliers` set, a point cloud's statistical outliers are removed first
// (statistical_outliers.h) and the description says how many; INVALID_ARGUMENT for another
// kind of input. With `colors` set and a point cloud that carries colours (the points left
// after outlier removal), or a mesh whose vertices do, `colors` of the result is set and the
// description ends "with colours". Point cloud files are read with `selection`.
absl::StatusOr<TargetSpace> LoadTargetSpace(
    const std::vector<std::string>& inputs, SamplingMode mode,
    const std::optional<OutlierOptions>& outliers = std::nullopt,
    const std::optional<PointColorOptions>& colors = std::nullopt,
    const PointSelection& selection = {});

// OK when `inputs` is one file that --off_core reads where it lies (by its extension: .las,
// .laz, .ply, .pcd) and no outliers are removed in the client (`remove_outliers`, which needs
// every point in memory); else INVALID_ARGUMENT saying why. CheckInputFile's errors.
absl::Status CheckOffCoreInput(const std::vector<std::string>& inputs, bool remove_outliers);

// The one file of `inputs` read where it lies (--off_core): an uncompressed LAS, binary PLY or
// binary PCD file mapped into memory, a LAS file's records with `selection`'s classes.
// CheckOffCoreInput's errors; MappedPointFile::Open's, naming INPUT.
absl::StatusOr<MappedPointFile> OpenOffCoreFile(const std::vector<std::string>& inputs,
                                                bool remove_outliers,
                                                const PointSelection& selection = {});

// The LAZ file `input` read a chunk at a time (--off_core with --server), its records with
// `selection`'s classes; MappedLazFile::Open's errors, naming INPUT.
absl::StatusOr<MappedLazFile> OpenOffCoreLazFile(const std::string& input,
                                                 const PointSelection& selection = {});

// The target space of `inputs` sampled off-core (OffCoreSampler on OpenOffCoreFile's file).
// Returns INVALID_ARGUMENT for a sampling mode other than uniform; OpenOffCoreFile's errors.
// Colours are not painted off-core: the description says so when the file carries them.
absl::StatusOr<TargetSpace> LoadOffCoreTargetSpace(const std::vector<std::string>& inputs,
                                                   SamplingMode mode, bool remove_outliers,
                                                   const PointSelection& selection = {});

// The most points LoadPointsForUpload samples from a builtin surface: the server's default
// limit of points per session (neuralmesh-server --max_points_per_session), 1.6 GB here.
inline constexpr size_t kMaxBuiltinUploadPoints = size_t{1} << 26;

// The points of `inputs` for upload: point cloud files as read (LoadPointClouds), or
// `builtin_points` samples of a builtin:NAME surface drawn with `seed` (1 to
// kMaxBuiltinUploadPoints). Errors as LoadTargetSpace.
// With `left_out`, `note` and `selection`, as LoadPointClouds.
absl::StatusOr<PointCloud> LoadPointsForUpload(const std::vector<std::string>& inputs,
                                               size_t builtin_points, uint64_t seed,
                                               PointsLeftOut* left_out = nullptr,
                                               std::string* note = nullptr,
                                               const PointSelection& selection = {});

// The points of a point cloud file (any extension ReadPointCloud reads, with `selection`).
// Errors as LoadTargetSpace; `role` names the argument in messages. With `left_out`, as
// LoadPointsForUpload; with `las`, as ReadPointCloud.
absl::StatusOr<PointCloud> LoadPointCloud(const std::string& input, absl::string_view role,
                                          PointsLeftOut* left_out = nullptr,
                                          const PointSelection& selection = {},
                                          LasDescription* las = nullptr);

// The points of point cloud files as one cloud (MergePointClouds: one after another, each
// where its origin puts it). Errors as LoadPointCloud, and INVALID_ARGUMENT for a builtin:NAME
// among several inputs. With `left_out`, the points left out of all the files are counted
// there; `note` (when not null) is set to "" or to what the merge dropped because a file lacks
// it: "; normals dropped (b.las has none)". Each file is read with `selection`.
absl::StatusOr<PointCloud> LoadPointClouds(const std::vector<std::string>& inputs,
                                           absl::string_view role,
                                           PointsLeftOut* left_out = nullptr,
                                           std::string* note = nullptr,
                                           const PointSelection& selection = {});

// The inputs for messages: "'a.las'", "'a.las', 'b.las'".
std::string QuotedInputs(const std::vector<std::string>& inputs);

// "" when no point was left out; else what to tell the user: "; left out 3 withheld points
// and 117 classified as noise", "; left out 120 points without a position", "; left out 5000
// points of other classes".
std::string LeftOutNote(const PointsLeftOut& left_out);

// "" for a zero origin; else (georeferenced data) what to tell the user: "; coordinates taken
// relative to (X, Y, Z), and put back in the files written".
std::string OriginNote(const Origin& origin);

// "" unless `output` is an STL file and `origin` is not zero; else a line that says its
// coordinates stay relative to the origin (STL holds only floats).
std::string StlOriginNote(const std::string& output, const Origin& origin);

// A mesh to report on or compare: a mesh file, or for builtin:NAME the reference mesh of the
// implicit surface. Errors as LoadTargetSpace; `role` names the argument in messages.
absl::StatusOr<TriangleMesh> LoadMesh(const std::string& input, absl::string_view role);

// The mesh of --start_mesh (a mesh file): NOT_FOUND or INVALID_ARGUMENT as ReadMesh, the
// message prefixed "--start_mesh: ". Whether learning can go on from it is judged by the
// learner (Learner::CreateFrom) or the server.
absl::StatusOr<TriangleMesh> ReadStartMesh(const std::string& path);

// Moves the start mesh read from `path` into the frame of the points, relative to `origin`
// (MoveOrigin); INVALID_ARGUMENT "--start_mesh 'path': ..." when it cannot be.
absl::Status MoveStartMesh(const Origin& origin, const std::string& path,
                           TriangleMesh* mesh);

// A short name for output files: the file name without directory and extension, NAME for
// builtin:NAME, "stdin" for '-' (points streamed from standard input).
std::string InputStem(const std::string& input);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_INPUTS_H_
