// Points arriving as text on a file descriptor, a line at a time as they come (a PointStream:
// point_stream.h). Each line holds a point's x, y and z, its fields split as the XYZ reader
// splits them (spaces, tabs, commas or semicolons); blank lines and comments ('#', or a line
// starting with "//") are skipped. Further columns are ignored, unless a header comment before
// the first point names the columns as an XYZ file's does ("# x y z r g b", CloudCompare's
// "//X,Y,Z,R,G,B": as many names as the first point's values): then each line's red, green and
// blue come too, as 0-255 levels or fractions (ColorScale: TextChannelScale).
#ifndef NEURALMESH_CORE_IO_POINT_TEXT_STREAM_H_
#define NEURALMESH_CORE_IO_POINT_TEXT_STREAM_H_

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/io/point_stream.h"
#include "core/rgb.h"

namespace neuralmesh {

class PointTextStream final : public DescriptorPointStream {
 public:
  // The stream of `fd` (not closed here); `name` names it in messages ("standard input").
  // `first_bytes`: its bytes read already (OpenPointStream's, to tell its format).
  PointTextStream(int fd, std::string name, std::string first_bytes = "")
      : DescriptorPointStream(fd, std::move(name), std::move(first_bytes)) {}

  // Read (PointStream::Read) gives the points of the lines that have arrived (a last line
  // without a newline is taken at the end). INVALID_ARGUMENT, naming the stream and the line,
  // for a line that does not start with three finite numbers.

  // "12 lines".
  std::string ReadSoFar() const override;
  double ColorScale(float largest) const override { return TextChannelScale(largest); }
  // The lines read so far.
  uint64_t lines() const { return lines_; }

 private:
  // The points of the lines `text` completes.
  absl::Status Take(absl::string_view text, StreamedPoints* points) override;
  // The last line, if it has no newline.
  absl::Status End(StreamedPoints* points) override;
  // Parses the complete line `line` (without its newline) into `points`.
  absl::Status ParseLine(absl::string_view line, StreamedPoints* points);

  std::string partial_;  // The start of a line whose end has not arrived.
  uint64_t lines_ = 0;
  bool first_point_read_ = false;
  std::vector<std::string> comments_;  // Before the first point: the header's candidates.
  std::optional<std::array<int, 3>> color_columns_;  // As the header names them.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_POINT_TEXT_STREAM_H_
