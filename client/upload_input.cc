#include "client/upload_input.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/time.h"
#include "client/inputs.h"
#include "core/status_macros.h"

namespace neuralmesh::client {
namespace {

constexpr char kStandardInput[] = "-";  // The INPUT that streams points from standard input.

BoundingBox BoundsOf(const PointCloud& cloud) {
  BoundingBox box;
  for (const Vec3f& p : cloud.positions) box.Extend(Vec3(p[0], p[1], p[2]));
  return box;
}

// Points streamed from standard input (INPUT '-'), sent as they arrive.
absl::StatusOr<UploadInput> StreamUploadInput(const RemoteReconstructOptions& options,
                                              bool outliers_on_server, std::ostream& out) {
  if (options.off_core) {
    return absl::InvalidArgumentError(
        "--off_core reads a file where it lies; standard input ('-') is streamed as it comes");
  }
  if (options.outliers.has_value() && !outliers_on_server) {
    return absl::InvalidArgumentError(
        "--remove_outliers judges every point against its neighbours, so it needs them all "
        "before the upload: with standard input ('-') add --outliers_on_server");
  }
  if (!options.resume_session.empty()) {
    return absl::InvalidArgumentError(
        "--resume uploads the input again from the points the session has taken; standard "
        "input ('-') cannot be read again");
  }
  auto upload = std::make_unique<StreamUpload>(
      OpenPointStream(STDIN_FILENO, "standard input", options.selection.las_classes),
      options.colors.has_value());
  NM_RETURN_IF_ERROR(upload->Start(options.batch_size));
  UploadInput input;
  input.origin = upload->origin();
  input.streamed = true;
  out << "INPUT '-': points streamed from standard input"
      << (upload->has_colors() ? " with their colours" : "") << ", sent every "
      << absl::FormatDuration(StreamUpload::kFlushAfter) << " or " << options.batch_size
      << " points" << OriginNote(input.origin) << "\n";
  input.points = std::move(upload);
  return input;
}

}  // namespace

absl::StatusOr<UploadInput> LoadUploadInput(const RemoteReconstructOptions& options,
                                            bool outliers_on_server, std::ostream& out) {
  if (std::find(options.inputs.begin(), options.inputs.end(), kStandardInput) !=
      options.inputs.end()) {
    if (options.inputs.size() > 1) {
      return absl::InvalidArgumentError(
          "standard input ('-') is streamed alone; several INPUTs are files uploaded as one");
    }
    return StreamUploadInput(options, outliers_on_server, out);
  }
  UploadInput input;
  if (options.off_core) {
    NM_RETURN_IF_ERROR(
        CheckOffCoreInput(options.inputs, options.outliers.has_value() && !outliers_on_server));
    const std::string& path = options.inputs.front();
    const bool colors = options.colors.has_value();
    const auto describe = [&](const auto& file, absl::string_view how) {
      input.origin = file.origin();
      input.bounds = file.bounds();
      input.size = static_cast<uint64_t>(
          std::llround(static_cast<double>(file.records()) * file.kept_share()));
      input.estimated = true;
      const char* color_note = file.has_colors() && colors ? "; with colours" : "";
      out << absl::StrFormat("INPUT '%s': %d records %s (off-core; %.1f%% of them points%s)%s\n",
                             path, file.records(), how, 100 * file.kept_share(), color_note,
                             OriginNote(input.origin));
    };
    if (IsLazFile(path)) {
      NM_ASSIGN_OR_RETURN(MappedLazFile file, OpenOffCoreLazFile(path, options.selection));
      input.laz = std::make_unique<MappedLazFile>(std::move(file));
      input.points = std::make_unique<LazFileUpload>(*input.laz, colors);
      describe(*input.laz,
               absl::StrCat("decoded where they lie, a LAZ chunk at a time (", input.laz->chunks(),
                            input.laz->chunks() == 1 ? " chunk)" : " chunks)"));
    } else {
      NM_ASSIGN_OR_RETURN(MappedPointFile file,
                          OpenOffCoreFile(options.inputs, false, options.selection));
      input.file = std::make_unique<MappedPointFile>(std::move(file));
      input.points = std::make_unique<FileRecordsUpload>(*input.file, colors);
      describe(*input.file, "read where they lie");
    }
    return input;
  }
  PointsLeftOut left_out;
  std::string merge_note;
  NM_ASSIGN_OR_RETURN(PointCloud points, LoadPointsForUpload(options.inputs, options.builtin_points,
                                                             options.learner.seed, &left_out,
                                                             &merge_note, options.selection));
  input.cloud = std::make_unique<PointCloud>(std::move(points));
  PointCloud& cloud = *input.cloud;
  const size_t points_read = cloud.size();
  if (!options.colors) cloud.colors.clear();
  if (options.outliers.has_value() && !outliers_on_server) {
    NM_ASSIGN_OR_RETURN(const size_t removed, RemoveStatisticalOutliers(cloud, *options.outliers));
    out << "outliers removed: " << removed << " of " << points_read << " points\n";
  }
  if (const std::string notes =
          absl::StrCat(merge_note, LeftOutNote(left_out), OriginNote(cloud.origin));
      !notes.empty()) {
    out << "INPUT " << QuotedInputs(options.inputs) << notes << "\n";
  }
  input.points = std::make_unique<CloudUpload>(cloud, CloudUpload::Order::kSpread);
  input.origin = cloud.origin;
  input.bounds = BoundsOf(cloud);
  input.size = cloud.size();
  return input;
}

}  // namespace neuralmesh::client
