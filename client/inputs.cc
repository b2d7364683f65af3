#include "client/inputs.h"

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/builtin_shapes.h"
#include "client/file_util.h"
#include "core/io/mesh_io.h"
#include "core/io/point_cloud_io.h"
#include "core/io/point_cloud_merge.h"
#include "core/sampling/mesh_sampler.h"
#include "core/sampling/off_core_sampler.h"
#include "core/sampling/point_cloud_sampler.h"
#include "core/sampling/sample_points.h"
#include "core/status_macros.h"

namespace neuralmesh::client {
namespace {

const char* ModeName(SamplingMode mode) {
  switch (mode) {
    case SamplingMode::kUniform:
      return "uniform";
    case SamplingMode::kWeighted:
      return "weighted";
    case SamplingMode::kArea:
      return "area";
    case SamplingMode::kCurvature:
      return "curvature";
  }
  return "uniform";
}

// Puts the role and the file in front of a reader's message, so that every error says which
// argument it is about.
absl::Status InFile(const absl::Status& status, absl::string_view role, const std::string& path) {
  if (status.ok()) return status;
  // The readers already quote the path; then the role alone is enough.
  if (absl::StrContains(status.message(), absl::StrCat("'", path, "'"))) {
    return absl::Status(status.code(), absl::StrCat(role, " ", status.message()));
  }
  return absl::Status(status.code(), absl::StrCat(role, " '", path, "': ", status.message()));
}

}  // namespace

absl::StatusOr<SamplingMode> ParseSamplingMode(absl::string_view name) {
  for (SamplingMode mode : {SamplingMode::kUniform, SamplingMode::kWeighted, SamplingMode::kArea,
                            SamplingMode::kCurvature}) {
    if (name == ModeName(mode)) return mode;
  }
  return absl::InvalidArgumentError(absl::StrCat("--sampling: unknown mode '", name,
                                                 "'; use uniform, weighted, area or curvature"));
}

// Paints with `source` (built from INPUT `input`); ", with colours" for the description.
absl::StatusOr<std::string> UseColors(absl::StatusOr<std::unique_ptr<ColorSource>> source,
                                      const std::string& input, TargetSpace& target) {
  if (!source.ok()) return InFile(source.status(), "INPUT", input);
  target.colors = *std::move(source);
  return std::string(", with colours");
}

absl::StatusOr<TargetSpace> LoadTargetSpace(const std::vector<std::string>& inputs,
                                            SamplingMode mode,
                                            const std::optional<OutlierOptions>& outliers,
                                            const std::optional<PointColorOptions>& colors,
                                            const PointSelection& selection) {
  if (inputs.empty()) return absl::InvalidArgumentError("INPUT is required");
  const std::string& input = inputs.front();
  TargetSpace target;
  if (inputs.size() > 1 && (mode == SamplingMode::kArea || mode == SamplingMode::kCurvature)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--sampling ", ModeName(mode), " samples one mesh; several INPUTs are ",
                     "point cloud files learned as one (uniform or weighted sampling)"));
  }
  if (outliers.has_value() && ((inputs.size() == 1 && IsBuiltin(input)) ||
                               mode == SamplingMode::kArea || mode == SamplingMode::kCurvature)) {
    return absl::InvalidArgumentError(
        "--remove_outliers applies to point cloud inputs (uniform or weighted sampling)");
  }
  if (inputs.size() == 1 && IsBuiltin(input)) {
    if (mode != SamplingMode::kUniform) {
      return absl::InvalidArgumentError(
          absl::StrCat("--sampling ", ModeName(mode), " does not apply to ", input,
                       " (a built-in surface is sampled uniformly by area)"));
    }
    NM_ASSIGN_OR_RETURN(target.sampler, MakeBuiltinSurface(input));
    target.description = absl::StrCat("the implicit surface ", input);
    return target;
  }
  if (mode == SamplingMode::kArea || mode == SamplingMode::kCurvature) {
    NM_RETURN_IF_ERROR(CheckInputFile(input, "INPUT"));
    absl::StatusOr<TriangleMesh> mesh = ReadMesh(input);
    if (!mesh.ok()) return InFile(mesh.status(), "INPUT", input);
    if (mesh->faces.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("INPUT '", input, "' has no faces: --sampling ", ModeName(mode),
                       " needs a triangle mesh (use uniform or weighted for a point cloud)"));
    }
    const size_t faces = mesh->faces.size();
    target.origin = mesh->origin;
    std::string with_colors;
    if (colors.has_value() && !mesh->colors.empty()) {
      NM_ASSIGN_OR_RETURN(with_colors, UseColors(MakeMeshColorSource(*mesh), input, target));
    }
    MeshSamplerOptions options;
    options.mode =
        mode == SamplingMode::kArea ? MeshSamplingMode::kArea : MeshSamplingMode::kCurvature;
    absl::StatusOr<std::unique_ptr<Sampler>> sampler =
        MeshSampler::Create(std::make_shared<const TriangleMesh>(*std::move(mesh)), options);
    if (!sampler.ok()) return InFile(sampler.status(), "INPUT", input);
    target.sampler = *std::move(sampler);
    target.description =
        absl::StrCat("the ", faces, " triangles of ", input, " (", ModeName(mode), " sampling",
                     with_colors, OriginNote(target.origin), ")");
    return target;
  }
  PointsLeftOut left_out;
  std::string merge_note;
  NM_ASSIGN_OR_RETURN(PointCloud cloud,
                      LoadPointClouds(inputs, "INPUT", &left_out, &merge_note, selection));
  const std::string names = absl::StrJoin(inputs, ", ");
  if (mode == SamplingMode::kWeighted && cloud.weights.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "INPUT ", QuotedInputs(inputs), " has no per-point weights for --sampling weighted"));
  }
  const size_t points = cloud.size();
  const std::string notes =
      absl::StrCat(merge_note, LeftOutNote(left_out), OriginNote(cloud.origin));
  target.origin = cloud.origin;
  std::string removed_outliers;
  if (outliers.has_value()) {
    absl::StatusOr<size_t> removed = RemoveStatisticalOutliers(cloud, *outliers);
    if (!removed.ok()) return InFile(removed.status(), "INPUT", names);
    removed_outliers = absl::StrCat(", outliers removed: ", *removed);
  }
  std::string with_colors;
  if (colors.has_value() && !cloud.colors.empty()) {
    NM_ASSIGN_OR_RETURN(with_colors,
                        UseColors(MakePointColorSource(cloud, *colors), names, target));
  }
  auto shared = std::make_shared<const PointCloud>(std::move(cloud));
  absl::StatusOr<std::unique_ptr<Sampler>> sampler = mode == SamplingMode::kWeighted
                                                         ? WeightedPointCloudSampler::Create(shared)
                                                         : UniformPointCloudSampler::Create(shared);
  if (!sampler.ok()) return InFile(sampler.status(), "INPUT", names);
  target.sampler = *std::move(sampler);
  target.description = absl::StrCat(points, " points of ", names, " (", ModeName(mode), " sampling",
                                    removed_outliers, with_colors, notes, ")");
  return target;
}

