#include "core/io/point_selection.h"

#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace neuralmesh {
namespace {

constexpr int kLargestClass = 255;

absl::StatusOr<int> ParseClass(absl::string_view text, absl::string_view list) {
  int value = 0;
  if (!absl::SimpleAtoi(text, &value) || value < 0 || value > kLargestClass) {
    return absl::InvalidArgumentError(absl::StrCat("LAS classes '", list, "': '", text,
                                                   "' is not a class from 0 to ", kLargestClass));
  }
  return value;
}

}  // namespace

absl::StatusOr<LasClasses> ParseLasClasses(absl::string_view text) {
  LasClasses classes;
  const absl::string_view list = absl::StripAsciiWhitespace(text);
  if (list == "all") return classes.set();
  if (list.empty()) {
    return absl::InvalidArgumentError(
        "LAS classes: the list is empty; give classes such as 2,6 or 1-6, or all");
  }
  for (absl::string_view item : absl::StrSplit(list, ',')) {
    item = absl::StripAsciiWhitespace(item);
    const std::vector<absl::string_view> ends = absl::StrSplit(item, absl::MaxSplits('-', 1));
    absl::StatusOr<int> first = ParseClass(ends[0], list);
    if (!first.ok()) return first.status();
    absl::StatusOr<int> last = ends.size() == 2 ? ParseClass(ends[1], list) : first;
    if (!last.ok()) return last.status();
    if (*last < *first) {
      return absl::InvalidArgumentError(
          absl::StrCat("LAS classes '", list, "': the range '", item, "' runs backwards"));
    }
    for (int c = *first; c <= *last; ++c) classes.set(c);
  }
  return classes;
}

}  // namespace neuralmesh
