// The registry of sessions: creation under the server's limits, lookup, listing, deletion and
// the idle-session reaper.
#ifndef NEURALMESH_SERVER_SESSION_MANAGER_H_
#define NEURALMESH_SERVER_SESSION_MANAGER_H_

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/functional/function_ref.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "core/triangle_mesh.h"
#include "server/event_log.h"
#include "server/executor.h"
#include "server/server_metrics.h"
#include "server/session.h"
#include "server/session_config.h"
#include "server/session_store.h"
#include "server/worker_pool.h"

namespace neuralmesh::server {

struct SessionLimits {
  size_t max_sessions = 64;                // Sessions held at once, in any state.
  // Of those, the most one client (Session::owner, a named access token) may hold; 0: no
  // limit of its own. Sessions without an owner count against max_sessions only.
  size_t max_sessions_per_client = 0;
  size_t max_points_per_session = 1u << 26;  // 67M points.
  // Points per batch: 2M, so that a packed batch of as many points with weights, normals and
  // colours (31 bytes a point) fits the default message limit of 64 MiB.
  size_t max_batch_points = 1u << 21;
  // Sessions without an open stream and without activity (RPCs, learning) for this long are
  // deleted. InfiniteDuration: never.
  absl::Duration idle_timeout = absl::Minutes(30);
};

// What restoring the sessions of the state directory found (SessionManager::StartRestore).
struct RestoreReport {
  size_t sessions = 0;  // Restored, in any state.
  size_t points = 0;    // Their points, taken again.
  absl::Duration took;  // Reading the directory and taking the points again.
  // Sessions left on disk unrestored, torn journal tails cut off, sessions restored as failed:
  // one line each, for the server's log.
  std::vector<std::string> problems;
};

// `id`, as a client sent it, quoted for a status message: cut to its first 64 bytes, with its
// length, when longer (ids the server makes have 18), so that an error about a bogus id never
// outgrows the client's metadata limit (8 KB by default), which turns it into
// RESOURCE_EXHAUSTED.
std::string QuotedSessionId(absl::string_view id);

// OK when a session of `config` can learn from `start_mesh`: fewer vertices than its target,
// and a mesh the learner can go on from (MakeStartMesh); INVALID_ARGUMENT saying why not.
absl::Status CheckStartMesh(const TriangleMesh& start_mesh, const SessionConfig& config);

class SessionManager {
 public:
  // `pool` and `encoder` must outlive the manager's sessions' work (see Session). `log`, when
  // set, records every session's creation, end and deletion. `store`, when set, keeps every
  // session on disk (session_store.h) and must outlive the manager. `metrics`, when set, counts
  // the sessions' creation, work, end and deletion (server_metrics.h) and must outlive them.
  SessionManager(const SessionLimits& limits, WorkerPool* pool, Executor* encoder,
                 std::shared_ptr<EventLog> log = nullptr, SessionStore* store = nullptr,
                 ServerMetrics* metrics = nullptr);
  ~SessionManager();  // Calls Shutdown().

  SessionManager(const SessionManager&) = delete;
  SessionManager& operator=(const SessionManager&) = delete;

  // Validates `config` (ResolveSessionConfig) and creates a session for the client at `peer`
  // (gRPC's peer address, for the event log), owned by `owner` (the client name of the call's
  // access token, Session::owner), that learns from `start_mesh` when set
  // (CreateSessionRequest.start_mesh; with a store it is the session's first checkpoint).
  // INVALID_ARGUMENT for an invalid configuration, a name longer than 256 bytes or a start mesh
  // CheckStartMesh refuses; RESOURCE_EXHAUSTED at max_sessions or when `owner` holds
  // max_sessions_per_client; UNAVAILABLE after Shutdown; with a store, the error of creating
  // the session's files (RESOURCE_EXHAUSTED for a full disk, and so on).
  absl::StatusOr<std::shared_ptr<Session>> Create(
      SessionConfig config, std::string name, absl::string_view peer = "",
      std::string owner = "", std::optional<TriangleMesh> start_mesh = std::nullopt)
      ABSL_LOCKS_EXCLUDED(mu_);

  // Hands the session `id` to the client `new_owner` (TransferSession), on disk first with a
  // store; `by` says who asked, for the event log ("client ops at ipv4:..."). `allowed` decides
  // whether the caller may hand the session over, under the lock that owner changes take, so
  // that two transfers cannot both pass a check of the owner before either changes it; its
  // error is returned. Nothing changes when `new_owner` owns it already. INVALID_ARGUMENT for a
  // new owner that is empty, longer than 256 bytes or holds control characters;
  // RESOURCE_EXHAUSTED when it holds max_sessions_per_client; the errors of Get; with a store,
  // the error of writing the owner.
  absl::StatusOr<std::shared_ptr<Session>> Transfer(
      absl::string_view id, std::string new_owner, absl::string_view by = "",
      absl::FunctionRef<absl::Status(const Session&)> allowed =
          [](const Session&) { return absl::OkStatus(); }) ABSL_LOCKS_EXCLUDED(mu_);

  // NOT_FOUND for an unknown id (INVALID_ARGUMENT for an empty one), UNAVAILABLE after
  // Shutdown. Counts as activity.
  absl::StatusOr<std::shared_ptr<Session>> Get(absl::string_view id) const
      ABSL_LOCKS_EXCLUDED(mu_);

