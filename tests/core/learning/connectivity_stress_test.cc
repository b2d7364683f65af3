// Randomised stress test of Steps 2 and 3: at least 100,000 vertex splits and half-edge
// collapses on closed and bordered meshes, each followed by a full validity check.
#include <vector>

#include "core/learning/half_edge_collapse.h"
#include "core/learning/vertex_split.h"
#include "core/mesh_validation.h"
#include "core/random.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

struct StressCounts {
  int splits = 0;
  int collapses = 0;
};

// Alternates growth and shrinking phases so that the mesh explores many configurations
// (including low vertex counts near the tetrahedron limit).
StressCounts Stress(Mesh& mesh, uint64_t seed, int operations) {
  Random rng(seed);
  StressCounts counts;
  std::vector<Mesh::VertexHandle> live;
  size_t live_count = mesh.n_vertices();
  for (int op = 0; op < operations; ++op) {
    live.clear();
    for (auto v : mesh.vertices()) live.push_back(v);
    const bool grow = ((op / 500) % 2 == 0) ? rng.NextDouble() < 0.7 : rng.NextDouble() < 0.3;
    const Mesh::VertexHandle v = live[rng.NextIndex(live.size())];
    if (grow) {
      if (!SplitVertex(mesh, v).is_valid()) continue;
      ++counts.splits;
      ++live_count;
    } else {
      const auto h = BestCollapse(mesh, v, live_count);
      if (!h.is_valid()) continue;
      mesh.collapse(h);
      ++counts.collapses;
      --live_count;
    }
    // Jitter positions a little so that "longest edge" choices vary.
    mesh.point(v) += Vec3(rng.NextDouble() - 0.5, rng.NextDouble() - 0.5, rng.NextDouble() - 0.5) * 0.01;
    const absl::Status valid = ValidateMesh(mesh);
    if (!valid.ok()) {
      ADD_FAILURE() << "after operation " << op << " (" << (grow ? "split" : "collapse")
                    << " of vertex " << v.idx() << "): " << valid;
      return counts;
    }
    if (mesh.n_vertices() > 3 * live_count + 100) mesh.garbage_collection();
  }
  return counts;
}

TEST(ConnectivityStressTest, HundredThousandOperationsKeepAValidManifold) {
  StressCounts total;
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    Mesh closed = testing::MustToMesh(testing::Icosphere(1));
    const StressCounts c = Stress(closed, seed, 40000);
    total.splits += c.splits;
    total.collapses += c.collapses;
    if (HasFailure()) return;
    Mesh bordered = testing::MustToMesh(testing::GridPatch(6, 6));
    const StressCounts b = Stress(bordered, seed + 100, 40000);
    total.splits += b.splits;
    total.collapses += b.collapses;
    if (HasFailure()) return;
  }
  EXPECT_GE(total.splits + total.collapses, 100000) << "the test must exercise 100k operations";
  EXPECT_GE(total.collapses, 20000) << "collapses must be exercised, not only splits";
  EXPECT_GE(total.splits, 20000);
}

}  // namespace
}  // namespace neuralmesh
