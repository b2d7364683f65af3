// A bounded pool of learning threads shared fairly by every session.
//
// Sessions are Schedulable tasks that learn in time slices: a worker takes the task at the
// front of one FIFO run queue, calls RunSlice with a deadline one slice away, and puts the task
// back at the end of the queue if it has more to do. With W workers and S runnable sessions
// every session therefore gets about W / S of the cores and waits at most about
// (S / W) * slice between two of its slices: 8 sessions on 2 workers all make progress. When
// no other task waits, a task that wants more keeps its worker (no hop to another core with
// cold caches).
//
// A task is in one of three places: nowhere (idle, not known to the pool), in the queue, or
// running on a worker. Wake() makes an idle task runnable; waking a task that is running marks
// it so that it is queued again when its slice returns even if the slice reported kIdle, so a
// wake-up that races with a slice that is just going idle is never lost. A slice may also ask
// to be woken at a time (a refresh that is due later); the pool keeps those timers.
#ifndef NEURALMESH_SERVER_WORKER_POOL_H_
#define NEURALMESH_SERVER_WORKER_POOL_H_

#include <cstddef>
#include <deque>
#include <map>
#include <memory>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/container/flat_hash_map.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"

namespace neuralmesh::server {

// What a slice reports back to the pool.
struct SliceResult {
  enum Kind {
    kMore,  // Runnable: queue again.
    kIdle,  // Nothing to do until Wake() (or wake_at).
    kDone,  // Never run again; the pool forgets the task.
  };
  Kind kind = kIdle;
  // With kIdle: wake the task at this time even without Wake().
  absl::Time wake_at = absl::InfiniteFuture();
};

class Schedulable {
 public:
  virtual ~Schedulable() = default;
  // Does up to `deadline` worth of work. Called by one worker at a time per task.
  virtual SliceResult RunSlice(absl::Time deadline) = 0;
};

class WorkerPool {
 public:
  // Starts `threads` (>= 1) workers with slices of `slice` (> 0).
  WorkerPool(int threads, absl::Duration slice);
  ~WorkerPool();  // Calls Shutdown().

  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Makes `task` runnable (no-op when already queued). Thread-safe; ignored after Shutdown.
  void Wake(std::shared_ptr<Schedulable> task) ABSL_LOCKS_EXCLUDED(mu_);

  // Stops the workers after their current slices and drops every queued task and timer.
  // Idempotent.
  void Shutdown() ABSL_LOCKS_EXCLUDED(mu_);

  int threads() const { return static_cast<int>(workers_.size()); }
  absl::Duration slice() const { return slice_; }

  // Tasks queued or running (for tests and monitoring).
  size_t active_tasks() const ABSL_LOCKS_EXCLUDED(mu_);

 private:
  enum class Place { kQueued, kRunning };
  struct Entry {
    std::shared_ptr<Schedulable> task;
    Place place = Place::kQueued;
    bool wake_pending = false;  // Woken while running.
  };

  void WorkerLoop() ABSL_LOCKS_EXCLUDED(mu_);
  void WakeLocked(std::shared_ptr<Schedulable> task) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Moves due timers into the queue; returns the earliest pending timer.
  absl::Time FireTimersLocked(absl::Time now) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  const absl::Duration slice_;
  mutable absl::Mutex mu_;
  bool shutdown_ ABSL_GUARDED_BY(mu_) = false;
  std::deque<Schedulable*> queue_ ABSL_GUARDED_BY(mu_);
  absl::flat_hash_map<Schedulable*, Entry> entries_ ABSL_GUARDED_BY(mu_);
  // Timers of idle tasks; a weak pointer so a timer does not keep a deleted session alive.
  std::multimap<absl::Time, std::weak_ptr<Schedulable>> timers_ ABSL_GUARDED_BY(mu_);
  std::vector<std::thread> workers_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_WORKER_POOL_H_
