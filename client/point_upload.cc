#include "client/point_upload.h"

#include <algorithm>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/status_macros.h"
#include "proto/packing.h"

namespace neuralmesh::client {

absl::Status CloudUpload::SkipTo(uint64_t first) {
  if (first > cloud_.size()) {
    return absl::OutOfRangeError(
        absl::StrCat("the upload cannot start at point ", first, " of ", cloud_.size()));
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::PointBatch> CloudUpload::Batch(uint64_t first, size_t count) {
  NM_RETURN_IF_ERROR(SkipTo(first));
  const uint64_t end = std::min<uint64_t>(cloud_.size(), first + count);
  done_ = end;
  return PackPointBatch(cloud_, first, end);
}

std::optional<uint64_t> FileRecordsUpload::size() const {
  if (slot_ < order_.slots()) return std::nullopt;
  return points_;
}

template <typename OnPoint>
void FileRecordsUpload::ReadNext(const OnPoint& on_point) {
  const uint64_t record = order_[slot_++];
  if (record >= file_.records()) return;
  if (const std::optional<Vec3> point = file_.Point(record); point.has_value()) {
    ++points_;
    on_point(*point);
  }
}

absl::Status FileRecordsUpload::SkipTo(uint64_t first) {
  if (first < points_) {
    slot_ = 0;
    points_ = 0;
  }
  while (points_ < first && slot_ < order_.slots()) ReadNext([](const Vec3&) {});
  if (points_ < first) {
    return absl::OutOfRangeError(
        absl::StrCat("the upload cannot start at point ", first, " of ", points_));
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::PointBatch> FileRecordsUpload::Batch(uint64_t first, size_t count) {
  NM_RETURN_IF_ERROR(SkipTo(first));
  std::string positions;
  positions.reserve(count * sizeof(Vec3f));
  const uint64_t end = first + count;
  while (points_ < end && slot_ < order_.slots()) {
    ReadNext([&positions](const Vec3& p) {
      const Vec3f f(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
      positions.append(reinterpret_cast<const char*>(f.data()), sizeof(Vec3f));
    });
  }
  v1::PointBatch batch;
  batch.mutable_first_point()->set_value(first);
  batch.mutable_packed()->set_positions(std::move(positions));
  return batch;
}

}  // namespace neuralmesh::client
