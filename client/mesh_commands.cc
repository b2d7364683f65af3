// RunStats, RunEval and RunConvert (declared in client/local_commands.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"
#include "client/builtin_shapes.h"
#include "client/inputs.h"
#include "client/local_commands.h"
#include "core/analysis/geometric_error.h"
#include "core/analysis/json_writer.h"
#include "core/analysis/mesh_report.h"
#include "core/analysis/statistical_outliers.h"
#include "core/io/las_cleaning.h"
#include "core/io/las_description.h"
#include "core/io/mesh_io.h"
#include "core/io/point_cloud_io.h"
#include "core/status_macros.h"

namespace neuralmesh::client {

namespace {

// The report of a point cloud file (one ReadPointCloud reads that is no mesh file): the points
// read and left out, where they lie, what they carry; and for LAS and LAZ the header, the
// classes and the compression (LasDescription).
absl::Status PrintPointCloudStats(const std::string& path, bool json, std::ostream& out) {
  PointsLeftOut left_out;
  // A LAS or LAZ file is described in the pass that reads its points.
  std::optional<LasDescription> las;
  if (IsLasPath(path)) las.emplace();
  NM_ASSIGN_OR_RETURN(const PointCloud cloud,
                      LoadPointCloud(path, "FILE", &left_out, {}, las ? &*las : nullptr));
  std::array<double, 3> low = {INFINITY, INFINITY, INFINITY};
  std::array<double, 3> high = {-INFINITY, -INFINITY, -INFINITY};
  for (const Vec3f& p : cloud.positions) {
    for (int c = 0; c < 3; ++c) {
      low[c] = std::min(low[c], cloud.origin[c] + double{p[c]});
      high[c] = std::max(high[c], cloud.origin[c] + double{p[c]});
    }
  }
  std::vector<std::string> carried;
  if (!cloud.colors.empty()) carried.push_back("colours");
  if (!cloud.normals.empty()) carried.push_back("normals");
  if (!cloud.weights.empty()) carried.push_back("weights");
  // Classes with records, "2: 1500" (JSON: {"2": 1500}).
  std::vector<std::pair<int, uint64_t>> classes;
  if (las.has_value()) {
    for (int c = 0; c < 256; ++c) {
      if (las->records_by_class[c] > 0) classes.push_back({c, las->records_by_class[c]});
    }
  }
  if (json) {
    JsonWriter writer(2);
    writer.BeginObject();
    writer.Key("file").String(path);
    writer.Key("points").Uint(cloud.size());
    writer.Key("left_out").BeginObject();
    writer.Key("withheld").Uint(left_out.withheld);
    writer.Key("noise").Uint(left_out.noise);
    writer.Key("invalid").Uint(left_out.invalid);
    writer.EndObject();
    if (!cloud.empty()) {
      writer.Key("min").BeginArray();
      for (const double v : low) writer.Double(v);
      writer.EndArray();
      writer.Key("max").BeginArray();
      for (const double v : high) writer.Double(v);
      writer.EndArray();
    }
    writer.Key("colors").Bool(!cloud.colors.empty());
    writer.Key("normals").Bool(!cloud.normals.empty());
    writer.Key("weights").Bool(!cloud.weights.empty());
    if (las.has_value()) {
      writer.Key("las").BeginObject();
      writer.Key("version").String(absl::StrCat("1.", las->version_minor));
      writer.Key("point_format").Int(las->point_format);
      writer.Key("record_length").Uint(las->record_length);
      writer.Key("extra_bytes").Uint(las->extra_bytes);
      writer.Key("records").Uint(las->records);
      writer.Key("withheld").Uint(las->withheld);
      writer.Key("classes").BeginObject();
      for (const auto& [c, count] : classes) writer.Key(absl::StrCat(c)).Uint(count);
      writer.EndObject();
      writer.Key("scale").BeginArray();
      for (const double v : las->scale) writer.Double(v);
      writer.EndArray();
      writer.Key("offset").BeginArray();
      for (const double v : las->offset) writer.Double(v);
      writer.EndArray();
      writer.Key("coordinate_system").String(las->coordinate_system);
      writer.Key("gps_time").String(las->standard_gps_time ? "adjusted standard" : "week");
      writer.Key("variable_length_records").Uint(las->variable_length_records);
      writer.Key("generating_software").String(las->generating_software);
      writer.Key("file_bytes").Uint(las->file_bytes);
      if (!las->compression.empty()) writer.Key("compression").String(las->compression);
      writer.EndObject();
    }
    writer.EndObject();
    NM_ASSIGN_OR_RETURN(const std::string text, writer.Finish());
    out << text << "\n";
    return absl::OkStatus();
  }
  out << path << "\n";
  if (las.has_value()) {
    out << absl::StrFormat("  LAS 1.%d, point format %d: %d records of %d bytes (%d extra)\n",
                           las->version_minor, las->point_format, las->records, las->record_length,
                           las->extra_bytes);
    if (!las->compression.empty()) {
      out << absl::StrFormat("  LAZ: %s; %d bytes\n", las->compression, las->file_bytes);
    }
    out << absl::StrFormat("  scale %.17g %.17g %.17g, offset %.17g %.17g %.17g\n", las->scale[0],
                           las->scale[1], las->scale[2], las->offset[0], las->offset[1],
                           las->offset[2]);
    out << "  coordinate system: "
        << (las->coordinate_system.empty() ? "none"
                                           : absl::StrCat(las->coordinate_system, " record"))
        << "; GPS time: " << (las->standard_gps_time ? "adjusted standard" : "week") << "\n";
    out << "  classes: "
        << absl::StrJoin(classes, ", ",
                         [](std::string* text, const std::pair<int, uint64_t>& c) {
                           absl::StrAppend(text, c.first, ": ", c.second);
                         })
        << (las->withheld > 0 ? absl::StrCat(" (", las->withheld, " withheld)") : "") << "\n";
    if (!las->generating_software.empty()) {
      out << "  written by " << las->generating_software << "\n";
    }
  }
  out << "  " << cloud.size() << " points read" << LeftOutNote(left_out) << "\n";
  if (!cloud.empty()) {
    out << absl::StrFormat("  from (%.15g, %.15g, %.15g) to (%.15g, %.15g, %.15g)\n", low[0],
                           low[1], low[2], high[0], high[1], high[2]);
  }
  out << "  with " << (carried.empty() ? "positions only" : absl::StrJoin(carried, ", ")) << "\n";
  return absl::OkStatus();
}

}  // namespace

absl::Status RunStats(const std::string& mesh_path, bool json, std::ostream& out) {
  if (!IsSupportedMeshExtension(mesh_path) && IsReadablePointCloudExtension(mesh_path)) {
    return PrintPointCloudStats(mesh_path, json, out);
  }
  NM_ASSIGN_OR_RETURN(TriangleMesh mesh, LoadMesh(mesh_path, "MESH"));
  // Points in a mesh format (a PLY of a scan): the point cloud's report, read again with what
  // points carry (the mesh let go first: a scan's points can fill gigabytes).
  if (mesh.faces.empty() && IsReadablePointCloudExtension(mesh_path)) {
    mesh = TriangleMesh();
    return PrintPointCloudStats(mesh_path, json, out);
  }
  const MeshReport report = ComputeMeshReport(mesh);
  if (json) {
    out << MeshReportToJson(report, 2) << "\n";
  } else {
    out << mesh_path << "\n" << MeshReportToText(report);
  }
  return absl::OkStatus();
}

namespace {

// The error's figures, as text or JSON; `points` is the count of the reference's points when
// it was a point cloud, else 0.
absl::Status PrintGeometricError(const EvalOptions& options, const GeometricError& error,
                                 size_t samples, size_t points, std::ostream& out) {
  const bool has_normals = !std::isnan(error.normal_consistency);
  if (options.json) {
    JsonWriter json(2);
    json.BeginObject();
    json.Key("mesh").String(options.mesh);
    json.Key("reference").String(options.reference);
    if (points > 0) json.Key("reference_points").Uint(points);
    json.Key("samples").Uint(samples);
    json.Key("chamfer_l1").Double(error.chamfer_l1);
    json.Key("hausdorff").Double(error.hausdorff);
    if (has_normals) json.Key("normal_consistency").Double(error.normal_consistency);
    json.Key("accuracy").Double(error.accuracy);
    json.Key("completeness").Double(error.completeness);
    json.Key("diagonal").Double(error.diagonal);
    json.EndObject();
    NM_ASSIGN_OR_RETURN(const std::string text, json.Finish());
    out << text << "\n";
    return absl::OkStatus();
  }
  const char* other = points > 0 ? "points" : "reference";
  if (points > 0) {
    out << absl::StrFormat(
        "%s against the %d points of %s (each point to the mesh; %d samples of the mesh to\n"
        "their nearest points)\n",
        options.mesh, points, options.reference, samples);
  } else {
    out << absl::StrFormat("%s against %s (%d samples per surface)\n", options.mesh,
                           options.reference, samples);
  }
  // Each distance relative to the diagonal and in the files' units (metres for most scans).
  out << absl::StrFormat("  %-18s  %-12s  %-12s  (%s bounding-box diagonal: %.6g)\n", "",
                         "/ diagonal", "distance", points > 0 ? "the points'" : "the reference's",
                         error.diagonal);
  const auto line = [&](const char* name, double value, const std::string& what) {
    const std::string row = absl::StrFormat("  %-18s  %-12.6g  %-12.6g%s", name, value,
                                            value * error.diagonal, what);
    out << absl::StripTrailingAsciiWhitespace(row) << "\n";
  };
  line("chamfer_l1", error.chamfer_l1, "");
  line("hausdorff", error.hausdorff, "");
  if (has_normals) out << absl::StrFormat("  normal_consistency  %.6f\n", error.normal_consistency);
  line("accuracy", error.accuracy, absl::StrCat("  (reconstruction -> ", other, ")"));
  line("completeness", error.completeness, absl::StrCat("  (", other, " -> reconstruction)"));
  return absl::OkStatus();
}

}  // namespace

absl::Status RunEval(const EvalOptions& options, std::ostream& out) {
  NM_ASSIGN_OR_RETURN(TriangleMesh mesh, LoadMesh(options.mesh, "MESH"));
  // A surface (builtin:NAME, a mesh file with faces), or points: a point cloud format, or a
  // mesh format whose file holds no faces.
  std::optional<TriangleMesh> reference;
  const std::string& name = options.reference;
  if (IsBuiltin(name) || !IsReadablePointCloudExtension(name) || IsSupportedMeshExtension(name)) {
    NM_ASSIGN_OR_RETURN(reference, LoadMesh(name, "--reference"));
    if (reference->faces.empty() && IsReadablePointCloudExtension(name)) reference.reset();
  }
  GeometricErrorOptions error_options;
  if (options.samples > 0) error_options.samples = options.samples;
  error_options.seed = options.seed;
  NM_RETURN_IF_ERROR(error_options.Validate());
  const auto named = [&](const absl::Status& status) {
    return absl::Status(status.code(),
                        absl::StrCat("MESH '", options.mesh, "' against --reference '",
                                     options.reference, "': ", status.message()));
  };
  absl::StatusOr<GeometricError> error;
  size_t points = 0;
  if (!reference.has_value()) {
    NM_ASSIGN_OR_RETURN(const PointCloud cloud,
                        LoadPointClouds({options.reference}, "--reference", nullptr, nullptr,
                                        options.selection));
    // Georeferenced files may have been read relative to different origins.
    if (const absl::Status moved = MoveOrigin(cloud.origin, &mesh); !moved.ok()) {
      return named(moved);
    }
    points = cloud.size();
    error = ComputeErrorAgainstPoints(mesh, cloud, error_options);
  } else {
    if (const absl::Status moved = MoveOrigin(reference->origin, &mesh); !moved.ok()) {
      return named(moved);
    }
    error = ComputeGeometricError(mesh, *reference, error_options);
  }
  // The error speaks of "the reconstruction": the message names the two files.
  if (!error.ok()) return named(error.status());
  return PrintGeometricError(options, *error, error_options.samples, points, out);
}

namespace {

// RunConvert for points: read as a point cloud, outliers removed, written as one.
absl::Status ConvertPoints(const ConvertOptions& options, std::ostream& out) {
  if (!IsWritablePointCloudExtension(options.output)) {
    return absl::InvalidArgumentError(
        absl::StrCat("INPUT ", QuotedInputs(options.inputs),
                     " holds points without faces: OUTPUT '", options.output,
                     "' must be a point cloud format (", kWritablePointCloudExtensions, ")"));
  }
  const bool gltf = absl::EndsWithIgnoreCase(options.output, ".glb") ||
                    absl::EndsWithIgnoreCase(options.output, ".gltf");
  if (gltf && options.writing.gltf_draco) {
    return absl::InvalidArgumentError(
        "--gltf_draco compresses meshes; points are written to glTF uncompressed (or to .drc)");
  }
  // LAS to LAS (.las or .laz): the records themselves, with what a PointCloud does not hold.
  const bool las_to_las = IsLasPath(options.output) &&
                          std::all_of(options.inputs.begin(), options.inputs.end(), IsLasPath);
  if (options.outliers_as_noise && !las_to_las) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--outliers_as_noise classifies the outliers of .las/.laz INPUTs in a .las/.laz OUTPUT; "
        "INPUT ", QuotedInputs(options.inputs), " to OUTPUT '", options.output,
        "' can only leave them out"));
  }
  // One LAS file with nothing to remove or select: every record as it is, compressed or not.
  // Records that LAZ is not written in here (FAILED_PRECONDITION) go the points' way below,
  // which says why.
  if (las_to_las && options.inputs.size() == 1 && !options.outliers.has_value() &&
      !options.selection.las_classes.has_value()) {
    const absl::StatusOr<LasCopy> copy = CopyLas(options.inputs.front(), options.output);
    if (copy.ok()) {
      out << options.output << ": " << copy->records << " records of " << options.inputs.front()
          << ", every one and the header as they were (" << copy->read_bytes << " bytes to "
          << copy->written_bytes << ")\n";
      return absl::OkStatus();
    }
    if (!absl::IsFailedPrecondition(copy.status())) return copy.status();
  }
  PointsLeftOut left_out;
  std::string merge_note;
  NM_ASSIGN_OR_RETURN(PointCloud cloud,
                      LoadPointClouds(options.inputs, "INPUT", &left_out, &merge_note,
                                      options.selection));
  const size_t read = cloud.size();
  std::vector<bool> outlier(cloud.size(), false);
  if (options.outliers.has_value()) {
    NM_ASSIGN_OR_RETURN(outlier, FindStatisticalOutliersInPasses(cloud, *options.outliers));
    cloud = WithoutPoints(cloud, outlier);
  }
  const size_t found = read - cloud.size();
  size_t written = cloud.size();
  std::string contents;  // What the file holds besides positions, for the line below.
  std::vector<std::string> dropped;
  const WrittenPointAttributes kept = PointAttributesWrittenTo(options.output);
  // Several LAS files whose records cannot share one file (another coordinate system, extra
  // bytes, ...) are written as points, saying why.
  bool las_records_kept = false;
  std::string not_joined;
  LasJoin join;
  if (las_to_las) {
    const absl::Status joined = WriteCleanedLas(
        options.inputs, outlier,
        options.outliers_as_noise ? LasOutlierRecords::kClassifiedAsNoise
                                  : LasOutlierRecords::kLeftOut,
        options.output, options.selection, &join);
    las_records_kept = joined.ok();
    if (absl::IsFailedPrecondition(joined)) {
      if (options.outliers_as_noise) {
        return absl::InvalidArgumentError(absl::StrCat(
            "--outliers_as_noise: the records of INPUT ", QuotedInputs(options.inputs),
            " cannot be put in one file: ", joined.message()));
      }
      not_joined = absl::StrCat("; the records could not be kept whole: ", joined.message());
    } else {
      NM_RETURN_IF_ERROR(joined);
    }
  }
  if (las_records_kept) {
    contents = options.inputs.size() == 1
                   ? absl::StrCat(", each record as in ", options.inputs.front(),
                                  " with every field, and its header's scale, offset and "
                                  "variable-length records")
                   : absl::StrCat(", each record as in its INPUT with every field",
                                  join.converted ? absl::StrCat(", in point format ",
                                                                join.point_format, " of LAS 1.",
                                                                join.version_minor)
                                                 : std::string(),
                                  ", and the header's offset and variable-length records of ",
                                  options.inputs[join.header_source]);
    // Classified, the outliers and the records left out on reading stay in the file.
    if (options.outliers_as_noise) {
      written = read;
      left_out = {};
    }
  } else {
    NM_RETURN_IF_ERROR(
        WritePointCloud(cloud, options.output, {options.writing.draco, options.pcd_data}));
    // What the file holds (LAS has no place for normals and weights, E57 none for weights).
    std::vector<std::string> carried;
    if (!cloud.normals.empty()) (kept.normals ? carried : dropped).push_back("normals");
    if (!cloud.weights.empty()) (kept.weights ? carried : dropped).push_back("weights");
    if (!cloud.colors.empty()) (kept.colors ? carried : dropped).push_back("colours");
    if (!carried.empty()) contents = absl::StrCat(", with ", absl::StrJoin(carried, ", "));
  }
  out << options.output << ": " << written << " points" << contents;
  if (options.outliers.has_value()) {
    out << " (" << found << " outliers of " << read
        << (options.outliers_as_noise ? " classified as noise)" : " removed)");
  }
  // Copied LAS records keep the file's own coordinates: no origin was taken or put back.
  out << merge_note << LeftOutNote(left_out)
      << (las_records_kept ? std::string() : OriginNote(cloud.origin)) << not_joined << "\n";
  if (!dropped.empty()) {
    std::vector<std::string> holds = {"positions"};
    if (kept.colors) holds.push_back("colours");
    if (kept.normals) holds.push_back("normals");
    if (kept.weights) holds.push_back("weights");
    const std::string last = holds.back();
    holds.pop_back();
    // The format's name: its extension, "LAS" for .las.
    const std::string extension = std::filesystem::path(options.output).extension().string();
    const std::string format = absl::AsciiStrToUpper(extension.substr(1));
    out << "note: " << format << " keeps " << absl::StrJoin(holds, ", ") << " and " << last
        << "; the " << absl::StrJoin(dropped, " and ") << " were left out\n";
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status RunConvert(const ConvertOptions& options, std::ostream& out) {
  if (options.output.empty()) return absl::InvalidArgumentError("-o OUTPUT is required");
  const bool mesh_output = IsSupportedMeshExtension(options.output);
  if (!mesh_output && !IsWritablePointCloudExtension(options.output)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "OUTPUT '", options.output, "': unsupported format; use one of ", kMeshExtensions,
        " for meshes, or ", kWritablePointCloudExtensions, " for points"));
  }
  if (options.inputs.empty()) return absl::InvalidArgumentError("INPUT is required");
  const std::string& input = options.inputs.front();
  if (options.inputs.size() > 1) {
    if (!IsWritablePointCloudExtension(options.output)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "several INPUTs are written as one point cloud; OUTPUT '", options.output,
          "' must be a point cloud format (", kWritablePointCloudExtensions, ")"));
    }
    return ConvertPoints(options, out);
  }
  if (IsBuiltin(input) && !mesh_output) {
    return absl::InvalidArgumentError(absl::StrCat(
        input, " is a surface, not points: convert writes its tessellation to a mesh "
        "format (", kMeshExtensions, ")"));
  }
  if (!IsBuiltin(input) && (!mesh_output || !IsSupportedMeshExtension(input))) {
    return ConvertPoints(options, out);
  }
  NM_ASSIGN_OR_RETURN(const TriangleMesh mesh, LoadMesh(input, "INPUT"));
  if (mesh.faces.empty() && IsWritablePointCloudExtension(options.output)) {
    return ConvertPoints(options, out);  // Read again as points: normals and weights too.
  }
  if (options.outliers.has_value()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--remove_outliers removes points from point clouds; INPUT '", input,
        "' is a mesh of ", mesh.faces.size(), " faces"));
  }
  NM_RETURN_IF_ERROR(WriteMesh(mesh, options.output, options.writing));
  out << options.output << ": " << mesh.positions.size() << " vertices, " << mesh.faces.size()
      << " faces" << (mesh.colors.empty() ? "" : ", with colours") << OriginNote(mesh.origin)
      << "\n"
      << StlOriginNote(options.output, mesh.origin);
  return absl::OkStatus();
}

}  // namespace neuralmesh::client
