// SessionManager::StartRestore: the sessions of a state directory are restored on a thread of
// their own while the manager answers. A session still to be restored answers UNAVAILABLE
// (a client tries again), the list waits for all of them, new sessions can be created
// meanwhile and come after the stored ones, and a shutdown stops the restore and leaves the
// rest on disk for the next start.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/synchronization/notification.h"
#include "server/session_manager.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::server {
namespace {

using ::neuralmesh::server::testing::SpherePoints;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

SessionConfig SmallConfig() {
  SessionConfig config;
  config.target_vertices = 100;
  return config;
}

std::vector<std::string> ListedIds(const SessionManager& manager) {
  const std::vector<std::shared_ptr<Session>> sessions = manager.List().value();
  std::vector<std::string> ids;
  for (const auto& session : sessions) ids.push_back(session->id());
  return ids;
}

class SessionManagerRestoreTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = neuralmesh::testing::MakeTempDir("manager_restore"); }
  void TearDown() override {
    pool_.Shutdown();
    encoder_.Shutdown();
  }

  // Sessions with 1,000, 2,000, ... points, owned by "alice", kept in the directory.
  std::vector<std::string> StoreSessions(int count) {
    std::unique_ptr<SessionStore> store = SessionStore::Open(dir_, false).value();
    SessionManager manager(SessionLimits(), &pool_, &encoder_, nullptr, store.get());
    std::vector<std::string> ids;
    for (int i = 0; i < count; ++i) {
      std::shared_ptr<Session> session =
          manager.Create(SmallConfig(), absl::StrCat("stored ", i), "", "alice").value();
      EXPECT_TRUE(session->AddPoints(SpherePoints(1000 * (i + 1), i + 1)).ok());
      ids.push_back(session->id());
    }
    return ids;
  }

  std::string dir_;
  WorkerPool pool_{1, absl::Milliseconds(10)};
  Executor encoder_{1};
};

TEST_F(SessionManagerRestoreTest, SessionsAnswerUnavailableUntilRestoredAndNewOnesComeAfter) {
  const std::vector<std::string> stored = StoreSessions(2);
  std::unique_ptr<SessionStore> store = SessionStore::Open(dir_, false).value();
  SessionLimits limits;
  limits.max_sessions = 3;
  limits.max_sessions_per_client = 2;
  SessionManager manager(limits, &pool_, &encoder_, nullptr, store.get());
  absl::Notification first_restored, release_second;
  manager.StartRestore([&](const std::string& id) {
    if (id == stored[1]) {
      first_restored.Notify();
      release_second.WaitForNotification();
    }
  });
  first_restored.WaitForNotification();

  // The first is back with its points; the second is not yet.
  absl::StatusOr<std::shared_ptr<Session>> first = manager.Get(stored[0]);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ((*first)->points_received(), 1000u);
  const absl::Status second = manager.Get(stored[1]).status();
  EXPECT_TRUE(absl::IsUnavailable(second)) << second;
  EXPECT_THAT(second.message(),
              HasSubstr("is being restored after a restart of the server (1 of 2 sessions done)"));
  EXPECT_TRUE(absl::IsUnavailable(manager.Delete(stored[1])));
  const absl::Status listed = manager.List().status();
  EXPECT_TRUE(absl::IsUnavailable(listed)) << listed;
  EXPECT_THAT(listed.message(), HasSubstr("restoring its sessions after a restart (1 of 2 done)"));
  EXPECT_TRUE(absl::IsNotFound(manager.Get("s-0000000000000000").status()));

  // The session still to be restored counts toward the limits: alice holds 2 of her 2, the
  // server 2 of its 3.
  const absl::Status alice = manager.Create(SmallConfig(), "more", "", "alice").status();
  EXPECT_TRUE(absl::IsResourceExhausted(alice)) << alice;
  absl::StatusOr<std::shared_ptr<Session>> created = manager.Create(SmallConfig(), "new");
  ASSERT_TRUE(created.ok()) << created.status();
  EXPECT_TRUE(absl::IsResourceExhausted(manager.Create(SmallConfig(), "full").status()));

  release_second.Notify();
  const RestoreReport report = manager.WaitForRestore();
  EXPECT_EQ(report.sessions, 2u);
  EXPECT_EQ(report.points, 3000u);
  EXPECT_TRUE(report.problems.empty());
  absl::StatusOr<std::shared_ptr<Session>> restored = manager.Get(stored[1]);
  ASSERT_TRUE(restored.ok()) << restored.status();
  EXPECT_EQ((*restored)->points_received(), 2000u);
  EXPECT_EQ((*restored)->owner(), "alice");
  EXPECT_THAT(ListedIds(manager), ElementsAre(stored[0], stored[1], (*created)->id()));
}

TEST_F(SessionManagerRestoreTest, AShutdownStopsTheRestoreAndTheRestStaysOnDisk) {
  const std::vector<std::string> stored = StoreSessions(2);
  {
    std::unique_ptr<SessionStore> store = SessionStore::Open(dir_, false).value();
    SessionManager manager(SessionLimits(), &pool_, &encoder_, nullptr, store.get());
    absl::Notification reached_second;
    manager.StartRestore([&](const std::string& id) {
      if (id == stored[1]) {
        reached_second.Notify();
        // Held until the shutdown below has begun (it joins this thread).
        while (manager.Get(stored[0]).ok()) absl::SleepFor(absl::Milliseconds(1));
      }
    });
    reached_second.WaitForNotification();
    manager.Shutdown(absl::UnavailableError("the server is shutting down"));
    const RestoreReport report = manager.WaitForRestore();
    EXPECT_EQ(report.sessions, 1u);
  }
  // The next start finds both, points and all.
  std::unique_ptr<SessionStore> store = SessionStore::Open(dir_, false).value();
  SessionManager manager(SessionLimits(), &pool_, &encoder_, nullptr, store.get());
  manager.StartRestore();
  const RestoreReport report = manager.WaitForRestore();
  EXPECT_EQ(report.sessions, 2u);
  EXPECT_EQ(report.points, 3000u);
  EXPECT_THAT(ListedIds(manager), ElementsAre(stored[0], stored[1]));
  for (const std::string& id : stored) {
    EXPECT_EQ(manager.Get(id).value()->ToProto().state(), v1::SESSION_STATE_COLLECTING) << id;
  }
}

TEST_F(SessionManagerRestoreTest, WithoutAStoreThereIsNothingToWaitFor) {
  SessionManager manager(SessionLimits(), &pool_, &encoder_);
  manager.StartRestore();
  const RestoreReport report = manager.WaitForRestore();
  EXPECT_EQ(report.sessions, 0u);
  EXPECT_TRUE(manager.List().ok());
}

}  // namespace
}  // namespace neuralmesh::server
