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
  if (!sink_) return;
  const std::string line =
      absl::StrCat(absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", absl::Now(), absl::UTCTimeZone()),
                   " session ", session_id, " ", event);
  absl::MutexLock lock(&mu_);
  sink_(line);
}

}  // namespace neuralmesh::server
