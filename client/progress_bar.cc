#include "client/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <utility>

#include "absl/strings/str_format.h"

namespace neuralmesh::client {
namespace {
constexpr int kBarWidth = 30;
}  // namespace

bool ShowProgressOnStderr(bool forced) { return forced || isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(std::ostream& out, bool enabled, std::string label, std::string unit)
    : out_(out),
      enabled_(enabled),
      label_(std::move(label)),
      unit_(std::move(unit)),
      start_(absl::Now()) {}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Update(uint64_t done, uint64_t total, const std::string& detail) {
  if (!enabled_) return;
  const absl::Time now = absl::Now();
  if (now - last_draw_ < absl::Milliseconds(100) && done != total) return;
  last_draw_ = now;

  std::string line = label_ + " ";
  if (total > 0) {
    const double fraction = std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
    const int filled = static_cast<int>(fraction * kBarWidth);
    line += "[" + std::string(filled, '#') + std::string(kBarWidth - filled, ' ') + "]";
    line += absl::StrFormat(" %3.0f%% %d/%d %s", 100 * fraction, done, total, unit_);
  } else {
    line += absl::StrFormat("%d %s", done, unit_);
  }
  line += absl::StrFormat("  %.1fs", absl::ToDoubleSeconds(now - start_));
  if (!detail.empty()) line += "  " + detail;
  // Pad with blanks so that a shorter line fully covers the previous one.
  const size_t width = line.size();
  if (width < last_width_) line += std::string(last_width_ - width, ' ');
  last_width_ = width;
  out_ << '\r' << line << std::flush;
  drawn_ = true;
}

void ProgressBar::Finish() {
  if (!drawn_) return;
  out_ << '\n' << std::flush;
  drawn_ = false;
  last_width_ = 0;
}

void ProgressBar::Clear() {
  if (!drawn_) return;
  out_ << '\r' << std::string(last_width_, ' ') << '\r' << std::flush;
  drawn_ = false;
  last_width_ = 0;
  last_draw_ = absl::InfinitePast();
}

}  // namespace neuralmesh::client
