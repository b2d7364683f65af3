#include "core/io/point_stream.h"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/las.h"
#include "core/io/internal/las_layout.h"
#include "core/io/internal/laz.h"
#include "core/io/internal/position_collector.h"
#include "core/io/point_text_stream.h"
#include "core/rgb.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

using io_internal::LoadScalar;
namespace las_layout = io_internal::las_layout;

// The most bytes a LAS stream's header and variable-length records may take before its
// records: real ones hold a few kilobytes of coordinate system.
constexpr size_t kLongestLasHeader = size_t{64} << 20;

// A LAS file's header and point records as they arrive (LasPointStream in point_stream.h):
// each complete record is read as reading the file whole reads it (io_internal::LasRecords:
// withheld records left out, and those of other classes than `classes`, or without them those
// classified as noise), with its colour levels in formats with colours, up to the number of
// records the header states (what follows them, LAS 1.3's waveform packets or LAS 1.4's
// extended variable-length records, is not read). A stream that ends before them is an error;
// a header that states none (a writer that did not know how many would come) is read to the
// stream's end. A LAZ stream's chunks are decoded as each arrives whole (LazStreamDecoder).
class LasPointStream final : public DescriptorPointStream {
 public:
  LasPointStream(int fd, std::string name, std::string first_bytes,
                 std::optional<LasClasses> classes)
      : DescriptorPointStream(fd, std::move(name), std::move(first_bytes)),
        classes_(std::move(classes)) {}

  std::string ReadSoFar() const override {
    return absl::StrCat(records_read_, records_read_ == 1 ? " LAS record" : " LAS records");
  }
  double ColorScale(float largest) const override {
    return LevelScale(static_cast<uint16_t>(std::clamp(largest, 0.0f, 65535.0f)));
  }

 private:
  absl::Status Invalid(absl::string_view why) const {
    return absl::InvalidArgumentError(absl::StrCat(name(), ": ", why));
  }

  // A stream that ends within its header or a record, or before the records its header
  // states, is cut short.
  absl::Status End(StreamedPoints* points) override {
    if (laz_.has_value() && records_left_ > 0)
      NM_RETURN_IF_ERROR(TakeChunks(/*ended=*/true, points));
    if (record_length_ == 0) {
      return Invalid(absl::StrCat("ended within the LAS header, after ", header_.size(), " bytes"));
    }
    if (!records_.empty() && records_left_ > 0) {
      return Invalid(absl::StrCat("ended within LAS record ", records_read_ + 1, " (",
                                  records_.size(), " of its ", record_length_, " bytes)"));
    }
    if (stated_records_ > 0 && records_left_ > 0) {
      return Invalid(absl::StrCat("ended after ", records_read_, " of the ", stated_records_,
                                  " LAS records its header states"));
    }
    return absl::OkStatus();
  }

  // Takes the stream's next bytes: the header's, then records'.
  absl::Status Take(absl::string_view bytes, StreamedPoints* points) override {
    if (record_length_ == 0) {
      NM_RETURN_IF_ERROR(TakeHeader(&bytes));
      if (record_length_ == 0) return absl::OkStatus();
    }
    if (records_left_ == 0) return absl::OkStatus();  // What follows the records is not read.
    if (laz_.has_value()) {
      compressed_.append(bytes.data(), bytes.size());
      return TakeChunks(/*ended=*/false, points);
    }
    records_.append(bytes.data(), bytes.size());
    return TakeRecords(points);
  }

  // Decodes the LAZ chunks that have come whole (all that are left once the stream `ended`).
  // A chunk's end is known once it decodes, so it is first tried once the bytes of the chunk
  // before it and a little more have come, in proportion to their records (chunks of a scan
  // compress alike), then each time a quarter more have: most chunks decode at the first try.
  // The last of several, whose records are fewer, is followed by a few bytes only (the chunk
  // table, and LAS 1.4's extended records): it is tried again as each piece of the stream
  // arrives, so that its points do not wait for the stream's end (a chunk of at most the
  // others' records, its first try near its size; a file of one chunk keeps the quarters, which
  // bound the decoding of a large chunk to a few times its bytes).
  absl::Status TakeChunks(bool ended, StreamedPoints* points) {
    // A stream that ends between chunks is cut short (End says where).
    while (laz_->records_left() > 0 &&
           (ended ? !compressed_.empty() : compressed_.size() >= next_attempt_)) {
      // Decoded after the records not read yet (none: a LAZ stream's come in whole chunks).
      const uint64_t left = laz_->records_left();
      absl::StatusOr<size_t> taken = laz_->DecodeNext(compressed_, ended, &records_);
      if (!taken.ok()) return Invalid(taken.status().message());
      if (*taken == 0) {
        const bool last_of_several =
            laz_->last_chunk_next() && laz_->records_left() < stated_records_;
        next_attempt_ = compressed_.size() +
                        (last_of_several ? 1 : std::max<size_t>(compressed_.size() / 4, 4096));
        break;
      }
      compressed_.erase(0, *taken);
      const uint64_t decoded = left - laz_->records_left();
      next_attempt_ = static_cast<size_t>((*taken + *taken / 32) *
                                          std::min(decoded, laz_->records_left()) / decoded);
      NM_RETURN_IF_ERROR(TakeRecords(points));
    }
    if (laz_->records_left() == 0) std::string().swap(compressed_);  // The chunk table, ...
    return absl::OkStatus();
  }

