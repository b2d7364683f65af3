// Points arriving as text on a file descriptor, a line at a time as they come: standard input
// fed by a scanner's pipeline (`scanner | neuralmesh reconstruct - --server ...`), a pipe or a
// socket. Each line holds a point's x, y and z, its fields split as the XYZ reader splits them
// (spaces, tabs, commas or semicolons); further columns are ignored, as are blank lines and
// '#' comments. The stream never blocks longer than
// asked, so that a caller can send what has come at its own pace.
#ifndef NEURALMESH_CORE_IO_POINT_TEXT_STREAM_H_
#define NEURALMESH_CORE_IO_POINT_TEXT_STREAM_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/bounding_box.h"
#include "core/origin.h"

namespace neuralmesh {

class PointTextStream {
 public:
  // The stream of `fd` (not closed here); `name` names it in messages ("standard input").
  PointTextStream(int fd, std::string name) : fd_(fd), name_(std::move(name)) {}

  // Appends the points of the lines that have arrived to `points`, in the stream's coordinates,
  // waiting up to `wait` for a first byte when none is there. Returns whether the stream goes
  // on (false once it ended: a last line without a newline is taken then). INVALID_ARGUMENT,
  // naming the stream and the line, for a line that does not start with three finite numbers;
  // UNAVAILABLE for a read that fails.
  absl::StatusOr<bool> Read(absl::Duration wait, std::vector<Vec3>* points);

  const std::string& name() const { return name_; }
  // The lines read so far.
  uint64_t lines() const { return lines_; }

 private:
  // Parses the complete line `line` (without its newline) into `points`.
  absl::Status ParseLine(absl::string_view line, std::vector<Vec3>* points);

  int fd_;
  std::string name_;
  std::string partial_;  // The start of a line whose end has not arrived.
  uint64_t lines_ = 0;
  bool ended_ = false;
};

// Where points of a stream that states no resolution should be taken relative to, from the box
// of its first points: the origin reading an XYZ file of them chooses (PositionCollector's
// rule), so that georeferenced coordinates keep their precision as floats.
Origin OriginOfStreamedPoints(const BoundingBox& first_points);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_POINT_TEXT_STREAM_H_
