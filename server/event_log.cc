#include "server/event_log.h"

#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"

namespace neuralmesh::server {

EventLog::Sink EventLog::StandardOutput() {
  return [](const std::string& line) {
    std::fwrite(line.data(), 1, line.size(), stdout);
    std::fputc('\n', stdout);
    std::fflush(stdout);
  };
}

void EventLog::Record(absl::string_view session_id, absl::string_view event) {
  RecordLine(absl::StrCat("session ", session_id, " ", event));
}

void EventLog::RecordLine(absl::string_view line) {
  if (!sink_) return;
  const std::string stamped = absl::StrCat(
      absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", absl::Now(), absl::UTCTimeZone()), " ", line);
  absl::MutexLock lock(&mu_);
  sink_(stamped);
}

}  // namespace neuralmesh::server
