// A small fixed pool of threads running closures in FIFO order: the mesh encoders. Snapshots
// are taken on the learning threads (a copy) and encoded here, so Draco and the mesh report
// never hold up learning.
#ifndef NEURALMESH_SERVER_EXECUTOR_H_
#define NEURALMESH_SERVER_EXECUTOR_H_

#include <deque>
#include <functional>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"

namespace neuralmesh::server {

class Executor {
 public:
  explicit Executor(int threads);  // At least one thread.
  ~Executor();                     // Calls Shutdown().

  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  // Queues `task`. Returns false (and drops the task) after Shutdown.
  bool Schedule(std::function<void()> task) ABSL_LOCKS_EXCLUDED(mu_);

  // Lets the running closures finish, drops the queued ones and joins the threads. Idempotent.
  void Shutdown() ABSL_LOCKS_EXCLUDED(mu_);

 private:
  void Loop() ABSL_LOCKS_EXCLUDED(mu_);

  absl::Mutex mu_;
  bool shutdown_ ABSL_GUARDED_BY(mu_) = false;
  std::deque<std::function<void()>> queue_ ABSL_GUARDED_BY(mu_);
  std::vector<std::thread> threads_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_EXECUTOR_H_
