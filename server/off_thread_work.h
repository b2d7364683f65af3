// Work of a streaming reactor run on an Executor instead of on gRPC's callback threads, and the
// reactor's deletion deferred until that work has ended.
//
// gRPC runs every reaction of the server's calls on a few threads of its own, so a reaction
// must not block: while one filters a large batch for outliers (seconds for a million points,
// streaming_outlier_filter.h), calls of other clients wait (three such uploads held a
// GetSession up for 20 s). The reactor hands that work to an Executor instead and starts its
// next read from there. The call may end meanwhile (shutdown, the session deleted, the client
// gone), and then OnDone may come while the work is queued or running, so the reactor cannot
// delete itself in OnDone: it asks ReleaseOnDone, and when that says no, the last task to end
// deletes it.
#ifndef NEURALMESH_SERVER_OFF_THREAD_WORK_H_
#define NEURALMESH_SERVER_OFF_THREAD_WORK_H_

#include <functional>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "server/executor.h"

namespace neuralmesh::server {

class OffThreadWork {
 public:
  // `destroy` deletes the reactor that owns this object.
  explicit OffThreadWork(std::function<void()> destroy) : destroy_(std::move(destroy)) {}

  OffThreadWork(const OffThreadWork&) = delete;
  OffThreadWork& operator=(const OffThreadWork&) = delete;

  // Queues `work` on `executor`. False when the executor has shut down: nothing runs, and the
  // caller ends the call itself. A task the executor drops at its shutdown still counts as
  // ended.
  bool Run(Executor& executor, std::function<void()> work) ABSL_LOCKS_EXCLUDED(mu_);

  // Called once, from the reactor's OnDone: true when no work is queued or running, and the
  // reactor deletes itself now; false when the last task will delete it.
  bool ReleaseOnDone() ABSL_LOCKS_EXCLUDED(mu_);

 private:
  void TaskEnded() ABSL_LOCKS_EXCLUDED(mu_);

  const std::function<void()> destroy_;
  absl::Mutex mu_;
  int tasks_ ABSL_GUARDED_BY(mu_) = 0;
  bool done_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_OFF_THREAD_WORK_H_
