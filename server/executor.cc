#include "server/executor.h"

#include <algorithm>
#include <utility>

namespace neuralmesh::server {

Executor::Executor(int threads) {
  threads = std::max(threads, 1);
  threads_.reserve(threads);
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Loop(); });
}

Executor::~Executor() { Shutdown(); }

bool Executor::Schedule(std::function<void()> task) {
  absl::MutexLock lock(&mu_);
  if (shutdown_) return false;
  queue_.push_back(std::move(task));
  return true;
}

void Executor::Loop() {
  while (true) {
    std::function<void()> task;
    {
      absl::MutexLock lock(&mu_);
      auto ready = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
        return shutdown_ || !queue_.empty();
      };
      mu_.Await(absl::Condition(&ready));
      if (shutdown_) return;
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    task();
  }
}

void Executor::Shutdown() {
  std::deque<std::function<void()>> dropped;
  std::vector<std::thread> threads;
  {
    absl::MutexLock lock(&mu_);
    if (shutdown_) return;
    shutdown_ = true;
    dropped.swap(queue_);
    threads.swap(threads_);
  }
  for (std::thread& thread : threads) thread.join();
  // `dropped` destroys its closures (and what they captured) here, outside the lock.
}

}  // namespace neuralmesh::server
