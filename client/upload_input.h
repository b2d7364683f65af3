// What `neuralmesh reconstruct --server` uploads: its INPUT read whole, a file read where it
// lies (--off_core), or points streamed from standard input ('-'), with what the session is
// told of them before the first batch.
#ifndef NEURALMESH_CLIENT_UPLOAD_INPUT_H_
#define NEURALMESH_CLIENT_UPLOAD_INPUT_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>

#include "absl/status/statusor.h"
#include "client/point_upload.h"
#include "client/remote_commands.h"
#include "core/bounding_box.h"
#include "core/io/mapped_laz_file.h"
#include "core/io/mapped_point_file.h"
#include "core/origin.h"
#include "core/point_cloud.h"

namespace neuralmesh::client {

// What an upload sends, and what the session is told of it before the first batch.
struct UploadInput {
  std::unique_ptr<PointCloud> cloud;      // The points, read whole (not off-core).
  std::unique_ptr<MappedPointFile> file;  // Off-core: the file, read where it lies,
  std::unique_ptr<MappedLazFile> laz;     // or a LAZ file's, a chunk at a time.
  std::unique_ptr<PointUpload> points;    // Of `cloud`, `file` or `laz`, or streamed.
  Origin origin = kNoOrigin;
  // Where the points lie, when that is known before the upload.
  std::optional<BoundingBox> bounds;
  // The points to send; off-core an estimate (the records times the share of the probe's that
  // are points), as `estimated` says; unknown (0) for points streamed from standard input.
  uint64_t size = 0;
  bool estimated = false;
  bool streamed = false;
};

// The input of `options`: read whole (outliers removed when the client removes them, colours
// dropped unless asked for), off-core its one file mapped, or standard input streamed (its
// first batch waited for); what was done is said on `out`. The loaders' errors, and
// INVALID_ARGUMENT, saying why, for flags the way does not take (standard input: --off_core,
// --resume, --remove_outliers without --outliers_on_server, other INPUTs beside it).
absl::StatusOr<UploadInput> LoadUploadInput(const RemoteReconstructOptions& options,
                                            bool outliers_on_server, std::ostream& out);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_UPLOAD_INPUT_H_
