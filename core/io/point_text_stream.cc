#include "core/io/point_text_stream.h"

#include <cmath>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/io/internal/text.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

// A point's line is a few dozen bytes; a stream whose line runs past this is not text.
constexpr size_t kLongestLine = 1 << 20;

}  // namespace

absl::Status PointTextStream::ParseLine(absl::string_view line, StreamedPoints* points) {
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
          absl::StrCat(name(), ", line ", lines_, ": ", io_internal::Quoted(line),
                       " does not start with a point's x, y and z (three finite numbers)"));
    }
  }
  points->positions.push_back(p);
  return absl::OkStatus();
}

std::string PointTextStream::ReadSoFar() const {
  return absl::StrCat(lines_, lines_ == 1 ? " line" : " lines");
}

absl::Status PointTextStream::End(StreamedPoints* points) {
  if (partial_.empty()) return absl::OkStatus();
  const std::string last = std::move(partial_);
  partial_.clear();
  return ParseLine(last, points);
}

absl::Status PointTextStream::Take(absl::string_view text, StreamedPoints* points) {
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
    return absl::InvalidArgumentError(absl::StrCat(name(), ", line ", lines_ + 1, ": over ",
                                                   kLongestLine,
                                                   " bytes without a line's end: not "
                                                   "text of points"));
  }
  return absl::OkStatus();
}

}  // namespace neuralmesh