  // The header the records are read with: a LAZ stream's is that of the LAS file it holds.
  const std::string& RecordsHeader() const {
    return laz_.has_value() ? laz_->las_header() : header_;
  }

  // Gathers the header and its variable-length records; once they are complete, checks them
  // as reading the file checks them and sets record_length_. Moves `bytes` past what it took.
  absl::Status TakeHeader(absl::string_view* bytes) {
    const size_t wanted = offset_to_points_ > 0 ? offset_to_points_ : las_layout::kLegacyHeaderSize;
    const size_t take = std::min(bytes->size(), wanted - header_.size());
    header_.append(bytes->data(), take);
    bytes->remove_prefix(take);
    if (header_.size() < wanted) return absl::OkStatus();
    if (offset_to_points_ == 0) {
      offset_to_points_ = LoadScalar<uint32_t>(header_.data() + las_layout::kOffsetToPoints, false);
      if (offset_to_points_ > kLongestLasHeader) {
        return Invalid(absl::StrCat("the LAS header says its records start after ",
                                    offset_to_points_, " bytes; at most ", kLongestLasHeader,
                                    " are read"));
      }
      if (offset_to_points_ > header_.size()) return TakeHeader(bytes);
    }
    if ((static_cast<uint8_t>(header_[las_layout::kPointFormat]) & las_layout::kCompressedBits) !=
        0) {
      absl::StatusOr<io_internal::LazStreamDecoder> laz =
          io_internal::LazStreamDecoder::Create(header_);
      if (!laz.ok()) return Invalid(laz.status().message());
      laz_ = *std::move(laz);
    }
    absl::StatusOr<std::unique_ptr<io_internal::LasRecords>> checked =
        io_internal::LasRecords::Create(RecordsHeader(), absl::string_view(), classes_);
    if (!checked.ok()) return Invalid(checked.status().message());
    record_length_ = LoadScalar<uint16_t>(header_.data() + las_layout::kRecordLength, false);
    if (record_length_ == 0) return Invalid("the LAS header gives records of 0 bytes");
    // The records the header states (as reading the file counts them: LAS 1.4's count where it
    // gives one, else the legacy one), and at most those before LAS 1.4's extended
    // variable-length records.
    stated_records_ = LoadScalar<uint32_t>(header_.data() + las_layout::kLegacyPointCount, false);
    const bool las14 =
        static_cast<uint8_t>(header_[las_layout::kVersionMinor]) >= 4 &&
        LoadScalar<uint16_t>(header_.data() + las_layout::kHeaderSize, false) >=
            las_layout::kHeaderSize14;
    if (las14) {
      const uint64_t count14 =
          LoadScalar<uint64_t>(header_.data() + las_layout::kPointCount, false);
      if (count14 != 0) stated_records_ = count14;
    }
    if (stated_records_ > 0) records_left_ = stated_records_;
    if (las14 && !laz_.has_value()) {  // A LAZ file's extended records follow its chunk table.
      const uint64_t evlr_start =
          LoadScalar<uint64_t>(header_.data() + las_layout::kEvlrStart, false);
      const uint32_t evlrs =
          LoadScalar<uint32_t>(header_.data() + las_layout::kEvlrStart + 8, false);
      if (evlrs > 0 && evlr_start >= offset_to_points_) {
        records_left_ =
            std::min<uint64_t>(records_left_, (evlr_start - offset_to_points_) / record_length_);
      }
    }
    return absl::OkStatus();
  }

  // Reads the complete records gathered in records_, keeping a partial one for later.
  absl::Status TakeRecords(StreamedPoints* points) {
    const uint64_t complete = std::min<uint64_t>(records_.size() / record_length_, records_left_);
    if (complete == 0) return absl::OkStatus();
    absl::StatusOr<std::unique_ptr<io_internal::LasRecords>> records =
        io_internal::LasRecords::Create(
            RecordsHeader(), absl::string_view(records_.data(), complete * record_length_),
            classes_);
    if (!records.ok()) return Invalid(records.status().message());
    for (uint64_t i = 0; i < complete; ++i) {
      const std::optional<io_internal::Point3d> p = (*records)->KeptPoint(i);
      if (!p.has_value()) continue;
      if (!std::isfinite((*p)[0]) || !std::isfinite((*p)[1]) || !std::isfinite((*p)[2])) continue;
      points->positions.emplace_back((*p)[0], (*p)[1], (*p)[2]);
      if (const auto levels = (*records)->ColorLevels(i); levels.has_value()) {
        points->colors.push_back({static_cast<float>((*levels)[0]),
                                  static_cast<float>((*levels)[1]),
                                  static_cast<float>((*levels)[2])});
      }
    }
    records_read_ += complete;
    records_left_ -= complete;
    records_.erase(0, records_left_ == 0 ? records_.size() : complete * record_length_);
    return absl::OkStatus();
  }

