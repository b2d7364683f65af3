// Which of a file's points the readers take, where a file says more of a point than where it
// is: the classification of LiDAR points (LAS).
#ifndef NEURALMESH_CORE_IO_POINT_SELECTION_H_
#define NEURALMESH_CORE_IO_POINT_SELECTION_H_

#include <bitset>
#include <optional>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh {

// ASPRS classes (LAS 1.4, Table 17): bit c for class c. Formats 0-5 hold classes 0-31,
// formats 6-10 classes 0-255.
using LasClasses = std::bitset<256>;

struct PointSelection {
  // LAS: the classes whose points are taken (2 ground, 6 building, 7 low noise, ...). Unset:
  // every class but noise (7, low point, and 18, high noise). Withheld points are never taken.
  std::optional<LasClasses> las_classes;
};

// Classes as a user writes them: numbers from 0 to 255 separated by commas ("2,6"), ranges
// ("1-6,9"), or "all". INVALID_ARGUMENT saying what is wrong otherwise.
absl::StatusOr<LasClasses> ParseLasClasses(absl::string_view text);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_POINT_SELECTION_H_