absl::Status CheckOffCoreInput(const std::vector<std::string>& inputs, bool remove_outliers) {
  if (inputs.size() != 1) {
    return absl::InvalidArgumentError(
        "--off_core reads one file where it lies; several INPUTs are read whole and learned as "
        "one without it");
  }
  const std::string& input = inputs.front();
  const bool read_where_it_lies =
      absl::EndsWithIgnoreCase(input, ".las") || absl::EndsWithIgnoreCase(input, ".laz") ||
      absl::EndsWithIgnoreCase(input, ".ply") || absl::EndsWithIgnoreCase(input, ".pcd");
  if (IsBuiltin(input) || !read_where_it_lies) {
    return absl::InvalidArgumentError(
        absl::StrCat("--off_core reads LAS (.las, .laz), binary PLY (.ply) and binary PCD "
                     "(.pcd) files where they lie; INPUT '",
                     input, "' is read whole without it"));
  }
  if (remove_outliers) {
    return absl::InvalidArgumentError(
        "--remove_outliers judges every point against its neighbours, so it reads the file "
        "whole: not with --off_core");
  }
  return CheckInputFile(input, "INPUT");
}

absl::StatusOr<MappedPointFile> OpenOffCoreFile(const std::vector<std::string>& inputs,
                                                bool remove_outliers,
                                                const PointSelection& selection) {
  NM_RETURN_IF_ERROR(CheckOffCoreInput(inputs, remove_outliers));
  absl::StatusOr<MappedPointFile> file =
      MappedPointFile::Open(inputs.front(), selection.las_classes);
  if (!file.ok()) return InFile(file.status(), "INPUT", inputs.front());
  return file;
}

