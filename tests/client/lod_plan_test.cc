// Tests of client/lod_plan.h.
#include "client/lod_plan.h"

#include <string>
#include <vector>

#include "gtest/gtest.h"

namespace neuralmesh::client {
namespace {

TEST(ParseLodListTest, SortsAndDeduplicates) {
  absl::StatusOr<std::vector<size_t>> lods = ParseLodList("2000, 500,1000,500");
  ASSERT_TRUE(lods.ok()) << lods.status();
  EXPECT_EQ(*lods, (std::vector<size_t>{500, 1000, 2000}));
}

TEST(ParseLodListTest, EmptyMeansNone) {
  absl::StatusOr<std::vector<size_t>> lods = ParseLodList("");
  ASSERT_TRUE(lods.ok()) << lods.status();
  EXPECT_TRUE(lods->empty());
}

TEST(ParseLodListTest, RejectsNonPositiveAndNonNumericEntries) {
  for (const char* text : {"100,abc", "0", "-5", "100,,200", "1e3"}) {
    absl::StatusOr<std::vector<size_t>> lods = ParseLodList(text);
    EXPECT_TRUE(absl::IsInvalidArgument(lods.status())) << "'" << text << "' was accepted";
  }
}

TEST(LodTargetsTest, AppendsTheFinalCount) {
  absl::StatusOr<std::vector<size_t>> targets = LodTargets({100, 250}, 500);
  ASSERT_TRUE(targets.ok()) << targets.status();
  EXPECT_EQ(*targets, (std::vector<size_t>{100, 250, 500}));
}

TEST(LodTargetsTest, RejectsLodsAtOrAboveTheFinalCountAndTinyTargets) {
  EXPECT_TRUE(absl::IsInvalidArgument(LodTargets({500}, 500).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(LodTargets({600}, 500).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(LodTargets({4}, 500).status()))
      << "4 vertices is the initial tetrahedron";
  EXPECT_TRUE(absl::IsInvalidArgument(LodTargets({}, 4).status()));
}

TEST(LodTargetsTest, EveryTargetExceedsTheStartMesh) {
  absl::StatusOr<std::vector<size_t>> targets = LodTargets({300, 400}, 500, 250);
  ASSERT_TRUE(targets.ok()) << targets.status();
  EXPECT_EQ(*targets, (std::vector<size_t>{300, 400, 500}));
  const absl::Status low = LodTargets({200}, 500, 250).status();
  EXPECT_TRUE(absl::IsInvalidArgument(low));
  EXPECT_NE(low.message().find("more than 250 vertices (those of --start_mesh)"), std::string::npos)
      << low;
  EXPECT_TRUE(absl::IsInvalidArgument(LodTargets({}, 250, 250).status()));
}

TEST(LodPathTest, InsertsTheVertexCountBeforeTheExtension) {
  EXPECT_EQ(LodPath("out/mesh.ply", 1000), "out/mesh_lod1000.ply");
  EXPECT_EQ(LodPath("mesh.drc", 50), "mesh_lod50.drc");
  EXPECT_EQ(LodPath("/a.b/mesh.v2.obj", 7), "/a.b/mesh.v2_lod7.obj");
}

}  // namespace
}  // namespace neuralmesh::client
