// Points arriving on a file descriptor as they come: standard input fed by a scanner's or a
// converter's pipeline (`scanner | neuralmesh reconstruct - --server ...`), a pipe or a socket.
// A stream is text of "x y z" lines (PointTextStream: with colours where a header comment names
// their columns) or a LAS file's header and records (LasPointStream: with their colours, and a
// choice of their classes), told apart by its first bytes (OpenPointStream). Reads never block
// longer than asked, so that a caller can send what has come at its own pace.
#ifndef NEURALMESH_CORE_IO_POINT_STREAM_H_
#define NEURALMESH_CORE_IO_POINT_STREAM_H_

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/time/time.h"
#include "core/bounding_box.h"
#include "core/io/point_selection.h"
#include "core/origin.h"

namespace neuralmesh {

// The points a stream gave, in its coordinates, with their colours where they carry them: the
// red, green and blue channels as the stream states them (LAS: 16-bit fields holding 8- or
// 16-bit levels; text: 0-255 levels or fractions), whose full scale the stream's ColorScale
// tells from the largest channel of its first points.
struct StreamedPoints {
  std::vector<Vec3> positions;
  std::vector<std::array<float, 3>> colors;  // Empty, or one per position.

  size_t size() const { return positions.size(); }
  void clear() {
    positions.clear();
    colors.clear();
  }
};

class PointStream {
 public:
  virtual ~PointStream() = default;

  // Appends the points that have arrived to `points`, waiting up to `wait` for a first byte
  // when none is there. Returns whether the stream goes on (false once it ended).
  // INVALID_ARGUMENT, naming the stream and where in it, for content that is not points of its
  // format; UNAVAILABLE for a read that fails.
  virtual absl::StatusOr<bool> Read(absl::Duration wait, StreamedPoints* points) = 0;

  // The full scale of the colour channels of points whose largest channel is `largest`, for
  // ChannelFromLevel (core/rgb.h): LAS's LevelScale, text's TextChannelScale.
  virtual double ColorScale(float largest) const = 0;
  // The stream's name in messages ("standard input").
  virtual const std::string& name() const = 0;
  // What has been read so far, for messages: "12 lines", "3 LAS records".
  virtual std::string ReadSoFar() const = 0;
};

// The bytes one wait on a descriptor gave: none when nothing came within the wait.
struct StreamBytes {
  absl::string_view bytes;
  bool ended = false;  // The descriptor reached its end (no bytes then).
};

// Waits up to `wait` for bytes on `fd` and reads those there into `buffer` (of `capacity`
// bytes). UNAVAILABLE, naming the stream `name`, for a failed poll or read.
absl::StatusOr<StreamBytes> ReadStreamBytes(int fd, absl::Duration wait, const std::string& name,
                                            char* buffer, size_t capacity);

// A stream of a file descriptor's bytes read in its format: Read waits for them and hands them
// to Take as they arrive, and the end to End.
class DescriptorPointStream : public PointStream {
 public:
  absl::StatusOr<bool> Read(absl::Duration wait, StreamedPoints* points) final;
  const std::string& name() const final { return name_; }

 protected:
  // The stream of `fd` (not closed here), named `name` in messages ("standard input");
  // `first_bytes`: its bytes read already (OpenPointStream's, to tell its format), taken first.
  DescriptorPointStream(int fd, std::string name, std::string first_bytes)
      : fd_(fd), name_(std::move(name)), pending_(std::move(first_bytes)) {}

  // Takes the bytes that arrived next: the points they complete.
  virtual absl::Status Take(absl::string_view bytes, StreamedPoints* points) = 0;
  // The stream ended: takes what is left, or refuses it.
  virtual absl::Status End(StreamedPoints* points) = 0;

 private:
  int fd_;
  std::string name_;
  std::string pending_;  // Bytes read before the stream's format was known.
  bool ended_ = false;
};

// The stream of `fd` (not closed here), named `name`: LAS when its first bytes are a LAS
// file's signature ("LASF"), else text. The format is decided by the first Read calls, once
// four bytes (or the end) have come. With `las_classes`, a LAS stream gives the points of those
// classes (as reading the file with them: point_selection.h), and a text stream is refused
// (INVALID_ARGUMENT), having no classes to choose from.
std::unique_ptr<PointStream> OpenPointStream(int fd, std::string name,
                                             std::optional<LasClasses> las_classes = std::nullopt);

// Where points of a stream should be taken relative to, from the box of its first points: the
// origin reading an XYZ file of them chooses (PositionCollector's rule), so that
// georeferenced coordinates keep their precision as floats.
Origin OriginOfStreamedPoints(const BoundingBox& first_points);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_POINT_STREAM_H_
