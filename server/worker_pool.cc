#include "server/worker_pool.h"

#include <algorithm>
#include <utility>

namespace neuralmesh::server {

WorkerPool::WorkerPool(int threads, absl::Duration slice) : slice_(slice) {
  threads = std::max(threads, 1);
  workers_.reserve(threads);
  for (int i = 0; i < threads; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

WorkerPool::~WorkerPool() { Shutdown(); }

void WorkerPool::Wake(std::shared_ptr<Schedulable> task) {
  absl::MutexLock lock(&mu_);
  if (shutdown_) return;
  WakeLocked(std::move(task));
}

void WorkerPool::WakeLocked(std::shared_ptr<Schedulable> task) {
  Schedulable* key = task.get();
  auto [it, inserted] = entries_.try_emplace(key);
  if (inserted) {
    it->second.task = std::move(task);
    it->second.place = Place::kQueued;
    queue_.push_back(key);
  } else if (it->second.place == Place::kRunning) {
    it->second.wake_pending = true;
  }
}

absl::Time WorkerPool::FireTimersLocked(absl::Time now) {
  while (!timers_.empty() && timers_.begin()->first <= now) {
    std::shared_ptr<Schedulable> task = timers_.begin()->second.lock();
    timers_.erase(timers_.begin());
    if (task != nullptr) WakeLocked(std::move(task));
  }
  return timers_.empty() ? absl::InfiniteFuture() : timers_.begin()->first;
}

void WorkerPool::WorkerLoop() {
  mu_.Lock();
  while (true) {
    const absl::Time next_timer = FireTimersLocked(absl::Now());
    if (shutdown_) break;
    if (queue_.empty()) {
      // Sleep until a wake-up, the next timer or shutdown.
      auto ready = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
        return shutdown_ || !queue_.empty();
      };
      mu_.AwaitWithDeadline(absl::Condition(&ready), next_timer);
      continue;
    }
    Schedulable* key = queue_.front();
    queue_.pop_front();
    Entry& entry = entries_[key];
    entry.place = Place::kRunning;
    entry.wake_pending = false;
    std::shared_ptr<Schedulable> task = entry.task;  // Keeps it alive outside the lock.

    while (true) {
      mu_.Unlock();
      const SliceResult result = task->RunSlice(absl::Now() + slice_);
      mu_.Lock();

      // Shutdown may have cleared the table while the slice ran.
      auto it = entries_.find(key);
      if (it == entries_.end()) break;
      if (result.kind == SliceResult::kDone) {
        entries_.erase(it);
        break;
      }
      if (result.kind == SliceResult::kMore || it->second.wake_pending) {
        it->second.wake_pending = false;
        FireTimersLocked(absl::Now());
        // Nobody else waits: keep the task on this thread, where its data is in the caches.
        if (queue_.empty() && !shutdown_) continue;
        it->second.place = Place::kQueued;
        queue_.push_back(key);
        break;
      }
      entries_.erase(it);
      if (result.wake_at != absl::InfiniteFuture()) timers_.emplace(result.wake_at, task);
      break;
    }
    // Drop our reference outside the lock: the last reference may destroy a session.
    mu_.Unlock();
    task.reset();
    mu_.Lock();
  }
  mu_.Unlock();
}

void WorkerPool::Shutdown() {
  std::vector<std::thread> workers;
  absl::flat_hash_map<Schedulable*, Entry> entries;
  std::multimap<absl::Time, std::weak_ptr<Schedulable>> timers;
  {
    absl::MutexLock lock(&mu_);
    if (shutdown_) return;
    shutdown_ = true;
    queue_.clear();
    entries.swap(entries_);
    timers.swap(timers_);
    workers.swap(workers_);
  }
  for (std::thread& worker : workers) worker.join();
  // `entries` and `timers` release their tasks here, outside the lock.
}

size_t WorkerPool::active_tasks() const {
  absl::MutexLock lock(&mu_);
  return entries_.size();
}

}  // namespace neuralmesh::server
