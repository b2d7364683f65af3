#include "core/io/point_text_stream.h"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"

namespace neuralmesh {
namespace {

// A point's line is a few dozen bytes; a stream whose line runs past this is not text.
constexpr size_t kLongestLine = 1 << 20;

}  // namespace

absl::Status PointTextStream::ParseLine(absl::string_view line, std::vector<Vec3>* points) {
  ++lines_;
  line = absl::StripTrailingAsciiWhitespace(io_internal::StripHashComment(line));  // CRLF.
  std::vector<absl::string_view> tokens;
  io_internal::SplitFields(line, &tokens);
  if (tokens.empty()) return absl::OkStatus();
  Vec3 p;
  for (int c = 0; c < 3; ++c) {
    if (static_cast<size_t>(c) >= tokens.size() || !io_internal::ParseDouble(tokens[c], &p[c]) ||
        !std::isfinite(p[c])) {
      return absl::InvalidArgumentError(
          absl::StrCat(name_, ", line ", lines_, ": ", io_internal::Quoted(line),
                       " does not start with a point's x, y and z (three finite numbers)"));
    }
  }
  points->push_back(p);
  return absl::OkStatus();
}

absl::StatusOr<bool> PointTextStream::Read(absl::Duration wait, std::vector<Vec3>* points) {
  if (ended_) return false;
  pollfd ready{fd_, POLLIN, 0};
  const int waited = poll(&ready, 1, static_cast<int>(absl::ToInt64Milliseconds(wait)));
  if (waited < 0 && errno != EINTR) {
    return absl::UnavailableError(absl::StrCat("cannot read ", name_, ": ", strerror(errno)));
  }
  if (waited <= 0) return true;
  char buffer[1 << 16];
  const ssize_t got = read(fd_, buffer, sizeof(buffer));
  if (got < 0) {
    if (errno == EINTR || errno == EAGAIN) return true;
    return absl::UnavailableError(absl::StrCat("cannot read ", name_, ": ", strerror(errno)));
  }
  if (got == 0) {
    ended_ = true;
    if (!partial_.empty()) {
      const std::string last = std::move(partial_);
      partial_.clear();
      if (absl::Status parsed = ParseLine(last, points); !parsed.ok()) return parsed;
    }
    return false;
  }
  absl::string_view text(buffer, static_cast<size_t>(got));
  for (size_t newline = text.find('\n'); newline != absl::string_view::npos;
       newline = text.find('\n')) {
    absl::Status parsed;
    if (partial_.empty()) {
      parsed = ParseLine(text.substr(0, newline), points);
    } else {
      partial_.append(text.data(), newline);
      parsed = ParseLine(partial_, points);
      partial_.clear();
    }
    if (!parsed.ok()) return parsed;
    text.remove_prefix(newline + 1);
  }
  partial_.append(text.data(), text.size());
  if (partial_.size() > kLongestLine) {
    return absl::InvalidArgumentError(absl::StrCat(name_, ", line ", lines_ + 1, ": over ",
                                                   kLongestLine,
                                                   " bytes without a line's end: not "
                                                   "text of points"));
  }
  return true;
}

Origin OriginOfStreamedPoints(const BoundingBox& first_points) {
  const Vec3& low = first_points.min;
  const Vec3& high = first_points.max;
  return io_internal::OriginOfUnstatedResolution({low[0], low[1], low[2]},
                                                 {high[0], high[1], high[2]});
}

}  // namespace neuralmesh
