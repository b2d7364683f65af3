// server/session_store.h: one server per state directory, sessions created, listed, changed
// and removed, and what the directory holds that is not a session.
#include "server/session_store.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "neuralmesh/storage/v1/learner_checkpoint.pb.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::server {
namespace {

storage::v1::StoredSession NewSession(const std::string& id, int64_t create_time_us) {
  storage::v1::StoredSession stored;
  stored.set_session_id(id);
  stored.set_name(absl::StrCat("name of ", id));
  stored.set_owner("alice");
  stored.mutable_config()->set_target_vertices(1234);
  stored.set_create_time_us(create_time_us);
  stored.set_state(v1::SESSION_STATE_COLLECTING);
  return stored;
}

TEST(SessionStoreTest, OneServerAtATimeUsesADirectory) {
  const std::string dir = neuralmesh::testing::MakeTempDir("locked") + "/state";
  absl::StatusOr<std::unique_ptr<SessionStore>> first = SessionStore::Open(dir, false);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_TRUE(std::filesystem::is_directory(dir + "/sessions"));
  EXPECT_EQ(std::filesystem::status(dir + "/sessions").permissions(),
            std::filesystem::perms::owner_all)
      << "the clients' points are the server user's alone";
  absl::StatusOr<std::unique_ptr<SessionStore>> second = SessionStore::Open(dir, false);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(absl::StrContains(second.status().message(), "in use by another neuralmesh-server"))
      << second.status();
  first->reset();
  EXPECT_TRUE(SessionStore::Open(dir, false).ok());
}

TEST(SessionStoreTest, ADirectoryThatCannotBeMadeIsAnError) {
  const std::string file = neuralmesh::testing::MakeTempDir("notdir") + "/file";
  std::ofstream(file) << "x";
  absl::StatusOr<std::unique_ptr<SessionStore>> store = SessionStore::Open(file, false);
  EXPECT_FALSE(store.ok());
  EXPECT_TRUE(absl::StrContains(store.status().message(), file)) << store.status();
}

TEST(SessionStoreTest, SessionsAreListedOldestFirstWithTheirStateAndMesh) {
  const std::string dir = neuralmesh::testing::MakeTempDir("listed");
  absl::StatusOr<std::unique_ptr<SessionStore>> store = SessionStore::Open(dir, true);
  ASSERT_TRUE(store.ok()) << store.status();
  absl::StatusOr<std::unique_ptr<SessionRecord>> later =
      (*store)->Create(NewSession("s-later", 2000));
  absl::StatusOr<std::unique_ptr<SessionRecord>> earlier =
      (*store)->Create(NewSession("s-earlier", 1000));
  ASSERT_TRUE(later.ok() && earlier.ok());
  EXPECT_EQ((*store)->Create(NewSession("s-later", 3000)).status().code(),
            absl::StatusCode::kAlreadyExists);

  ASSERT_TRUE((*earlier)->SetState(v1::SESSION_STATE_CANCELLED, "enough").ok());
  v1::MeshUpdate mesh;
  mesh.set_session_id("s-earlier");
  mesh.set_sequence(7);
  mesh.set_draco_mesh("bytes");
  ASSERT_TRUE((*earlier)->WriteLatestMesh(mesh, /*durable=*/true).ok());
  PointCloud batch;
  batch.positions = {Vec3f(1, 2, 3)};
  ASSERT_TRUE((*later)->AppendBatch(batch).ok());

  std::vector<std::string> problems;
  const std::vector<StoredSessionFiles> listed = (*store)->List(&problems);
  EXPECT_TRUE(problems.empty());
  ASSERT_EQ(listed.size(), 2u);
  EXPECT_EQ(listed[0].stored.session_id(), "s-earlier");
  EXPECT_EQ(listed[0].stored.state(), v1::SESSION_STATE_CANCELLED);
  EXPECT_EQ(listed[0].stored.error(), "enough");
  EXPECT_EQ(listed[0].stored.owner(), "alice");
  EXPECT_EQ(listed[0].stored.config().target_vertices(), 1234u);
  ASSERT_TRUE(listed[0].latest.has_value());
  EXPECT_EQ(listed[0].latest->sequence(), 7u);
  EXPECT_EQ(listed[0].latest->draco_mesh(), "bytes");
  EXPECT_EQ(listed[1].stored.session_id(), "s-later");
  EXPECT_FALSE(listed[1].latest.has_value());
  EXPECT_GT(std::filesystem::file_size(listed[1].journal_path), 12u);

  // Removed: gone from the disk, and the record ignores later writes.
  EXPECT_TRUE((*earlier)->Remove().ok());
  EXPECT_FALSE(std::filesystem::exists(dir + "/sessions/s-earlier"));
  EXPECT_TRUE((*earlier)->SetState(v1::SESSION_STATE_FAILED, "late").ok());
  EXPECT_FALSE(std::filesystem::exists(dir + "/sessions/s-earlier"));
  EXPECT_EQ((*store)->List(&problems).size(), 1u);
}

TEST(SessionStoreTest, WhatIsNotASessionIsReportedAndLeft) {
  const std::string dir = neuralmesh::testing::MakeTempDir("strays");
  absl::StatusOr<std::unique_ptr<SessionStore>> store = SessionStore::Open(dir, false);
  ASSERT_TRUE(store.ok());
  ASSERT_TRUE((*store)->Create(NewSession("s-good", 1)).ok());
  std::ofstream(dir + "/sessions/README") << "a stray file";
  std::filesystem::create_directory(dir + "/sessions/s-garbage");
  std::ofstream(dir + "/sessions/s-garbage/session.binpb") << "not a protobuf \xff\xff\xff";
  std::filesystem::create_directory(dir + "/sessions/s-empty");
  // A session whose directory was renamed: its file names another id.
  std::filesystem::create_directory(dir + "/sessions/s-renamed");
  std::filesystem::copy_file(dir + "/sessions/s-good/session.binpb",
                             dir + "/sessions/s-renamed/session.binpb");

  std::vector<std::string> problems;
  const std::vector<StoredSessionFiles> listed = (*store)->List(&problems);
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].stored.session_id(), "s-good");
  ASSERT_EQ(problems.size(), 4u);
  std::string all;
  for (const std::string& problem : problems) absl::StrAppend(&all, problem, "\n");
  EXPECT_TRUE(absl::StrContains(all, "README' is not a session")) << all;
  EXPECT_TRUE(absl::StrContains(all, "s-garbage/session.binpb' is not a stored session")) << all;
  EXPECT_TRUE(absl::StrContains(all, "s-empty/session.binpb")) << all;
  EXPECT_TRUE(absl::StrContains(all, "holds session \"s-good\"")) << all;
  EXPECT_TRUE(std::filesystem::exists(dir + "/sessions/s-garbage/session.binpb"));
}