absl::StatusOr<MappedLazFile> OpenOffCoreLazFile(const std::string& input,
                                                 const PointSelection& selection) {
  absl::StatusOr<MappedLazFile> file = MappedLazFile::Open(input, selection.las_classes);
  if (!file.ok()) return InFile(file.status(), "INPUT", input);
  return file;
}

absl::StatusOr<TargetSpace> LoadOffCoreTargetSpace(const std::vector<std::string>& inputs,
                                                   SamplingMode mode, bool remove_outliers,
                                                   const PointSelection& selection) {
  if (mode != SamplingMode::kUniform) {
    return absl::InvalidArgumentError(
        absl::StrCat("--off_core samples uniformly, not by --sampling ", ModeName(mode)));
  }
  NM_ASSIGN_OR_RETURN(MappedPointFile file, OpenOffCoreFile(inputs, remove_outliers, selection));
  TargetSpace target;
  target.origin = file.origin();
  target.description = absl::StrFormat(
      "the %d records of %s, sampled where they lie (off-core; %.1f%% of them points to read%s%s)",
      file.records(), inputs.front(), 100 * file.kept_share(),
      file.has_colors() ? "; colours are not painted off-core" : "", OriginNote(target.origin));
  target.sampler = std::make_unique<OffCoreSampler>(std::move(file));
  return target;
}

absl::StatusOr<PointCloud> LoadPointsForUpload(const std::vector<std::string>& inputs,
                                               size_t builtin_points, uint64_t seed,
                                               PointsLeftOut* left_out, std::string* note,
                                               const PointSelection& selection) {
  if (inputs.size() == 1 && IsBuiltin(inputs.front())) {
    if (note != nullptr) note->clear();
    if (builtin_points == 0) return absl::InvalidArgumentError("--points must be > 0");
    if (builtin_points > kMaxBuiltinUploadPoints) {
      return absl::InvalidArgumentError(absl::StrCat(
          "--points must be at most ", kMaxBuiltinUploadPoints, ", not ", builtin_points));
    }
    NM_ASSIGN_OR_RETURN(const std::unique_ptr<ImplicitSurface> surface,
                        MakeBuiltinSurface(inputs.front()));
    return SamplePoints(*surface, builtin_points, seed);
  }
  return LoadPointClouds(inputs, "INPUT", left_out, note, selection);
}

absl::StatusOr<PointCloud> LoadPointClouds(const std::vector<std::string>& inputs,
                                           absl::string_view role, PointsLeftOut* left_out,
                                           std::string* note, const PointSelection& selection) {
  if (note != nullptr) note->clear();
  if (inputs.empty()) return absl::InvalidArgumentError(absl::StrCat(role, " is required"));
  if (inputs.size() == 1) return LoadPointCloud(inputs.front(), role, left_out, selection);
  std::vector<PointCloud> clouds;
  PointsLeftOut total;
  for (const std::string& input : inputs) {
    if (IsBuiltin(input)) {
      return absl::InvalidArgumentError(absl::StrCat(
          input, " is a surface: several ", role, "s must all be point cloud files"));
    }
    PointsLeftOut one;
    NM_ASSIGN_OR_RETURN(PointCloud cloud, LoadPointCloud(input, role, &one, selection));
    total += one;
    clouds.push_back(std::move(cloud));
  }
  // What some files have and another lacks, named by the first that lacks it.
  std::vector<std::string> dropped;
  const auto check = [&](const char* what, auto has) {
    const auto without = std::find_if_not(clouds.begin(), clouds.end(), has);
    if (without != clouds.end() && std::any_of(clouds.begin(), clouds.end(), has)) {
      dropped.push_back(
          absl::StrCat(what, " dropped (", inputs[without - clouds.begin()], " has none)"));
    }
  };
  check("normals", [](const PointCloud& c) { return !c.normals.empty(); });
  check("weights", [](const PointCloud& c) { return !c.weights.empty(); });
  check("colours", [](const PointCloud& c) { return !c.colors.empty(); });
  if (note != nullptr && !dropped.empty()) *note = absl::StrCat("; ", absl::StrJoin(dropped, ", "));
  if (left_out != nullptr) *left_out = total;
  return MergePointClouds(std::move(clouds));
}

