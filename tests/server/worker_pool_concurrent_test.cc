#include "server/worker_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <vector>

#include "absl/synchronization/notification.h"

namespace neuralmesh::server {
namespace {

// Busy-works until the slice's deadline, for a fixed number of slices.
class SpinningTask : public Schedulable {
 public:
  explicit SpinningTask(int slices) : remaining_(slices) {}
  SliceResult RunSlice(absl::Time deadline) override {
    while (absl::Now() < deadline) {
    }
    slices_.fetch_add(1);
    return {--remaining_ > 0 ? SliceResult::kMore : SliceResult::kDone};
  }
  int slices() const { return slices_.load(); }

 private:
  int remaining_;
  std::atomic<int> slices_{0};
};

TEST(WorkerPoolTest, EightTasksOnTwoWorkersAllProgress) {
  WorkerPool pool(2, absl::Milliseconds(2));
  std::vector<std::shared_ptr<SpinningTask>> tasks;
  for (int i = 0; i < 8; ++i) {
    tasks.push_back(std::make_shared<SpinningTask>(1000000));
    pool.Wake(tasks.back());
  }
  absl::SleepFor(absl::Milliseconds(200));
  pool.Shutdown();
  int least = 1 << 30, most = 0;
  for (const auto& task : tasks) {
    least = std::min(least, task->slices());
    most = std::max(most, task->slices());
  }
  EXPECT_GE(least, 3) << "every task gets slices in turn";
  EXPECT_LE(most, 3 * least + 2) << "round robin shares the workers fairly";
}

// Goes idle after each slice and counts slices; a wake during a slice must not be lost.
class IdleTask : public Schedulable {
 public:
  SliceResult RunSlice(absl::Time deadline) override {
    if (slices_.fetch_add(1) == 0) {
      started_.Notify();
      absl::SleepFor(absl::Milliseconds(50));  // Woken meanwhile.
    }
    return {SliceResult::kIdle};
  }
  std::atomic<int> slices_{0};
  absl::Notification started_;
};

TEST(WorkerPoolTest, AWakeDuringASliceRunsTheTaskAgain) {
  WorkerPool pool(1, absl::Milliseconds(10));
  auto task = std::make_shared<IdleTask>();
  pool.Wake(task);
  task->started_.WaitForNotification();
  pool.Wake(task);  // While running: it said idle, but it must run again.
  const absl::Time deadline = absl::Now() + absl::Seconds(5);
  while (task->slices_.load() < 2 && absl::Now() < deadline) absl::SleepFor(absl::Milliseconds(1));
  EXPECT_EQ(task->slices_.load(), 2) << "the wake-up that raced with the slice was lost";
  absl::SleepFor(absl::Milliseconds(30));
  EXPECT_EQ(task->slices_.load(), 2) << "an idle task is not run again without a wake";
  EXPECT_EQ(pool.active_tasks(), 0u);
}

class TimedTask : public Schedulable {
 public:
  SliceResult RunSlice(absl::Time deadline) override {
    times[runs.load()] = absl::Now();
    if (runs.fetch_add(1) == 0) return {SliceResult::kIdle, absl::Now() + absl::Milliseconds(30)};
    return {SliceResult::kDone};
  }
  absl::Time times[2];
  std::atomic<int> runs{0};
};

TEST(WorkerPoolTest, IdleTasksWakeAtTheirTimer) {
  WorkerPool pool(1, absl::Milliseconds(10));
  auto task = std::make_shared<TimedTask>();
  pool.Wake(task);
  const absl::Time deadline = absl::Now() + absl::Seconds(5);
  while (task->runs.load() < 2 && absl::Now() < deadline) absl::SleepFor(absl::Milliseconds(5));
  pool.Shutdown();  // Joins the worker: its writes are visible below.
  ASSERT_EQ(task->runs.load(), 2) << "the timer did not wake the task";
  EXPECT_GE(task->times[1] - task->times[0], absl::Milliseconds(25));
}

}  // namespace
}  // namespace neuralmesh::server
