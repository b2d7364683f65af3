// A one-line progress bar for long commands, redrawn in place with '\r'.
#ifndef NEURALMESH_CLIENT_PROGRESS_BAR_H_
#define NEURALMESH_CLIENT_PROGRESS_BAR_H_

#include <cstdint>
#include <ostream>
#include <string>

#include "absl/time/clock.h"
#include "absl/time/time.h"

namespace neuralmesh::client {

// Whether a progress bar belongs on standard error: it is a terminal, or `forced`.
bool ShowProgressOnStderr(bool forced);

class ProgressBar {
 public:
  // Draws on `out` only when `enabled`; `label` prefixes the bar ("learning", "upload") and
  // `unit` follows the count ("vertices", "points").
  ProgressBar(std::ostream& out, bool enabled, std::string label, std::string unit);
  ~ProgressBar();

  // Redraws the bar at `done` of `total` (total 0: no percentage) followed by `detail`.
  // Redraws at most ten times a second unless `done == total`.
  void Update(uint64_t done, uint64_t total, const std::string& detail = "");

  // Ends the bar's line, so that what follows starts on a fresh one.
  void Finish();

  // Erases the bar from its line, so that other output can be printed there; the next
  // Update draws it again.
  void Clear();

 private:
  std::ostream& out_;
  const bool enabled_;
  const std::string label_;
  const std::string unit_;
  const absl::Time start_;
  absl::Time last_draw_ = absl::InfinitePast();
  size_t last_width_ = 0;
  bool drawn_ = false;
};

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_PROGRESS_BAR_H_
