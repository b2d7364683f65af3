#include "server/off_thread_work.h"

#include <gtest/gtest.h>

#include <atomic>
#include <memory>

#include "absl/synchronization/notification.h"

namespace neuralmesh::server {
namespace {

// Stands in for a reactor: owns its OffThreadWork and records its deletion.
struct Owner {
  explicit Owner(std::atomic<int>* deleted) : deleted(deleted), work([this] { delete this; }) {}
  ~Owner() { deleted->fetch_add(1); }
  std::atomic<int>* deleted;
  OffThreadWork work;
};

TEST(OffThreadWorkTest, WithoutWorkOnDoneDeletesAtOnce) {
  std::atomic<int> deleted{0};
  auto* owner = new Owner(&deleted);
  ASSERT_TRUE(owner->work.ReleaseOnDone());
  delete owner;
  EXPECT_EQ(deleted.load(), 1);
}

// OnDone while the work runs: the owner lives until the work has ended, then goes.
TEST(OffThreadWorkTest, TheLastTaskDeletesAnOwnerThatIsDone) {
  Executor executor(1);
  std::atomic<int> deleted{0};
  auto* owner = new Owner(&deleted);
  absl::Notification started, release;
  std::atomic<int> seen_deleted{-1};
  ASSERT_TRUE(owner->work.Run(executor, [&] {
    started.Notify();
    release.WaitForNotification();
    seen_deleted = deleted.load();  // The owner must still be alive here.
  }));
  started.WaitForNotification();
  EXPECT_FALSE(owner->work.ReleaseOnDone()) << "work is running";
  EXPECT_EQ(deleted.load(), 0);
  release.Notify();
  executor.Shutdown();  // Joins the thread: the task has ended.
  EXPECT_EQ(seen_deleted.load(), 0);
  EXPECT_EQ(deleted.load(), 1);
}

// A task the executor drops at shutdown still ends, and a queue that no longer runs refuses.
TEST(OffThreadWorkTest, DroppedAndRefusedTasksEnd) {
  Executor executor(1);
  absl::Notification started, release;
  ASSERT_TRUE(executor.Schedule([&] {
    started.Notify();
    release.WaitForNotification();
  }));
  started.WaitForNotification();
  std::atomic<int> deleted{0};
  auto* owner = new Owner(&deleted);
  std::atomic<bool> ran{false};
  ASSERT_TRUE(owner->work.Run(executor, [&] { ran = true; }));  // Queued behind the blocker.
  EXPECT_FALSE(owner->work.ReleaseOnDone());
  release.Notify();
  executor.Shutdown();  // Drops the queued task, unless the thread took it first.
  EXPECT_EQ(deleted.load(), 1) << "ran: " << ran.load();

  std::atomic<int> deleted_late{0};
  auto* late = new Owner(&deleted_late);
  EXPECT_FALSE(late->work.Run(executor, [] {}));
  EXPECT_TRUE(late->work.ReleaseOnDone()) << "the refused task has ended";
  delete late;
  EXPECT_EQ(deleted_late.load(), 1);
}

}  // namespace
}  // namespace neuralmesh::server
