// The streams of standard input (core/io/point_stream.h): bytes arriving through a pipe in
// pieces of any size, text or LAS, with or without LAS classes chosen. The input's first byte
// sets the pieces' size and whether classes are chosen, the rest is the stream. Properties:
// a stream ends or is refused with INVALID_ARGUMENT, never another error or a crash; its
// points are finite, with one colour each or none; and a LAS stream read without classes
// whose header states its records gives the points reading its bytes as a file gives
// (ParseLas), or the first of them where LAS 1.4's extended records start earlier (a header
// that states none is read to the stream's end, a file of it has no points); a LAZ stream
// decoded chunk by chunk as it arrives gives every point of the file.
#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "absl/strings/match.h"
#include "absl/strings/string_view.h"
#include "absl/time/time.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "core/io/point_selection.h"
#include "core/io/point_stream.h"
#include "fuzz/fuzz_check.h"

namespace {

using neuralmesh::StreamedPoints;

// Reads `bytes` through a pipe in pieces of `piece` bytes, a read after each, then to the end.
absl::Status ReadThroughPipe(absl::string_view bytes, size_t piece,
                             const std::optional<neuralmesh::LasClasses>& classes,
                             StreamedPoints* points) {
  int fds[2];
  FUZZ_CHECK(pipe(fds) == 0, "no pipe");
  std::unique_ptr<neuralmesh::PointStream> stream =
      neuralmesh::OpenPointStream(fds[0], "the stream", classes);
  absl::Status status;
  for (size_t at = 0; at < bytes.size() && status.ok(); at += piece) {
    const absl::string_view part = bytes.substr(at, piece);
    FUZZ_CHECK(write(fds[1], part.data(), part.size()) == static_cast<ssize_t>(part.size()),
               "a piece of %zu bytes did not fit in the pipe", part.size());
    // Until what was written is taken (a LAS stream's first read only tells its format).
    for (int k = 0; k < 3 && status.ok(); ++k) {
      status = stream->Read(absl::ZeroDuration(), points).status();
    }
  }
  close(fds[1]);
  bool more = status.ok();
  for (int k = 0; more && k < 1000; ++k) {
    absl::StatusOr<bool> read = stream->Read(absl::Milliseconds(10), points);
    status = read.status();
    more = read.ok() && *read;
  }
  FUZZ_CHECK(!more, "the stream did not end");
  close(fds[0]);
  return status;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const size_t piece = 1 + (data[0] & 0x7f) * 31;  // 1 to 3,938 bytes: within a pipe's buffer.
  std::optional<neuralmesh::LasClasses> classes;
  if ((data[0] & 0x80) != 0) classes = neuralmesh::LasClasses().set(2).set(6);
  const absl::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);

  StreamedPoints points;
  const absl::Status status = ReadThroughPipe(bytes, piece, classes, &points);
  FUZZ_CHECK(status.ok() || status.code() == absl::StatusCode::kInvalidArgument,
             "a stream failed otherwise than as invalid: %s", status.ToString().c_str());
  FUZZ_CHECK(status.ok() || absl::StartsWith(status.message(), "the stream"),
             "an error that does not name the stream: %s", status.ToString().c_str());
  FUZZ_CHECK(points.colors.empty() || points.colors.size() == points.size(),
             "%zu points with %zu colours", points.size(), points.colors.size());
  for (const neuralmesh::Vec3& p : points.positions) {
    FUZZ_CHECK(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]),
               "a point not finite");
  }
  if (!status.ok() || classes.has_value() || !absl::StartsWith(bytes, "LASF")) return 0;
  const absl::StatusOr<neuralmesh::io_internal::ParsedGeometry> parsed =
      neuralmesh::io_internal::ParseLas(bytes);
  // Points beyond a float's range from the origin the file's range chooses are left out of
  // the file and not of the stream, which chooses its origin later (StreamUpload).
  if (!parsed.ok() || parsed->left_out.invalid > 0) return 0;
  const bool laz = neuralmesh::io_internal::IsLaz(bytes);
  absl::StatusOr<uint64_t> stated;
  if (laz) {
    const absl::StatusOr<neuralmesh::io_internal::LazChunks> chunks =
        neuralmesh::io_internal::LazChunks::Open(bytes);
    stated = chunks.ok() ? absl::StatusOr<uint64_t>(chunks->records()) : chunks.status();
  } else {
    stated = neuralmesh::io_internal::LasRecordCount(bytes);
  }
  if (!stated.ok() || *stated == 0) return 0;
  // A LAZ stream decodes every record its header states, as the file does.
  FUZZ_CHECK(!laz || points.size() == parsed->positions.size(),
             "the LAZ stream gave %zu points, the file %zu", points.size(),
             parsed->positions.size());
  FUZZ_CHECK(points.size() <= parsed->positions.size(), "the stream gave %zu points, the file %zu",
             points.size(), parsed->positions.size());
  for (size_t i = 0; i < points.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const float relative = static_cast<float>(points.positions[i][c] - parsed->origin[c]);
      FUZZ_CHECK(relative == parsed->positions[i][c], "point %zu: %.9g in the stream, %.9g read", i,
                 relative, parsed->positions[i][c]);
    }
  }
  return 0;
}
