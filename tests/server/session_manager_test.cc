#include "server/session_manager.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/synchronization/notification.h"
#include "absl/time/clock.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::server {
namespace {

SessionConfig SmallConfig() {
  SessionConfig config;
  config.target_vertices = 100;
  return config;
}

class SessionManagerTest : public ::testing::Test {
 protected:
  void TearDown() override {
    pool_.Shutdown();
    encoder_.Shutdown();
  }
  WorkerPool pool_{1, absl::Milliseconds(10)};
  Executor encoder_{1};
};

// Between the manager's shutdown and the server's, calls on sessions that existed get the
// UNAVAILABLE the API promises at shutdown, not a NOT_FOUND that says they never did.
TEST_F(SessionManagerTest, AfterShutdownCallsAreUnavailableNotNotFound) {
  SessionManager manager(SessionLimits(), &pool_, &encoder_);
  absl::StatusOr<std::shared_ptr<Session>> session = manager.Create(SmallConfig(), "s");
  ASSERT_TRUE(session.ok()) << session.status();
  const std::string id = (*session)->id();
  manager.Shutdown(absl::UnavailableError("the server is shutting down"));
  EXPECT_TRUE(absl::IsUnavailable(manager.Get(id).status())) << manager.Get(id).status();
  EXPECT_TRUE(absl::IsUnavailable(manager.Delete(id)));
  EXPECT_TRUE(absl::IsUnavailable(manager.List().status()));
  EXPECT_TRUE(absl::IsUnavailable(manager.Create(SmallConfig(), "late").status()));
}

// An idle timeout the reaper thread never reaches in a test: the tests call ReapIdle with
// times of their own.
SessionLimits HourLimits() {
  SessionLimits limits;
  limits.idle_timeout = absl::Hours(1);
  return limits;
}

std::vector<std::string> ListedIds(const SessionManager& manager) {
  const std::vector<std::shared_ptr<Session>> sessions = manager.List().value();
  std::vector<std::string> ids;
  for (const auto& session : sessions) ids.push_back(session->id());
  return ids;
}

TEST_F(SessionManagerTest, ReapIdleDeletesSessionsIdleForTheTimeout) {
  SessionManager manager(HourLimits(), &pool_, &encoder_);
  std::shared_ptr<Session> a = manager.Create(SmallConfig(), "a").value();
  std::shared_ptr<Session> b = manager.Create(SmallConfig(), "b").value();
  EXPECT_EQ(manager.ReapIdle(absl::Now() + absl::Minutes(59)), 0u) << "idle for less than an hour";
  EXPECT_THAT(ListedIds(manager), ::testing::ElementsAre(a->id(), b->id()));

  EXPECT_EQ(manager.ReapIdle(absl::Now() + absl::Hours(2)), 2u);
  EXPECT_THAT(ListedIds(manager), ::testing::IsEmpty());
  EXPECT_TRUE(absl::IsNotFound(manager.Get(a->id()).status())) << manager.Get(a->id()).status();
  ASSERT_TRUE(a->updates().close_status().has_value()) << "a reaped session's watchers end";
  EXPECT_TRUE(absl::IsNotFound(*a->updates().close_status())) << *a->updates().close_status();
  EXPECT_THAT(a->updates().close_status()->message(), ::testing::HasSubstr("was deleted"));
}

TEST_F(SessionManagerTest, TheEventLogRecordsCreationsAndDeletions) {
  testing::CapturedEvents events;
  SessionManager manager(HourLimits(), &pool_, &encoder_,
                         std::make_shared<EventLog>(events.Sink()));
  SessionConfig disc = SmallConfig();
  disc.learner.initial_mesh = InitialMesh::kDisc;
  disc.outlier_removal = OutlierOptions();
  std::shared_ptr<Session> a = manager.Create(SmallConfig(), "a", "ipv4:10.0.0.7:41234").value();
  std::shared_ptr<Session> b = manager.Create(disc, "say \"hi\"\n").value();
  ASSERT_TRUE(manager.Delete(a->id()).ok());
  EXPECT_EQ(manager.ReapIdle(absl::Now() + absl::Hours(2)), 1u);
  EXPECT_FALSE(manager.Create(SmallConfig(), std::string(300, 'x')).ok());
  const std::vector<std::string> lines = events.lines();
  ASSERT_EQ(lines.size(), 4u) << "a refused creation is no event";
  EXPECT_THAT(lines[0], ::testing::EndsWith(absl::StrCat(
                            "session ", a->id(),
                            " created by ipv4:10.0.0.7:41234: \"a\", target 100 vertices")));
  EXPECT_THAT(lines[1], ::testing::EndsWith(absl::StrCat(
                            "session ", b->id(), " created: \"say \\\"hi\\\"\\n\", target 100 ",
                            "vertices, disc start, outlier removal")))
      << "the name is escaped";
  EXPECT_THAT(lines[2], ::testing::EndsWith(absl::StrCat("session ", a->id(), " deleted")));
  EXPECT_THAT(lines[3],
              ::testing::EndsWith(absl::StrCat("session ", b->id(), " deleted: idle for 1h")));
}

TEST_F(SessionManagerTest, OpenStreamsKeepASessionFromIdlingOut) {
  SessionManager manager(HourLimits(), &pool_, &encoder_);
  std::shared_ptr<Session> watched = manager.Create(SmallConfig(), "watched").value();
  std::shared_ptr<Session> unwatched = manager.Create(SmallConfig(), "unwatched").value();
  watched->AddStream();
  EXPECT_EQ(manager.ReapIdle(absl::Now() + absl::Hours(2)), 1u);
  EXPECT_THAT(ListedIds(manager), ::testing::ElementsAre(watched->id()));
  EXPECT_FALSE(watched->updates().close_status().has_value());

  watched->RemoveStream();
  EXPECT_EQ(manager.ReapIdle(absl::Now() + absl::Minutes(30)), 0u)
      << "closing the stream is activity: the timeout runs from then";
  EXPECT_EQ(manager.ReapIdle(absl::Now() + absl::Hours(2)), 1u);
  EXPECT_THAT(ListedIds(manager), ::testing::IsEmpty());
}

// ReapIdle lists the idle sessions, then deletes each one after looking again under the lock: a
// session used in between (here: Get, which every RPC on a session calls) stays.
TEST_F(SessionManagerTest, ASessionUsedAfterTheReaperListedItStays) {
  SessionManager manager(HourLimits(), &pool_, &encoder_);
  std::shared_ptr<Session> session = manager.Create(SmallConfig(), "s").value();
  const absl::Time listed_at = absl::Now() + absl::Hours(1);
  ASSERT_TRUE(session->IdleSince(listed_at, absl::Hours(1))) << "the reaper would list it";
  absl::SleepFor(absl::Milliseconds(2));
  ASSERT_TRUE(manager.Get(session->id()).ok());

  const absl::Status status = manager.DeleteIfIdle(session->id(), listed_at);
  EXPECT_TRUE(absl::IsFailedPrecondition(status)) << status;
  EXPECT_THAT(ListedIds(manager), ::testing::ElementsAre(session->id()));
  EXPECT_FALSE(session->updates().close_status().has_value()) << "its watchers go on";

  EXPECT_TRUE(manager.DeleteIfIdle(session->id(), absl::Now() + absl::Hours(2)).ok());
  EXPECT_THAT(ListedIds(manager), ::testing::IsEmpty());
  EXPECT_TRUE(absl::IsNotFound(manager.DeleteIfIdle(session->id(), absl::Now())));
}

// The reaper thread, with a timeout of 50 ms (it looks every 12.5 ms): an idle session goes
// within seconds; one with an open stream stays until the stream closes.
TEST_F(SessionManagerTest, TheReaperThreadDeletesIdleSessions) {
  SessionLimits limits;
  limits.idle_timeout = absl::Milliseconds(50);
  SessionManager manager(limits, &pool_, &encoder_);
  std::shared_ptr<Session> watched = manager.Create(SmallConfig(), "watched").value();
  watched->AddStream();
  std::shared_ptr<Session> idle = manager.Create(SmallConfig(), "idle").value();
  auto wait_until_listed_only = [&](std::vector<std::string> ids) {
    const absl::Time give_up = absl::Now() + absl::Seconds(20);
    while (ListedIds(manager) != ids && absl::Now() < give_up) {
      absl::SleepFor(absl::Milliseconds(5));
    }
    return ListedIds(manager);
  };
  EXPECT_THAT(wait_until_listed_only({watched->id()}), ::testing::ElementsAre(watched->id()));
  ASSERT_TRUE(idle->updates().close_status().has_value());
  EXPECT_TRUE(absl::IsNotFound(*idle->updates().close_status()));

  absl::SleepFor(absl::Milliseconds(200));  // 4 timeouts, 16 looks of the reaper.
  EXPECT_THAT(ListedIds(manager), ::testing::ElementsAre(watched->id()));
  watched->RemoveStream();
  EXPECT_THAT(wait_until_listed_only({}), ::testing::IsEmpty());
}

// StartRestore: the sessions of a state directory are restored on a thread of their own
// while the manager answers. A session still to be restored answers UNAVAILABLE (a client
// tries again), the list waits for all of them, new sessions can be created meanwhile and come
// after the stored ones, and a shutdown stops the restore and leaves the rest on disk for the
// next start.
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
      EXPECT_TRUE(session->AddPoints(testing::SpherePoints(1000 * (i + 1), i + 1)).ok());
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
              ::testing::HasSubstr(
                  "is being restored after a restart of the server (1 of 2 sessions done)"));
  EXPECT_TRUE(absl::IsUnavailable(manager.Delete(stored[1])));
  const absl::Status listed = manager.List().status();
  EXPECT_TRUE(absl::IsUnavailable(listed)) << listed;
  EXPECT_THAT(listed.message(),
              ::testing::HasSubstr("restoring its sessions after a restart (1 of 2 done)"));
  EXPECT_TRUE(absl::IsNotFound(manager.Get("s-0000000000000000").status()));
  // The metrics see what List does not yet: the session back, and one still to come.
  const SessionManager::Census census = manager.TakeCensus();
  ASSERT_EQ(census.sessions.size(), 1u);
  EXPECT_EQ(census.sessions[0]->id(), stored[0]);
  EXPECT_EQ(census.to_restore, 1u);

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
  EXPECT_THAT(ListedIds(manager), ::testing::ElementsAre(stored[0], stored[1], (*created)->id()));
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
  EXPECT_THAT(ListedIds(manager), ::testing::ElementsAre(stored[0], stored[1]));
  for (const std::string& id : stored) {  // Taking points still, not ended by the shutdown.
    const v1::SessionState state = manager.Get(id).value()->ToProto().state();
    EXPECT_TRUE(state == v1::SESSION_STATE_COLLECTING || state == v1::SESSION_STATE_LEARNING)
        << id << ": " << v1::SessionState_Name(state);
  }
}

