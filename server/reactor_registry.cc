#include "server/reactor_registry.h"

namespace neuralmesh::server {

bool ReactorRegistry::Add(LiveReactor* reactor) {
  absl::MutexLock lock(&mu_);
  if (closed_) return false;
  reactors_.insert(reactor);
  return true;
}

void ReactorRegistry::Remove(LiveReactor* reactor) {
  absl::MutexLock lock(&mu_);
  reactors_.erase(reactor);
}

void ReactorRegistry::AbortAll(const absl::Status& status) {
  absl::MutexLock lock(&mu_);
  closed_ = true;
  for (LiveReactor* reactor : reactors_) reactor->Abort(status);
}

bool ReactorRegistry::AwaitEmpty(absl::Time deadline) {
  absl::MutexLock lock(&mu_);
  auto empty = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return reactors_.empty(); };
  return mu_.AwaitWithDeadline(absl::Condition(&empty), deadline);
}

size_t ReactorRegistry::size() const {
  absl::MutexLock lock(&mu_);
  return reactors_.size();
}

}  // namespace neuralmesh::server
