#include "server/off_thread_work.h"

#include <memory>
#include <utility>

namespace neuralmesh::server {

bool OffThreadWork::Run(Executor& executor, std::function<void()> work) {
  {
    absl::MutexLock lock(&mu_);
    ++tasks_;
  }
  // Ends the task when the closure goes, whether it ran or was dropped (here when Schedule
  // refuses it, or by the executor's shutdown).
  class EndsTask {
   public:
    explicit EndsTask(OffThreadWork* work) : work_(work) {}
    EndsTask(const EndsTask&) = delete;  // One object, one end: made in place, never copied.
    EndsTask& operator=(const EndsTask&) = delete;
    ~EndsTask() { work_->TaskEnded(); }

   private:
    OffThreadWork* const work_;
  };
  auto ends = std::make_shared<EndsTask>(this);
  return executor.Schedule([ends = std::move(ends), work = std::move(work)] { work(); });
}

bool OffThreadWork::ReleaseOnDone() {
  absl::MutexLock lock(&mu_);
  done_ = true;
  return tasks_ == 0;
}

void OffThreadWork::TaskEnded() {
  bool destroy = false;
  {
    absl::MutexLock lock(&mu_);
    --tasks_;
    destroy = done_ && tasks_ == 0;
  }
  if (destroy) {
    const std::function<void()> destroy_owner = destroy_;  // Outlives the owner it deletes.
    destroy_owner();
  }
}

}  // namespace neuralmesh::server
