// The subcommands that work without a server: `reconstruct` (local learning), `stats` and
// `eval`.
#ifndef NEURALMESH_CLIENT_LOCAL_COMMANDS_H_
#define NEURALMESH_CLIENT_LOCAL_COMMANDS_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "client/inputs.h"
#include "core/analysis/color_source.h"
#include "core/analysis/statistical_outliers.h"
#include "core/io/draco_codec.h"
#include "core/io/point_cloud_io.h"
#include "core/io/point_selection.h"
#include "core/io/mesh_io.h"
#include "core/learning/learner_options.h"

namespace neuralmesh::client {

struct LocalReconstructOptions {
  // A point cloud or mesh file, or builtin:NAME; or several point cloud files, learned as one.
  std::vector<std::string> inputs;
  std::string output;        // The final mesh; its extension picks the format.
  size_t vertices = 0;       // Final vertex count, > 4.
  std::vector<size_t> lods;  // Milestones below `vertices`, each written beside `output`.
  LearnerOptions learner;
  // A mesh file to learn on from (Learner::CreateFrom); empty: learner.initial_mesh.
  std::string start_mesh;
  SamplingMode sampling = SamplingMode::kUniform;
  std::optional<OutlierOptions> outliers;  // Set: remove a point cloud's outliers first.
  PointSelection selection;                // Which points of a LAS file are read.
  // Sample the one file INPUT where it lies instead of reading it (LoadOffCoreTargetSpace).
  bool off_core = false;
  // Set: when the input carries colours, every mesh written gets them (color_source.h).
  std::optional<PointColorOptions> colors = PointColorOptions{};
  absl::Duration time_budget = absl::InfiniteDuration();  // For the whole run.
  uint64_t max_steps = 0;  // Basic Steps for the whole run; 0: no limit.
  MeshWriteOptions writing;  // For OUTPUT and the LOD files: Draco settings, glTF compression.
  bool progress = false;   // Draw a progress bar on `err`.
};

// Learns the input's surface up to each LOD and then to `vertices`, writing each milestone
// (OUTPUT stem + "_lod<N>" + extension) and the final mesh (coloured, with `colors`, when the
// input carries colours), and printing the figures of each on `out`, then a summary line.
// When the time or step budget runs out first, the mesh learned so far is written as OUTPUT
// and the summary says which budget stopped it.
// A first SIGINT or SIGTERM stops learning at a consistent state; the mesh so far is written
// as OUTPUT and CANCELLED returned.
// Returns INVALID_ARGUMENT for invalid options, an unknown output extension, a bad input or
// a start mesh learning cannot go on from; NOT_FOUND for a missing input or start mesh; the
// writer's error when a file cannot be written.
absl::Status RunLocalReconstruct(const LocalReconstructOptions& options, std::ostream& out,
                                 std::ostream& err);

// Prints the mesh report of MESH (a mesh file or builtin:NAME), or for a point cloud file (a
// mesh format's too when it holds no faces) what it holds (and a LAS or LAZ file's
// description), as text or JSON.
absl::Status RunStats(const std::string& mesh, bool json, std::ostream& out);

struct EvalOptions {
  std::string mesh;  // The reconstruction.
  // A mesh file, builtin:NAME for its implicit surface, or a point cloud file (a scan: the
  // points the mesh was learned from).
  std::string reference;
  size_t samples = 0;  // Samples per surface; 0: GeometricErrorOptions' default.
  uint64_t seed = 1;
  bool json = false;
  PointSelection selection;  // Which points of a LAS reference are read.
};

// Prints the geometric error of MESH against REFERENCE (core/analysis/geometric_error.h):
// ComputeGeometricError for a surface, ComputeErrorAgainstPoints for points (a point cloud
// format, or a file without faces), each distance also in the files' units.
absl::Status RunEval(const EvalOptions& options, std::ostream& out);

struct ConvertOptions {
  // A mesh or point cloud file, or builtin:NAME for its dense tessellation; or several point
  // cloud files, written as one.
  std::vector<std::string> inputs;
  // Its extension picks the format: a mesh's (kMeshExtensions) or a point cloud's (.ply .xyz
  // .txt .pts .ptx .las .laz .pcd .e57 .drc .glb .gltf).
  std::string output;
  MeshWriteOptions writing;  // Draco settings, glTF compression (meshes only).
  // Set: a point cloud's statistical outliers are removed before it is written.
  std::optional<OutlierOptions> outliers;
  PointSelection selection;  // Which points of a LAS file are read (and, LAS to LAS, kept).
  PcdData pcd_data = PcdData::kBinary;  // How a .pcd OUTPUT stores its points.
  // With `outliers`, from LAS files (.las, .laz) to LAS: the outliers' records are kept,
  // classified as noise (ASPRS class 7), instead of removed.
  bool outliers_as_noise = false;
};

// Writes INPUT to OUTPUT, colours included where the format holds them. A mesh (a file with
// faces, or builtin:NAME) is written as a mesh, and "OUTPUT: V vertices, F faces" printed
// (", with colours"). Points (a .xyz/.txt/.pts/.ptx/.las/.laz/.pcd/.e57 file, a file without
// faces, or any file written to .xyz/.txt/.pts/.ptx/.las/.laz/.pcd/.e57) are written as a point
// cloud with their normals, weights and colours where the format holds them, and "OUTPUT: N
// points" printed (", with normals, weights, colours"; how many outliers went; what LAS, PTX or
// E57 leaves out).
// One LAS INPUT (.las, .laz) written to LAS without `outliers` or `selection.las_classes` is
// copied whole, every record and the header ("OUTPUT: N records of INPUT, ..."; CopyLas).
// Other LAS INPUTs written to LAS are copied record by record instead
// (core/io/las_cleaning.h), their outliers left out or, with outliers_as_noise, classified as
// noise; several whose records cannot share one file (another point format, coordinate system,
// ...) are written as points, and the line says why (so are records of formats 4-10 written to
// .laz).
// INVALID_ARGUMENT for an unknown output extension (before reading INPUT), a mesh format for
// points that are not a mesh (.obj, .off, .stl), a point format for a builtin surface,
// --remove_outliers for a mesh, --gltf_draco for points, outliers_as_noise for anything but
// LAS INPUTs whose records share a LAS OUTPUT, and the reader's and writer's errors.
absl::Status RunConvert(const ConvertOptions& options, std::ostream& out);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_LOCAL_COMMANDS_H_
