#include "core/io/internal/las_file_writer.h"

#include <cstdint>

#include "absl/strings/str_cat.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/las_layout.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

using namespace las_layout;  // NOLINT: the header's field offsets.

uint16_t RecordLength(absl::string_view head) {
  return LoadScalar<uint16_t>(head.data() + kRecordLength, /*big_endian=*/false);
}

}  // namespace

absl::Status CheckLasHead(absl::string_view head) {
  if (head.size() < kLegacyHeaderSize || head.substr(0, 4) != "LASF") {
    return absl::InvalidArgumentError(
        absl::StrCat("LAS: a head of ", head.size(), " bytes is no LAS header"));
  }
  const uint32_t points_at = LoadScalar<uint32_t>(head.data() + kOffsetToPoints, false);
  if (points_at != head.size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "LAS: a head of ", head.size(), " bytes says the points start at byte ", points_at));
  }
  if (RecordLength(head) == 0) return absl::InvalidArgumentError("LAS: records of 0 bytes");
  return absl::OkStatus();
}

absl::Status CheckFinishingLasHead(absl::string_view head, absl::string_view started) {
  NM_RETURN_IF_ERROR(CheckLasHead(head));
  if (head.size() != started.size() || head[kPointFormat] != started[kPointFormat] ||
      RecordLength(head) != RecordLength(started)) {
    return absl::InvalidArgumentError(
        "LAS: the finished file's head has another size, point format or record length than "
        "the head it started with");
  }
  return absl::OkStatus();
}

absl::Status LasFileWriter::WriteHeadOnce(absl::string_view head) {
  if (head_written_) return absl::OkStatus();
  head_written_ = true;
  start_ = out_->size();
  return out_->Append(head);
}

absl::Status PlainLasWriter::Start(absl::string_view head) {
  NM_RETURN_IF_ERROR(CheckLasHead(head));
  started_ = std::string(head);
  return absl::OkStatus();
}

absl::Status PlainLasWriter::AppendRecords(absl::string_view records) {
  if (records.size() % RecordLength(started_) != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "LAS: ", records.size(), " bytes are not records of ", RecordLength(started_), " bytes"));
  }
  NM_RETURN_IF_ERROR(WriteHeadOnce(started_));
  return out_->Append(records);
}

absl::Status PlainLasWriter::Finish(absl::string_view head, absl::string_view tail) {
  NM_RETURN_IF_ERROR(CheckFinishingLasHead(head, started_));
  NM_RETURN_IF_ERROR(WriteHeadOnce(started_));
  NM_RETURN_IF_ERROR(out_->Append(tail));
  return out_->Patch(start_, head);
}

}  // namespace neuralmesh::io_internal