TEST(SessionStoreTest, ALearnerCheckpointComesBackExactlyOrSaysWhatIsWrong) {
  const std::string dir = neuralmesh::testing::MakeTempDir("checkpoint");
  absl::StatusOr<std::unique_ptr<SessionStore>> store = SessionStore::Open(dir, false);
  ASSERT_TRUE(store.ok()) << store.status();
  absl::StatusOr<std::unique_ptr<SessionRecord>> record = (*store)->Create(NewSession("s-1", 1));
  ASSERT_TRUE(record.ok()) << record.status();
  TriangleMesh mesh;
  mesh.positions = {Vec3f(0.1f, -2.5f, 1e-7f), Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 0, 1)};
  mesh.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  v1::LearningState learning;
  learning.set_basic_steps(123456);
  learning.set_learning_seconds(0.75);
  ASSERT_TRUE((*record)->WriteCheckpoint(mesh, learning).ok());

  std::vector<std::string> problems;
  std::vector<StoredSessionFiles> listed = (*store)->List(&problems);
  ASSERT_EQ(listed.size(), 1u);
  ASSERT_TRUE(listed[0].checkpoint.has_value()) << listed[0].checkpoint_damage;
  EXPECT_EQ(listed[0].checkpoint->mesh.positions, mesh.positions);
  EXPECT_EQ(listed[0].checkpoint->mesh.faces, mesh.faces);
  EXPECT_EQ(listed[0].checkpoint->learning.SerializeAsString(), learning.SerializeAsString());
  EXPECT_TRUE(listed[0].checkpoint_damage.empty());

  // Its faces cut short by a byte.
  const std::string path = dir + "/sessions/s-1/checkpoint.binpb";
  storage::v1::LearnerCheckpoint stored;
  {
    std::ifstream file(path, std::ios::binary);
    ASSERT_TRUE(stored.ParseFromIstream(&file));
  }
  stored.mutable_mesh()->mutable_faces()->pop_back();
  std::ofstream(path, std::ios::binary | std::ios::trunc) << stored.SerializeAsString();
  listed = (*store)->List(&problems);
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_FALSE(listed[0].checkpoint.has_value());
  EXPECT_TRUE(absl::StrContains(listed[0].checkpoint_damage,
                                "its mesh has 48 bytes of positions and 47 of faces"))
      << listed[0].checkpoint_damage;

  // Another session's.
  stored.set_session_id("s-2");
  stored.mutable_mesh()->mutable_faces()->push_back('\0');
  std::ofstream(path, std::ios::binary | std::ios::trunc) << stored.SerializeAsString();
  listed = (*store)->List(&problems);
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].checkpoint_damage, "it is of session \"s-2\"");
  EXPECT_TRUE(problems.empty()) << "the session itself is fine";

  // None at all: nothing wrong.
  std::filesystem::remove(path);
  listed = (*store)->List(&problems);
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_FALSE(listed[0].checkpoint.has_value());
  EXPECT_TRUE(listed[0].checkpoint_damage.empty());

  // An ended session keeps none, and takes none.
  ASSERT_TRUE((*record)->WriteCheckpoint(mesh, learning).ok());
  EXPECT_TRUE(std::filesystem::exists(path));
  ASSERT_TRUE((*record)->SetState(v1::SESSION_STATE_FINISHED, "").ok());
  EXPECT_FALSE(std::filesystem::exists(path));
  ASSERT_TRUE((*record)->WriteCheckpoint(mesh, learning).ok());
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(SessionStoreTest, ARefreshIsACheckpointOnlyOnceTheIntervalHasPassed) {
  TriangleMesh mesh;
  mesh.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 0, 1)};
  mesh.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  // The basic steps of the stored checkpoint (0: none).
  auto stored_steps = [](const std::string& path) -> uint64_t {
    std::ifstream file(path, std::ios::binary);
    storage::v1::LearnerCheckpoint checkpoint;
    return file && checkpoint.ParseFromIstream(&file) ? checkpoint.learning().basic_steps() : 0;
  };
  auto learning = [](uint64_t steps) {
    v1::LearningState state;
    state.set_basic_steps(steps);
    return state;
  };
  for (const absl::Duration interval : {absl::ZeroDuration(), absl::Milliseconds(200)}) {
    const std::string dir = neuralmesh::testing::MakeTempDir("interval");
    absl::StatusOr<std::unique_ptr<SessionStore>> store = SessionStore::Open(dir, false, interval);
    ASSERT_TRUE(store.ok()) << store.status();
    absl::StatusOr<std::unique_ptr<SessionRecord>> record =
        (*store)->Create(NewSession("s-1", 1));
    ASSERT_TRUE(record.ok()) << record.status();
    const std::string path = dir + "/sessions/s-1/checkpoint.binpb";
    const bool refreshes = interval > absl::ZeroDuration();
    // The first refresh comes after no checkpoint at all.
    ASSERT_TRUE((*record)->WriteCheckpoint(mesh, learning(1), CheckpointKind::kRefresh).ok());
    EXPECT_EQ(stored_steps(path), refreshes ? 1u : 0u) << interval;
    ASSERT_TRUE((*record)->WriteCheckpoint(mesh, learning(2), CheckpointKind::kMilestone).ok());
    EXPECT_EQ(stored_steps(path), 2u) << "every milestone";
    ASSERT_TRUE((*record)->WriteCheckpoint(mesh, learning(3), CheckpointKind::kRefresh).ok());
    EXPECT_EQ(stored_steps(path), 2u) << "a refresh right after a checkpoint";
    absl::SleepFor(absl::Milliseconds(250));
    ASSERT_TRUE((*record)->WriteCheckpoint(mesh, learning(4), CheckpointKind::kRefresh).ok());
    EXPECT_EQ(stored_steps(path), refreshes ? 4u : 2u) << interval;
  }
}

}  // namespace
}  // namespace neuralmesh::server
