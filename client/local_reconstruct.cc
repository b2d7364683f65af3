// RunLocalReconstruct (declared in client/local_commands.h).
#include <filesystem>
#include <memory>
#include <optional>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "client/inputs.h"
#include "client/interrupt.h"
#include "client/local_commands.h"
#include "client/lod_plan.h"
#include "client/lod_table.h"
#include "client/progress_bar.h"
#include "core/analysis/mesh_report.h"
#include "core/io/mesh_io.h"
#include "core/learning/growth_watch.h"
#include "core/learning/learner.h"
#include "core/status_macros.h"

namespace neuralmesh::client {
namespace {

// Fails before any learning when OUTPUT could not be written afterwards.
absl::Status CheckOutputPath(const std::string& output) {
  if (output.empty()) return absl::InvalidArgumentError("-o OUTPUT is required");
  if (!IsSupportedMeshExtension(output)) {
    return absl::InvalidArgumentError(absl::StrCat("OUTPUT '", output,
                                                   "': unsupported mesh format; use one of ",
                                                   kMeshExtensions));
  }
  const std::filesystem::path parent = std::filesystem::path(output).parent_path();
  std::error_code error;
  if (!parent.empty() && !std::filesystem::is_directory(parent, error)) {
    return absl::NotFoundError(
        absl::StrCat("the directory of OUTPUT, '", parent.string(), "', does not exist"));
  }
  if (std::filesystem::is_directory(output, error)) {
    return absl::InvalidArgumentError(
        absl::StrCat("OUTPUT '", output, "' is a directory; name a file in it"));
  }
  return absl::OkStatus();
}

const char* StopReasonText(StopReason reason) {
  switch (reason) {
    case StopReason::kTargetReached:
      return "target reached";
    case StopReason::kStepBudget:
      return "--max_steps reached";
    case StopReason::kTimeBudget:
      return "--time_budget used up";
    case StopReason::kCancelled:
      return "cancelled";
    case StopReason::kObserver:
      return "interrupted";
  }
  return "stopped";
}

}  // namespace

absl::Status RunLocalReconstruct(const LocalReconstructOptions& options, std::ostream& out,
                                 std::ostream& err) {
  NM_RETURN_IF_ERROR(options.learner.Validate());
  NM_RETURN_IF_ERROR(options.writing.draco.Validate());
  if (options.time_budget <= absl::ZeroDuration()) {
    return absl::InvalidArgumentError(absl::StrCat("--time_budget must be positive, not ",
                                                   absl::FormatDuration(options.time_budget)));
  }
  NM_RETURN_IF_ERROR(CheckOutputPath(options.output));
  std::optional<TriangleMesh> start_mesh;
  if (!options.start_mesh.empty()) {
    NM_ASSIGN_OR_RETURN(start_mesh, ReadStartMesh(options.start_mesh));
  }
  NM_ASSIGN_OR_RETURN(const std::vector<size_t> targets,
                      LodTargets(options.lods, options.vertices,
                                 start_mesh.has_value() ? start_mesh->positions.size() : 0));
  NM_ASSIGN_OR_RETURN(const TargetSpace target,
                      options.off_core
                          ? LoadOffCoreTargetSpace(options.inputs, options.sampling,
                                                   options.outliers.has_value(), options.selection)
                          : LoadTargetSpace(options.inputs, options.sampling, options.outliers,
                                            options.colors, options.selection));
  if (start_mesh.has_value()) {
    NM_RETURN_IF_ERROR(MoveStartMesh(target.origin, options.start_mesh, &*start_mesh));
  }
  absl::StatusOr<std::unique_ptr<Learner>> created =
      start_mesh.has_value()
          ? Learner::CreateFrom(options.learner, target.sampler.get(), *start_mesh)
          : Learner::Create(options.learner, target.sampler.get());
  if (start_mesh.has_value() && absl::IsInvalidArgument(created.status())) {
    return absl::Status(created.status().code(),
                        absl::StrCat("--start_mesh '", options.start_mesh,
                                     "': ", created.status().message()));
  }
  NM_RETURN_IF_ERROR(created.status());
  std::unique_ptr<Learner> learner = *std::move(created);
  out << "learning " << target.description << " to " << options.vertices << " vertices";
  if (start_mesh.has_value()) {
    out << " from " << options.start_mesh << " (" << start_mesh->positions.size() << " vertices)";
  }
  out << " (seed " << options.learner.seed << ")\n";
  out << StlOriginNote(options.output, target.origin);

  // Ctrl-C stops learning at a consistent state; the mesh so far is still written.
  InterruptScope interrupt;
  ProgressBar bar(err, options.progress, "learning", "vertices");
  const absl::Time start = absl::Now();
  const size_t final_vertices = targets.back();
  bool header_printed = false;
  StopReason reason = StopReason::kTargetReached;
  // A run whose mesh stops growing (too few points, all in one place) ends instead of spinning.
  GrowthWatch growth(LongestSplitInterval(options.learner), learner->num_vertices(), 0);
  absl::Status stalled;
  absl::Status source;  // Sampler::CheckSource's last answer.
  for (size_t i = 0; i < targets.size(); ++i) {
    StopCriteria stop;
    stop.target_vertices = targets[i];
    // A budget used up exactly at a milestone still ends with OUTPUT written below.
    const uint64_t steps_done = learner->progress().basic_steps;
    const absl::Duration time_left = options.time_budget - (absl::Now() - start);
    if (options.max_steps > 0 && steps_done >= options.max_steps) {
      reason = StopReason::kStepBudget;
    } else if (time_left <= absl::ZeroDuration()) {
      reason = StopReason::kTimeBudget;
    } else {
      if (options.max_steps > 0) stop.max_basic_steps = options.max_steps - steps_done;
      stop.time_budget = time_left;
      stop.observer = [&](const LearnerProgress& p) {
        bar.Update(p.vertices, final_vertices, absl::StrFormat("%d basic steps", p.basic_steps));
        if (InterruptScope::interrupted()) return false;
        source = target.sampler->CheckSource();
        if (!source.ok()) return false;
        stalled = growth.Check(p.vertices, p.basic_steps);
        return stalled.ok();
      };
      NM_ASSIGN_OR_RETURN(reason, learner->Run(stop));
    }
    if (!source.ok()) {  // The mesh has learned points that are not the input's.
      bar.Clear();
      return absl::Status(source.code(), absl::StrCat(source.message(), "; learning stopped at ",
                                                      learner->num_vertices(), " vertices and ",
                                                      options.output, " was not written"));
    }
    const bool last = i + 1 == targets.size() || reason != StopReason::kTargetReached;

    TriangleMesh mesh = learner->Snapshot();
    mesh.origin = target.origin;
    if (target.colors != nullptr) target.colors->Paint(&mesh);
    LodFigures figures;
    figures.kind = reason != StopReason::kTargetReached ? "stopped" : last ? "final" : "lod";
    figures.path = last ? options.output : LodPath(options.output, targets[i]);
    NM_RETURN_IF_ERROR(WriteMesh(mesh, figures.path, options.writing));
    const MeshReport report = ComputeMeshReport(mesh);
    figures.vertices = mesh.positions.size();
    figures.faces = mesh.faces.size();
    figures.valence6_percent = report.valence6_share;
    figures.genus = report.genus;
    figures.boundaries = report.boundary_loops;
    figures.basic_steps = learner->progress().basic_steps;
    figures.elapsed = absl::Now() - start;
    bar.Clear();
    if (!header_printed) {
      PrintLodHeader(out);
      header_printed = true;
    }
    PrintLodRow(figures, out);
    if (last) break;
  }
  bar.Finish();

  const LearnerProgress progress = learner->progress();
  const double seconds = absl::ToDoubleSeconds(absl::Now() - start);
  out << absl::StrFormat(
      "%s: %d vertices, %d faces, %d basic steps (%d splits, %d collapses) in %.2fs "
      "(%.0f steps/s); wrote %s\n",
      stalled.ok() ? StopReasonText(reason) : "stalled", progress.vertices, progress.faces,
      progress.basic_steps, progress.splits, progress.collapses, seconds,
      seconds > 0 ? static_cast<double>(progress.basic_steps) / seconds : 0.0, options.output);
  if (!stalled.ok()) {
    return absl::Status(
        stalled.code(),
        absl::StrCat(stalled.message(), "; the mesh learned so far is in ", options.output));
  }
  if (reason == StopReason::kObserver) {
    return absl::CancelledError(
        absl::StrCat("interrupted; the mesh learned so far is in ", options.output));
  }
  return absl::OkStatus();
}

}  // namespace neuralmesh::client
