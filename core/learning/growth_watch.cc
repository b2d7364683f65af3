#include "core/learning/growth_watch.h"

#include "absl/strings/str_cat.h"

namespace neuralmesh {

GrowthWatch::GrowthWatch(int c_vs, size_t vertices, uint64_t basic_steps)
    : patience_(kStallSplits * static_cast<uint64_t>(c_vs > 0 ? c_vs : 1)),
      max_vertices_(vertices),
      steps_at_max_(basic_steps) {}

absl::Status GrowthWatch::Check(size_t vertices, uint64_t basic_steps) {
  if (vertices > max_vertices_) {
    max_vertices_ = vertices;
    steps_at_max_ = basic_steps;
    return absl::OkStatus();
  }
  if (basic_steps - steps_at_max_ <= patience_) return absl::OkStatus();
  return absl::FailedPreconditionError(absl::StrCat(
      "learning stalled: the mesh has not grown past ", max_vertices_, " vertices in ",
      basic_steps - steps_at_max_,
      " Basic Steps (Step 3 collapses as many vertices as Step 2 splits); more points, another "
      "seed or a larger c_ec may help"));
}

}  // namespace neuralmesh