TEST_F(SessionManagerRestoreTest, AHandedOverSessionKeepsItsNewOwnerAfterARestart) {
  const std::vector<std::string> stored = StoreSessions(2);
  testing::CapturedEvents captured;
  {
    std::unique_ptr<SessionStore> store = SessionStore::Open(dir_, false).value();
    auto log = std::make_shared<EventLog>(captured.Sink());
    SessionLimits limits;
    limits.max_sessions_per_client = 2;
    SessionManager manager(limits, &pool_, &encoder_, log, store.get());
    manager.StartRestore();
    manager.WaitForRestore();
    absl::StatusOr<std::shared_ptr<Session>> handed =
        manager.Transfer(stored[1], "bob", "client ops at ipv4:127.0.0.1:1");
    ASSERT_TRUE(handed.ok()) << handed.status();
    EXPECT_EQ((*handed)->owner(), "bob");
    EXPECT_EQ((*handed)->ToProto().owner(), "bob");
    EXPECT_EQ((*handed)->points_received(), 2000u) << "its points stay";
    // Handing it to its owner changes nothing and records nothing.
    ASSERT_TRUE(manager.Transfer(stored[1], "bob").ok());
    // The caller's right is checked against the owner of the moment: a client that still
    // thinks the session is alice's cannot take it from bob.
    const absl::Status stale = manager
                                   .Transfer(stored[1], "carol", "", [](const Session& current) {
                                     return current.owner() == "alice"
                                                ? absl::OkStatus()
                                                : absl::PermissionDeniedError("not alice's");
                                   })
                                   .status();
    EXPECT_TRUE(absl::IsPermissionDenied(stale)) << stale;
    EXPECT_EQ(manager.Get(stored[1]).value()->owner(), "bob");
    // Bob may hold two sessions; alice's second would be his third.
    ASSERT_TRUE(manager.Create(SmallConfig(), "bob's own", "", "bob").ok());
    const absl::Status full = manager.Transfer(stored[0], "bob").status();
    EXPECT_TRUE(absl::IsResourceExhausted(full)) << full;
    EXPECT_THAT(full.message(), ::testing::HasSubstr("client bob holds its maximum of 2"));
    EXPECT_EQ(manager.Get(stored[0]).value()->owner(), "alice") << "a refused transfer";
    const struct {
      std::string owner;
      std::string message;
    } invalid[] = {{"", "new_owner is empty"},
                   {"bad\nname", "new_owner \"bad\\nname\" holds control characters"},
                   {std::string(257, 'x'), "new_owner has 257 bytes; at most 256"}};
    for (const auto& [owner, message] : invalid) {
      const absl::Status refused = manager.Transfer(stored[0], owner).status();
      EXPECT_TRUE(absl::IsInvalidArgument(refused)) << refused;
      EXPECT_THAT(refused.message(), ::testing::HasSubstr(message));
    }
    EXPECT_TRUE(absl::IsNotFound(manager.Transfer("s-0000000000000000", "bob").status()));
  }
  const std::vector<std::string> events = captured.lines();
  size_t handed_events = 0;
  for (const std::string& line : events) {
    handed_events += absl::StrContains(line, "handed");
  }
  EXPECT_EQ(handed_events, 1u);
  EXPECT_TRUE(std::any_of(events.begin(), events.end(), [&](const std::string& line) {
    return absl::StrContains(line, absl::StrCat("session ", stored[1], " handed from client "
                                                "alice to client bob by client ops at ipv4:"));
  })) << absl::StrJoin(events, "\n");

  std::unique_ptr<SessionStore> store = SessionStore::Open(dir_, false).value();
  SessionManager manager(SessionLimits(), &pool_, &encoder_, nullptr, store.get());
  manager.StartRestore();
  manager.WaitForRestore();
  EXPECT_EQ(manager.Get(stored[0]).value()->owner(), "alice");
  EXPECT_EQ(manager.Get(stored[1]).value()->owner(), "bob") << "the new owner was on disk";
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
