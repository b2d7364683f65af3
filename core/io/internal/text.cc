#include "core/io/internal/text.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace neuralmesh::io_internal {
namespace {

bool IsSpace(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

}  // namespace

bool LineCursor::Next(absl::string_view* line) {
  if (offset_ >= text_.size()) return false;
  const size_t end = text_.find('\n', offset_);
  const size_t stop = end == absl::string_view::npos ? text_.size() : end;
  absl::string_view result = text_.substr(offset_, stop - offset_);
  if (!result.empty() && result.back() == '\r') result.remove_suffix(1);
  offset_ = end == absl::string_view::npos ? text_.size() : end + 1;
  ++line_number_;
  *line = result;
  return true;
}

void SplitWhitespace(absl::string_view line, std::vector<absl::string_view>* tokens) {
  tokens->clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsSpace(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !IsSpace(line[i])) ++i;
    if (i > start) tokens->push_back(line.substr(start, i - start));
  }
}

void SplitFields(absl::string_view line, std::vector<absl::string_view>* tokens) {
  tokens->clear();
  for (absl::string_view field :
       absl::StrSplit(line, absl::ByAnyChar(" \t\v\f,;"), absl::SkipEmpty())) {
    tokens->push_back(field);
  }
}

absl::string_view StripHashComment(absl::string_view line) {
  const size_t hash = line.find('#');
  return hash == absl::string_view::npos ? line : line.substr(0, hash);
}

bool ParseDouble(absl::string_view token, double* value) {
  // SimpleAtod trims surrounding whitespace; tokens never hold any, and an empty token is not
  // a number.
  return !token.empty() && absl::SimpleAtod(token, value);
}

bool ParseFloat(absl::string_view token, float* value) {
  double wide = 0;
  if (!ParseDouble(token, &wide)) return false;
  *value = NarrowToFloat(wide);
  return true;
}

float NarrowToFloat(double value) {
  constexpr float kMax = std::numeric_limits<float>::max();
  // Halfway from the largest float to 2^128: ties round to even, which is 2^128, infinite.
  constexpr double kOverflow = 0x1.ffffffp+127;
  if (value >= kOverflow) return std::numeric_limits<float>::infinity();
  if (value <= -kOverflow) return -std::numeric_limits<float>::infinity();
  if (value > kMax) return kMax;
  if (value < -kMax) return -kMax;
  return static_cast<float>(value);
}

bool ParseInt64(absl::string_view token, int64_t* value) {
  return !token.empty() && absl::SimpleAtoi(token, value);
}

std::string Quoted(absl::string_view token) {
  constexpr size_t kMaxShown = 40;
  std::string shown;
  for (size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    shown.push_back(c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?');
  }
  if (token.size() > kMaxShown) shown += "...";
  return absl::StrCat("'", shown, "'");
}

absl::Status LineError(int line, absl::string_view message) {
  return absl::InvalidArgumentError(absl::StrCat("line ", line, ": ", message));
}

void AppendFloat(float value, std::string* out) {
  char buffer[32];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

void AppendCoordinate(float local, double origin, std::string* out) {
  if (origin == 0) {
    AppendFloat(local, out);
    return;
  }
  // As many decimals as `local` needs on its own (956.034 for the float nearest 956.034), and
  // more only when the sum's text would not read back as `local` relative to `origin`.
  char buffer[400];  // Fixed notation of a double up to 1.8e308, and its decimals.
  std::to_chars_result result =
      std::to_chars(buffer, buffer + sizeof(buffer), local, std::chars_format::fixed);
  const char* point = std::find(buffer, result.ptr, '.');
  const int own_decimals = point == result.ptr ? 0 : static_cast<int>(result.ptr - point - 1);
  const double value = origin + double{local};
  for (int decimals = own_decimals; decimals <= own_decimals + 3; ++decimals) {
    result = std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::fixed,
                           decimals);
    double back = 0;
    if (result.ec == std::errc() &&
        ParseDouble(absl::string_view(buffer, result.ptr - buffer), &back) &&
        NarrowToFloat(back - origin) == local) {
      out->append(buffer, result.ptr);
      return;
    }
  }
  result = std::to_chars(buffer, buffer + sizeof(buffer), value);  // The sum itself, exactly.
  out->append(buffer, result.ptr);
}

}  // namespace neuralmesh::io_internal
