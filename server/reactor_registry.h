// The live streaming reactors of the server, so that shutdown can end every open call with a
// status instead of waiting for clients that never hang up.
#ifndef NEURALMESH_SERVER_REACTOR_REGISTRY_H_
#define NEURALMESH_SERVER_REACTOR_REGISTRY_H_

#include <cstddef>

#include "absl/base/thread_annotations.h"
#include "absl/container/flat_hash_set.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"

namespace neuralmesh::server {

// A reactor that can be told to finish from outside its own callbacks.
class LiveReactor {
 public:
  virtual ~LiveReactor() = default;
  // Finishes the call with `status` as soon as no write is in flight. Must not block and must
  // not call back into the registry.
  virtual void Abort(const absl::Status& status) = 0;
};

class ReactorRegistry {
 public:
  // Registers a reactor (called from its constructor). Returns false once AbortAll has run:
  // the reactor must then finish at once with UNAVAILABLE.
  bool Add(LiveReactor* reactor) ABSL_LOCKS_EXCLUDED(mu_);
  // Unregisters (called from OnDone, before the reactor deletes itself).
  void Remove(LiveReactor* reactor) ABSL_LOCKS_EXCLUDED(mu_);

  // Refuses new reactors and aborts every live one with `status`. Abort runs under the
  // registry's lock, so a reactor cannot delete itself meanwhile (its OnDone waits in Remove).
  void AbortAll(const absl::Status& status) ABSL_LOCKS_EXCLUDED(mu_);

  // Waits until every reactor has unregistered or `deadline` passes; true when none is left.
  bool AwaitEmpty(absl::Time deadline) ABSL_LOCKS_EXCLUDED(mu_);

  size_t size() const ABSL_LOCKS_EXCLUDED(mu_);

 private:
  mutable absl::Mutex mu_;
  bool closed_ ABSL_GUARDED_BY(mu_) = false;
  absl::flat_hash_set<LiveReactor*> reactors_ ABSL_GUARDED_BY(mu_);
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_REACTOR_REGISTRY_H_
