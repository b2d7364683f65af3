#include "core/learning/learner_options.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

absl::Status OutOfRange(const char* name, double value, const char* range) {
  return absl::InvalidArgumentError(
      absl::StrCat(name, " = ", value, " is out of range; it must be in ", range));
}

}  // namespace

absl::string_view InitialMeshName(InitialMesh mesh) {
  switch (mesh) {
    case InitialMesh::kTetrahedron:
      return "tetrahedron";
    case InitialMesh::kDisc:
      return "disc";
  }
  return "unknown";
}

absl::StatusOr<InitialMesh> ParseInitialMesh(absl::string_view name) {
  for (InitialMesh mesh : {InitialMesh::kTetrahedron, InitialMesh::kDisc}) {
    if (name == InitialMeshName(mesh)) return mesh;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("initial_mesh '", name, "' is unknown; use tetrahedron or disc"));
}

absl::Status LearnerOptions::Validate() const {
  if (!(alpha_w > 0 && alpha_w <= 1)) return OutOfRange("alpha_w", alpha_w, "(0, 1]");
  if (!(alpha_l >= 0 && alpha_l <= 1)) return OutOfRange("alpha_l", alpha_l, "[0, 1]");
  if (c_l < 0 || c_l > 100) return OutOfRange("c_l", c_l, "[0, 100]");
  if (c_vs < 1 || c_vs > 1000000) return OutOfRange("c_vs", c_vs, "[1, 1000000]");
  if (!(c_ec > 0 && c_ec <= 1e6)) return OutOfRange("c_ec", c_ec, "(0, 1e6]");
  if (!(alpha_sc > 0 && alpha_sc < 1)) return OutOfRange("alpha_sc", alpha_sc, "(0, 1)");
  if (early_c_vs < 1 || early_c_vs > 1000000) {
    return OutOfRange("early_c_vs", early_c_vs, "[1, 1000000]");
  }
  if (!(early_c_ec > 0 && early_c_ec <= 1e6)) {
    return OutOfRange("early_c_ec", early_c_ec, "(0, 1e6]");
  }
  if (!(alpha_r > 0 && std::isfinite(alpha_r))) return OutOfRange("alpha_r", alpha_r, "(0, inf)");
  if (!(alpha_m > 0 && std::isfinite(alpha_m))) return OutOfRange("alpha_m", alpha_m, "(0, inf)");
  if (sewn_strip_grace_calls < 0 || sewn_strip_grace_calls > 1000) {
    return OutOfRange("sewn_strip_grace_calls", sewn_strip_grace_calls, "[0, 1000]");
  }
  if (min_merged_loop_vertices < 3 || min_merged_loop_vertices > 1000) {
    return OutOfRange("min_merged_loop_vertices", min_merged_loop_vertices, "[3, 1000]");
  }
  if (max_closed_hole_vertices < 3 || max_closed_hole_vertices > 1000) {
    return OutOfRange("max_closed_hole_vertices", max_closed_hole_vertices, "[3, 1000]");
  }
  if (initial_mesh != InitialMesh::kTetrahedron && initial_mesh != InitialMesh::kDisc) {
    return OutOfRange("initial_mesh", static_cast<int>(initial_mesh), "{tetrahedron, disc}");
  }
  if (splits_per_step < 1 || splits_per_step > 1000) {
    return OutOfRange("splits_per_step", splits_per_step, "[1, 1000]");
  }
  return absl::OkStatus();
}

int LongestSplitInterval(const LearnerOptions& options) {
  return options.early_phase_vertices > 0 ? std::max(options.c_vs, options.early_c_vs)
                                          : options.c_vs;
}

}  // namespace neuralmesh
