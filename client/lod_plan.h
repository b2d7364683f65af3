// Levels of detail of one reconstruction: which vertex counts to stop at and where each
// level's file goes.
#ifndef NEURALMESH_CLIENT_LOD_PLAN_H_
#define NEURALMESH_CLIENT_LOD_PLAN_H_

#include <cstddef>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::client {

// Parses a comma-separated list of vertex counts ("1000,2000,4000"; empty: none).
// Returns them sorted without duplicates, or INVALID_ARGUMENT naming the bad entry.
absl::StatusOr<std::vector<size_t>> ParseLodList(absl::string_view text);

// The successive vertex targets of a run from a mesh of `start_vertices` vertices (0: the 4
// of the initial tetrahedron): every LOD below `final_vertices`, then `final_vertices`.
// Returns INVALID_ARGUMENT when a LOD is not below `final_vertices` or when a target does not
// exceed the start.
absl::StatusOr<std::vector<size_t>> LodTargets(const std::vector<size_t>& lods,
                                               size_t final_vertices, size_t start_vertices = 0);

// The file of the LOD with `vertices` vertices next to `output`: the stem of `output`
// followed by "_lod<vertices>" and its extension ("out/m.ply" -> "out/m_lod1000.ply").
std::string LodPath(const std::string& output, size_t vertices);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_LOD_PLAN_H_