  std::string header_;           // The header and variable-length records, as far as they came.
  size_t offset_to_points_ = 0;  // Once the legacy header has come.
  size_t record_length_ = 0;     // Once the whole header has come and passed its checks.
  uint64_t stated_records_ = 0;  // By the header; 0: not stated.
  uint64_t records_left_ = std::numeric_limits<uint64_t>::max();
  std::string records_;  // Records not read yet: a partial one at most between reads.
  uint64_t records_read_ = 0;
  const std::optional<LasClasses> classes_;
  std::optional<io_internal::LazStreamDecoder> laz_;  // For a LAZ stream.
  std::string compressed_;   // A LAZ stream's bytes after its last chunk decoded.
  size_t next_attempt_ = 0;  // The bytes in compressed_ before a chunk is tried (again).
};

// A stream whose format its first four bytes tell (OpenPointStream).
class DetectedPointStream final : public PointStream {
 public:
  DetectedPointStream(int fd, std::string name, std::optional<LasClasses> las_classes)
      : fd_(fd), name_(std::move(name)), las_classes_(std::move(las_classes)) {}

  absl::StatusOr<bool> Read(absl::Duration wait, StreamedPoints* points) override {
    if (stream_ == nullptr) {
      char buffer[4];
      NM_ASSIGN_OR_RETURN(const StreamBytes got,
                          ReadStreamBytes(fd_, wait, name_, buffer, 4 - first_bytes_.size()));
      first_bytes_.append(got.bytes.data(), got.bytes.size());
      if (first_bytes_.size() < 4 && !got.ended) return true;
      if (absl::StartsWith(first_bytes_, "LASF")) {
        stream_ =
            std::make_unique<LasPointStream>(fd_, name_, std::move(first_bytes_), las_classes_);
      } else if (las_classes_.has_value()) {
        return absl::InvalidArgumentError(
            absl::StrCat(name_,
                         ": text, whose points have no LAS classes to choose from; "
                         "classes choose the records of a LAS stream"));
      } else {
        stream_ = std::make_unique<PointTextStream>(fd_, name_, std::move(first_bytes_));
      }
      wait = absl::ZeroDuration();  // The bytes read are taken at once.
    }
    return stream_->Read(wait, points);
  }

  const std::string& name() const override { return name_; }
  std::string ReadSoFar() const override {
    return stream_ != nullptr ? stream_->ReadSoFar() : "0 lines";
  }
  double ColorScale(float largest) const override {
    return stream_ != nullptr ? stream_->ColorScale(largest) : TextChannelScale(largest);
  }

 private:
  int fd_;
  std::string name_;
  const std::optional<LasClasses> las_classes_;
  std::string first_bytes_;
  std::unique_ptr<PointStream> stream_;  // Once the format is known.
};

}  // namespace

absl::StatusOr<StreamBytes> ReadStreamBytes(int fd, absl::Duration wait, const std::string& name,
                                            char* buffer, size_t capacity) {
  pollfd ready{fd, POLLIN, 0};
  const int waited = poll(&ready, 1, static_cast<int>(absl::ToInt64Milliseconds(wait)));
  if (waited < 0 && errno != EINTR) {
    return absl::UnavailableError(absl::StrCat("cannot read ", name, ": ", strerror(errno)));
  }
  if (waited <= 0) return StreamBytes{};
  const ssize_t got = read(fd, buffer, capacity);
  if (got < 0) {
    if (errno == EINTR || errno == EAGAIN) return StreamBytes{};
    return absl::UnavailableError(absl::StrCat("cannot read ", name, ": ", strerror(errno)));
  }
  if (got == 0) return StreamBytes{absl::string_view(), true};
  return StreamBytes{absl::string_view(buffer, static_cast<size_t>(got)), false};
}

absl::StatusOr<bool> DescriptorPointStream::Read(absl::Duration wait, StreamedPoints* points) {
  if (ended_) return false;
  if (!pending_.empty()) {
    const std::string first_bytes = std::move(pending_);
    pending_.clear();
    NM_RETURN_IF_ERROR(Take(first_bytes, points));
    return true;
  }
  char buffer[1 << 16];
  NM_ASSIGN_OR_RETURN(const StreamBytes got,
                      ReadStreamBytes(fd_, wait, name_, buffer, sizeof(buffer)));
  if (got.ended) {
    ended_ = true;
    NM_RETURN_IF_ERROR(End(points));
    return false;
  }
  NM_RETURN_IF_ERROR(Take(got.bytes, points));
  return true;
}

std::unique_ptr<PointStream> OpenPointStream(int fd, std::string name,
                                             std::optional<LasClasses> las_classes) {
  return std::make_unique<DetectedPointStream>(fd, std::move(name), std::move(las_classes));
}

Origin OriginOfStreamedPoints(const BoundingBox& first_points) {
  const Vec3& low = first_points.min;
  const Vec3& high = first_points.max;
  return io_internal::OriginOfUnstatedResolution({low[0], low[1], low[2]},
                                                 {high[0], high[1], high[2]});
}

}  // namespace neuralmesh