  // Every session, oldest first; UNAVAILABLE after Shutdown.
  absl::StatusOr<std::vector<std::shared_ptr<Session>>> List() const ABSL_LOCKS_EXCLUDED(mu_);

  // Removes the session, and its files with a store; its watchers end with NOT_FOUND.
  // NOT_FOUND when unknown, UNAVAILABLE after Shutdown.
  absl::Status Delete(absl::string_view id) ABSL_LOCKS_EXCLUDED(mu_);

  // Deletes the sessions idle at `now` (see SessionLimits::idle_timeout); returns how many.
  // Lists them first, then deletes each with DeleteIfIdle.
  size_t ReapIdle(absl::Time now) ABSL_LOCKS_EXCLUDED(mu_);

  // Deletes the session only if it is idle at `idle_at`, checked under the registry's lock:
  // FAILED_PRECONDITION when it was touched since (or has an open stream), so that a session
  // used between ReapIdle's listing and its deletion stays. Otherwise as Delete.
  absl::Status DeleteIfIdle(absl::string_view id, absl::Time idle_at) ABSL_LOCKS_EXCLUDED(mu_);

  // Starts restoring the sessions of the store (none without one) on a thread of its own,
  // oldest first, and returns once it knows their ids; call it once, before the server takes
  // calls. Each session takes its batches again and goes on from its stored state (session.h).
  // Until a session is restored, calls on it (Get, Delete) get UNAVAILABLE saying so, and List
  // gets UNAVAILABLE until every one is: a client tries again, as after a lost connection.
  // Sessions can be created meanwhile; stored sessions keep their places before them in List
  // and count toward the limits as restored ones do. Limits apply as at creation, except
  // max_sessions, which restored sessions may exceed (creation waits until they are deleted).
  // A session whose configuration no longer passes the limits stays on disk unrestored; one
  // whose batches no longer fit them is restored as failed, its files unchanged.
  // `before_each`, when set, runs on the restoring thread before each session, with its id.
  void StartRestore(std::function<void(const std::string& id)> before_each = nullptr)
      ABSL_LOCKS_EXCLUDED(mu_);

  // Blocks until the restore StartRestore began has ended (at once when none was begun, or
  // after Shutdown stopped it), and returns what it found.
  RestoreReport WaitForRestore() const ABSL_LOCKS_EXCLUDED(mu_);

  // Stops the reaper and terminates every session with `status` (their streams end with it).
  // Idempotent.
  void Shutdown(const absl::Status& status) ABSL_LOCKS_EXCLUDED(mu_);

  // The sessions held now (restored or created, oldest first) and the stored sessions still to
  // be restored, for the metrics: not activity, and an answer during a restore and after
  // Shutdown too.
  struct Census {
    std::vector<std::shared_ptr<Session>> sessions;
    size_t to_restore = 0;
  };
  Census TakeCensus() const ABSL_LOCKS_EXCLUDED(mu_);

  const SessionLimits& limits() const { return limits_; }

 private:
  void ReaperLoop() ABSL_LOCKS_EXCLUDED(mu_);
  // Delete, or with `idle_at` DeleteIfIdle.
  absl::Status DeleteUnlessActive(absl::string_view id, std::optional<absl::Time> idle_at)
      ABSL_LOCKS_EXCLUDED(mu_);
  std::string NewIdLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void RestoreLoop(std::vector<StoredSessionFiles> stored,
                   std::function<void(const std::string& id)> before_each)
      ABSL_LOCKS_EXCLUDED(mu_);
  // The answer for an `id` that sessions_ lacks: UNAVAILABLE while it is still to be
  // restored, NOT_FOUND otherwise.
  absl::Status NotHeldLocked(absl::string_view id) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // "N of M": the stored sessions restored so far, of all.
  std::string RestoredOfStoredLocked() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Sessions held now and still to be restored, of `owner` alone when not empty.
  size_t HeldLocked(absl::string_view owner) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  const SessionLimits limits_;
  WorkerPool* const pool_;
  Executor* const encoder_;
  const std::shared_ptr<EventLog> log_;  // May be null.
  SessionStore* const store_;             // May be null.
  ServerMetrics* const metrics_;          // May be null.

  mutable absl::Mutex mu_;
  bool shutdown_ ABSL_GUARDED_BY(mu_) = false;
  uint64_t created_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t id_state_ ABSL_GUARDED_BY(mu_);
  // Keyed by id; `order_` keeps creation order for List.
  std::map<std::string, std::shared_ptr<Session>> sessions_ ABSL_GUARDED_BY(mu_);
  std::map<uint64_t, std::string> order_ ABSL_GUARDED_BY(mu_);
  std::thread reaper_;

  // Stored sessions not restored yet, by id: their owners and their places in order_.
  struct Unrestored {
    std::string owner;
    uint64_t order = 0;
  };
  std::map<std::string, Unrestored> unrestored_ ABSL_GUARDED_BY(mu_);
  size_t stored_sessions_ ABSL_GUARDED_BY(mu_) = 0;  // Found by StartRestore.
  bool restoring_ ABSL_GUARDED_BY(mu_) = false;
  RestoreReport restore_report_ ABSL_GUARDED_BY(mu_);
  std::atomic<bool> stop_restoring_{false};  // Set by Shutdown: a journal stops being read.
  std::thread restorer_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SESSION_MANAGER_H_
