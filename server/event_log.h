// The operator's record of what happens to sessions: one line per event, for the server's
// standard output (and so `docker logs`):
//
//   2026-12-05T01:30:12.345Z session s-1a2b3c4d5e6f7a8b created by ipv4:10.0.0.7:41234: "scan", target 20000 vertices
//   2026-12-05T01:30:19.802Z session s-1a2b3c4d5e6f7a8b finished: 20000 vertices, 39996 faces, genus 1, ...
//
// Events: created (by whom, name, target, options that change learning), finished (the final
// mesh's figures), cancelled (why), failed (why), deleted (by a call, or idle for how long).
// Point batches and meshes in between are not events: `neuralmesh sessions` shows progress.
// With --log_calls, the gRPC calls too (call_log_interceptor.h):
//
//   2026-12-05T01:30:13.002Z call GetSession from ipv4:10.0.0.7:41240: NOT_FOUND (...) in 0.2 ms
#ifndef NEURALMESH_SERVER_EVENT_LOG_H_
#define NEURALMESH_SERVER_EVENT_LOG_H_

#include <functional>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"

namespace neuralmesh::server {

class EventLog {
 public:
  // Receives each line, without its newline, one call at a time.
  using Sink = std::function<void(const std::string& line)>;

  // A null sink records nothing.
  explicit EventLog(Sink sink) : sink_(std::move(sink)) {}

  // Writes each line to standard output and flushes it.
  static Sink StandardOutput();

  // "<UTC time> session <id> <event>". Thread-safe.
  void Record(absl::string_view session_id, absl::string_view event) ABSL_LOCKS_EXCLUDED(mu_);
  // "<UTC time> <line>". Thread-safe.
  void RecordLine(absl::string_view line) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  absl::Mutex mu_;
  const Sink sink_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_EVENT_LOG_H_
