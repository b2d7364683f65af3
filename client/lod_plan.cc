#include "client/lod_plan.h"

#include <algorithm>
#include <filesystem>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace neuralmesh::client {
namespace {
// The learner starts from a tetrahedron (Section 2).
constexpr size_t kInitialVertices = 4;
}  // namespace

absl::StatusOr<std::vector<size_t>> ParseLodList(absl::string_view text) {
  std::vector<size_t> lods;
  if (absl::StripAsciiWhitespace(text).empty()) return lods;
  for (absl::string_view item : absl::StrSplit(text, ',')) {
    item = absl::StripAsciiWhitespace(item);
    uint64_t value = 0;
    if (!absl::SimpleAtoi(item, &value) || value == 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          "--lod: '", item, "' is not a positive vertex count (expected e.g. 1000,2000)"));
    }
    lods.push_back(static_cast<size_t>(value));
  }
  std::sort(lods.begin(), lods.end());
  lods.erase(std::unique(lods.begin(), lods.end()), lods.end());
  return lods;
}

absl::StatusOr<std::vector<size_t>> LodTargets(const std::vector<size_t>& lods,
                                               size_t final_vertices, size_t start_vertices) {
  const size_t start = start_vertices == 0 ? kInitialVertices : start_vertices;
  const std::string what =
      start_vertices == 0 ? absl::StrCat(kInitialVertices, " vertices (the initial tetrahedron)")
                          : absl::StrCat(start, " vertices (those of --start_mesh)");
  if (final_vertices <= start) {
    return absl::InvalidArgumentError(
        absl::StrCat("--vertices must be more than ", what, ", got ", final_vertices));
  }
  std::vector<size_t> targets;
  for (size_t lod : lods) {
    if (lod <= start) {
      return absl::InvalidArgumentError(
          absl::StrCat("--lod: ", lod, " must be more than ", what));
    }
    if (lod >= final_vertices) {
      return absl::InvalidArgumentError(
          absl::StrCat("--lod: ", lod, " is not below --vertices ", final_vertices));
    }
    targets.push_back(lod);
  }
  targets.push_back(final_vertices);
  return targets;
}

std::string LodPath(const std::string& output, size_t vertices) {
  const std::filesystem::path path(output);
  std::filesystem::path lod = path.parent_path() / path.stem();
  return absl::StrCat(lod.string(), "_lod", vertices, path.extension().string());
}

}  // namespace neuralmesh::client
