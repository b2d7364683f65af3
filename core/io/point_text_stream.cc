#include "core/io/point_text_stream.h"

#include <cmath>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/io/internal/text.h"
#include "core/io/internal/xyz.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

// A point's line is a few dozen bytes; a stream whose line runs past this is not text.
constexpr size_t kLongestLine = 1 << 20;

// The comments before the first point kept as candidates for its header, the last ones.
constexpr size_t kHeaderCandidates = 16;

constexpr const char* kChannelNames[3] = {"red", "green", "blue"};

}  // namespace

absl::Status PointTextStream::ParseLine(absl::string_view line, StreamedPoints* points) {
  ++lines_;
  line = absl::StripTrailingAsciiWhitespace(line);  // CRLF.
  if (const std::optional<absl::string_view> comment = io_internal::XyzCommentText(line);
      comment.has_value()) {
    if (!first_point_read_) {
      if (comments_.size() == kHeaderCandidates) comments_.erase(comments_.begin());
      comments_.emplace_back(*comment);
    }
    return absl::OkStatus();
  }
  line = absl::StripTrailingAsciiWhitespace(io_internal::StripHashComment(line));
  std::vector<absl::string_view> tokens;
  io_internal::SplitFields(line, &tokens);
  if (tokens.empty()) return absl::OkStatus();
  const auto invalid = [&](absl::string_view why) {
    return absl::InvalidArgumentError(
        absl::StrCat(name(), ", line ", lines_, ": ", io_internal::Quoted(line), " ", why));
  };
  Vec3 p;
  for (int c = 0; c < 3; ++c) {
    if (static_cast<size_t>(c) >= tokens.size() || !io_internal::ParseDouble(tokens[c], &p[c]) ||
        !std::isfinite(p[c])) {
      return invalid("does not start with a point's x, y and z (three finite numbers)");
    }
  }
  if (!first_point_read_) {
    first_point_read_ = true;
    for (auto it = comments_.rbegin(); it != comments_.rend(); ++it) {
      if (const auto layout = io_internal::XyzLayoutFromHeader(*it, tokens.size());
          layout.has_value()) {
        if (layout->color[0] >= 0) color_columns_ = layout->color;
        break;
      }
    }
    comments_.clear();
  }
  if (color_columns_.has_value()) {
    std::array<float, 3> color;
    for (int c = 0; c < 3; ++c) {
      const size_t column = static_cast<size_t>((*color_columns_)[c]);
      double channel = 0;
      if (column >= tokens.size() || !io_internal::ParseDouble(tokens[column], &channel) ||
          !std::isfinite(channel)) {
        return invalid(absl::StrCat("has no ", kChannelNames[c], " in column ", column + 1,
                                    ", where the header names it (a finite number)"));
      }
      color[c] = static_cast<float>(channel);
    }
    points->colors.push_back(color);
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
