// Restoring one session of the state directory (session_store.h) after a restart of the
// server: its settings checked against the server's limits, its batches taken again from its
// journal, its state and latest mesh put back (Session::ReplayBatch, Session::FinishRestore).
#ifndef NEURALMESH_SERVER_SESSION_RESTORE_H_
#define NEURALMESH_SERVER_SESSION_RESTORE_H_

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "server/event_log.h"
#include "server/executor.h"
#include "server/session.h"
#include "server/session_store.h"
#include "server/worker_pool.h"

namespace neuralmesh::server {

// The session of `files`, restored, its files reopened in `store`; or null when it stays on
// disk untouched (its settings no longer pass `max_points_per_session`, its journal or files
// cannot be opened). What went wrong or was mended goes to `problems`, one line each: a torn
// journal tail (cut off), a batch that no longer fits (the session is then restored as
// failed, its files whole). `log`, when set, records the restoration; `metrics`, when set,
// counts the session's work after it (Session::AttachMetrics). Once `stop` is set (when given),
// the journal is read no further and the session stays on disk untouched.
std::shared_ptr<Session> RestoreSession(const StoredSessionFiles& files, SessionStore& store,
                                        size_t max_points_per_session, WorkerPool* pool,
                                        Executor* encoder, std::shared_ptr<EventLog> log,
                                        ServerMetrics* metrics, std::vector<std::string>& problems,
                                        const std::atomic<bool>* stop = nullptr);

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_SESSION_RESTORE_H_