std::string QuotedInputs(const std::vector<std::string>& inputs) {
  return absl::StrCat("'", absl::StrJoin(inputs, "', '"), "'");
}

absl::StatusOr<PointCloud> LoadPointCloud(const std::string& input, absl::string_view role,
                                          PointsLeftOut* left_out, const PointSelection& selection,
                                          LasDescription* las) {
  NM_RETURN_IF_ERROR(CheckInputFile(input, role));
  absl::StatusOr<PointCloud> cloud = ReadPointCloud(input, left_out, selection, las);
  if (!cloud.ok()) return InFile(cloud.status(), role, input);
  return cloud;
}

std::string LeftOutNote(const PointsLeftOut& left_out) {
  // "1 withheld point and 40 classified as noise": the first part names the points.
  std::vector<std::string> parts;
  const auto add = [&](size_t count, absl::string_view before, absl::string_view after) {
    if (count == 0) return;
    const char* points = !parts.empty() ? "" : count > 1 ? " points" : " point";
    parts.push_back(absl::StrCat(count, before, points, after));
  };
  add(left_out.withheld, " withheld", "");
  add(left_out.noise, "", " classified as noise");
  add(left_out.invalid, "", " without a position");
  add(left_out.other_class, "", " of other classes");
  if (parts.empty()) return "";
  const std::string last = parts.back();
  parts.pop_back();
  return absl::StrCat("; left out ", absl::StrJoin(parts, ", "), parts.empty() ? "" : " and ",
                      last);
}

std::string OriginNote(const Origin& origin) {
  if (origin == kNoOrigin) return "";
  return absl::StrFormat(
      "; coordinates taken relative to (%.15g, %.15g, %.15g), and put back in the files written",
      origin[0], origin[1], origin[2]);
}

std::string StlOriginNote(const std::string& output, const Origin& origin) {
  if (origin == kNoOrigin || !absl::EndsWithIgnoreCase(output, ".stl")) {
    return "";
  }
  return absl::StrFormat(
      "%s: STL holds only floats; its coordinates stay relative to (%.15g, %.15g, %.15g)\n",
      output, origin[0], origin[1], origin[2]);
}

absl::StatusOr<TriangleMesh> LoadMesh(const std::string& input, absl::string_view role) {
  if (IsBuiltin(input)) return BuiltinReferenceMesh(input);
  NM_RETURN_IF_ERROR(CheckInputFile(input, role));
  absl::StatusOr<TriangleMesh> mesh = ReadMesh(input);
  if (!mesh.ok()) return InFile(mesh.status(), role, input);
  return mesh;
}

absl::StatusOr<TriangleMesh> ReadStartMesh(const std::string& path) {
  absl::StatusOr<TriangleMesh> mesh = ReadMesh(path);
  if (!mesh.ok()) {
    return absl::Status(mesh.status().code(),
                        absl::StrCat("--start_mesh: ", mesh.status().message()));
  }
  return mesh;
}

absl::Status MoveStartMesh(const Origin& origin, const std::string& path,
                           TriangleMesh* mesh) {
  const absl::Status moved = MoveOrigin(origin, mesh);
  if (moved.ok()) return moved;
  return absl::InvalidArgumentError(absl::StrCat("--start_mesh '", path, "': ", moved.message()));
}

std::string InputStem(const std::string& input) {
  if (IsBuiltin(input)) return input.substr(kBuiltinPrefix.size());
  if (input == "-") return "stdin";
  return std::filesystem::path(input).stem().string();
}

}  // namespace neuralmesh::client
