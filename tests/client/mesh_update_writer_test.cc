// Tests of client/mesh_update_writer.h on updates built in code (no server).
#include "client/mesh_update_writer.h"

#include <filesystem>
#include <sstream>

#include "absl/strings/match.h"
#include "core/io/draco_codec.h"
#include "core/io/mesh_io.h"
#include "gtest/gtest.h"
#include "tests/client/subprocess.h"
#include "tests/testing/shapes.h"

namespace neuralmesh::client {
namespace {

v1::MeshUpdate MakeUpdate(v1::UpdateKind kind, uint64_t sequence, const TriangleMesh& mesh) {
  v1::MeshUpdate update;
  update.set_session_id("s-1");
  update.set_sequence(sequence);
  update.set_kind(kind);
  update.set_vertex_count(mesh.positions.size());
  update.set_face_count(mesh.faces.size());
  update.mutable_report()->set_valence6_share(75.0);
  update.mutable_report()->set_genus(0);
  update.mutable_learning()->set_basic_steps(1234);
  update.mutable_learning()->set_learning_seconds(1.5);
  absl::StatusOr<std::string> bytes = EncodeMesh(mesh, DracoOptions());
  EXPECT_TRUE(bytes.ok()) << bytes.status();
  update.set_draco_mesh(*bytes);
  return update;
}

TEST(MeshUpdateWriterTest, SavesMilestonesAndTheFinalMeshButOnlyPrintsRefreshes) {
  const std::string dir = testing::MakeTempDir("update_writer") + "/nested/out";
  std::ostringstream out;
  MeshUpdateWriter writer({dir, "ball", {".ply", ".glb"}}, out);
  const TriangleMesh coarse = testing::Icosphere(1);  // 42 vertices.
  const TriangleMesh fine = testing::Icosphere(2);    // 162 vertices.

  ASSERT_TRUE(writer.Write(MakeUpdate(v1::UPDATE_KIND_MILESTONE, 1, coarse)).ok());
  ASSERT_TRUE(writer.Write(MakeUpdate(v1::UPDATE_KIND_REFRESH, 2, fine)).ok());
  EXPECT_FALSE(writer.final_received());
  ASSERT_TRUE(writer.Write(MakeUpdate(v1::UPDATE_KIND_FINAL, 3, fine)).ok());
  EXPECT_TRUE(writer.final_received());

  EXPECT_TRUE(std::filesystem::exists(dir + "/ball_lod42.drc"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/ball_lod42.ply"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/ball_lod162.drc")) << "a refresh was saved";
  EXPECT_TRUE(std::filesystem::exists(dir + "/ball.drc"));
  absl::StatusOr<TriangleMesh> ply = ReadMesh(dir + "/ball.ply");
  ASSERT_TRUE(ply.ok()) << ply.status();
  EXPECT_EQ(ply->faces.size(), fine.faces.size());
  EXPECT_TRUE(std::filesystem::exists(dir + "/ball_lod42.glb"));
  absl::StatusOr<TriangleMesh> glb = ReadMesh(dir + "/ball.glb");
  ASSERT_TRUE(glb.ok()) << glb.status();
  EXPECT_EQ(glb->positions, ply->positions) << "both decoded from the same Draco bytes";
  EXPECT_EQ(glb->faces, ply->faces);

  ASSERT_EQ(writer.saved().size(), 2u);
  EXPECT_EQ(writer.saved()[0].kind, "lod");
  EXPECT_EQ(writer.saved()[1].kind, "final");
  const std::string table = out.str();
  EXPECT_TRUE(absl::StrContains(table, "refresh")) << table;
  EXPECT_TRUE(absl::StrContains(table, "75.0%")) << table;
  EXPECT_TRUE(absl::StrContains(table, "1234")) << table;
  std::filesystem::remove_all(std::filesystem::path(dir).parent_path().parent_path());
}

TEST(MeshUpdateWriterTest, ACorruptMeshFailsWhenItMustBecomePly) {
  const std::string dir = testing::MakeTempDir("update_writer_corrupt");
  std::ostringstream out;
  MeshUpdateWriter writer({dir, "bad", {".ply"}}, out);
  v1::MeshUpdate update = MakeUpdate(v1::UPDATE_KIND_FINAL, 1, testing::Icosphere(1));
  update.set_draco_mesh("not draco");
  EXPECT_TRUE(absl::IsInvalidArgument(writer.Write(update)));
  EXPECT_FALSE(writer.final_received());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace neuralmesh::client
