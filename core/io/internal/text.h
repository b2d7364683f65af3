// Line splitting, tokenizing, number parsing and number formatting shared by the text formats
// (ASCII PLY, OBJ, OFF, ASCII STL, XYZ).
#ifndef NEURALMESH_CORE_IO_INTERNAL_TEXT_H_
#define NEURALMESH_CORE_IO_INTERNAL_TEXT_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::io_internal {

// Walks the lines of a text buffer, numbering them from 1. A line ends at '\n'; a '\r' before
// it is dropped, so Windows line endings read like Unix ones.
class LineCursor {
 public:
  explicit LineCursor(absl::string_view text) : text_(text) {}

  // Sets `line` to the next line and returns true, or returns false at the end of the text.
  bool Next(absl::string_view* line);

  // The number of the line last returned by Next (0 before the first call).
  int line_number() const { return line_number_; }
  // The byte offset just past the line last returned (past its '\n').
  size_t offset() const { return offset_; }
  // The number of bytes not yet returned.
  size_t remaining() const { return text_.size() - offset_; }

 private:
  absl::string_view text_;
  size_t offset_ = 0;
  int line_number_ = 0;
};

// Replaces `tokens` with the whitespace-separated tokens of `line`.
void SplitWhitespace(absl::string_view line, std::vector<absl::string_view>* tokens);
// Replaces `tokens` with the fields of `line`, separated by whitespace, commas or semicolons
// (CloudCompare writes either): the columns of XYZ text.
void SplitFields(absl::string_view line, std::vector<absl::string_view>* tokens);

// `line` up to (not including) its first '#'.
absl::string_view StripHashComment(absl::string_view line);

// Parses the whole token as a decimal number (no trailing characters). Accepts "nan" and
// "inf", which callers reject with a clearer message where coordinates must be finite.
bool ParseDouble(absl::string_view token, double* value);
// As ParseDouble, then NarrowToFloat.
bool ParseFloat(absl::string_view token, float* value);

// Rounds to the nearest float, as a cast does: values that round beyond the largest float
// become infinite (a plain cast of them would be undefined behavior), and those between it and
// the halfway point to 2^128 become the largest float, as the text "3.4028235e+38" that prints
// it must.
float NarrowToFloat(double value);
// Parses the whole token as a base-10 integer.
bool ParseInt64(absl::string_view token, int64_t* value);

// `token` in single quotes for an error message: at most 40 characters, with unprintable bytes
// shown as '?'.
std::string Quoted(absl::string_view token);

// INVALID_ARGUMENT "line <line>: <message>".
absl::Status LineError(int line, absl::string_view message);

// Appends the shortest decimal text that reads back as exactly `value`.
void AppendFloat(float value, std::string* out);
// Appends coordinate `local` + `origin`: as AppendFloat when `origin` is 0, else the sum in
// fixed notation with the fewest decimals (from as many as `local` needs alone) whose value,
// less `origin`, narrows back to `local`: 500956.034 for 500000 and the float nearest 956.034.
void AppendCoordinate(float local, double origin, std::string* out);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_TEXT_H_
