// The points an upload sends, in the order it sends them, batch by batch: a point cloud in
// memory (CloudUpload), or the records of a file read where they lie, never whole
// (`neuralmesh reconstruct --server --off_core`: FileRecordsUpload for uncompressed LAS, binary
// PLY and binary PCD, LazFileUpload for LAZ).
#ifndef NEURALMESH_CLIENT_POINT_UPLOAD_H_
#define NEURALMESH_CLIENT_POINT_UPLOAD_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/io/mapped_laz_file.h"
#include "core/io/mapped_point_file.h"
#include "core/io/point_stream.h"
#include "core/io/spread_order.h"
#include "core/point_cloud.h"
#include "neuralmesh/v1/reconstruction.pb.h"

namespace neuralmesh::client {

class PointUpload {
 public:
  virtual ~PointUpload() = default;

  // Makes point `first` the next one Batch packs. OUT_OF_RANGE when the upload has fewer
  // than `first` points (its size() is then known).
  virtual absl::Status SkipTo(uint64_t first) = 0;
  // Points first, first + 1, ... of the upload, at most `count` (> 0) of them, as a batch
  // that says where it starts (PointBatch.first_point = first); a batch without points when
  // the upload has no point past `first`. SkipTo's errors.
  virtual absl::StatusOr<v1::PointBatch> Batch(uint64_t first, size_t count) = 0;
  // How far the batches so far went, and out of how much (points, or a file's records).
  virtual uint64_t done() const = 0;
  virtual uint64_t total() const = 0;
  // The upload's number of points, where it is known.
  virtual std::optional<uint64_t> size() const = 0;
  // The order the batches go in (v1::UploadOrder), for the session to keep: a resumed upload
  // must go in the same one, over the same number of items, from the same first points (the
  // order's fingerprint). Reads those points: Batch's errors.
  virtual absl::StatusOr<v1::UploadOrder> DescribeOrder() = 0;

  // The points an order's fingerprint is taken of: the upload's first ones.
  static constexpr size_t kFingerprintPoints = 1024;

 protected:
  // An UploadOrder of `items` named `name`, with the fingerprint of this upload's first
  // kFingerprintPoints points (OrderFingerprint). Batch's errors.
  absl::StatusOr<v1::UploadOrder> FingerprintedOrder(absl::string_view name, uint64_t items);
};

// An UploadOrder of `items` named `name`, without a fingerprint.
v1::UploadOrder MakeUploadOrder(absl::string_view name, uint64_t items);

// The fingerprint of an order whose first batch of PointUpload::kFingerprintPoints points
// packs positions `positions` (PackedPoints.positions): their 64-bit FNV-1a hash.
uint64_t OrderFingerprint(absl::string_view positions);

// A cloud's points with the weights, normals and colours it carries, in their stored order or
// in SpreadOrder (blocks of consecutive points visited along the golden ratio), where every
// prefix of the upload is spread over the whole cloud: a scan read whole, stored strip by
// strip, then reaches the server as a file read where it lies does (FileRecordsUpload).
class CloudUpload final : public PointUpload {
 public:
  enum class Order { kStored, kSpread };

  explicit CloudUpload(const PointCloud& cloud, Order order)
      : cloud_(cloud),
        spread_(order == Order::kSpread),
        order_(cloud.size(), spread_ ? SpreadOrder::kBlockRecords
                                     : std::max<uint64_t>(cloud.size(), 1)) {}  // One block.

  absl::Status SkipTo(uint64_t first) override;
  absl::StatusOr<v1::PointBatch> Batch(uint64_t first, size_t count) override;
  uint64_t done() const override { return done_; }
  uint64_t total() const override { return cloud_.size(); }
  std::optional<uint64_t> size() const override { return cloud_.size(); }
  // "points-spread-256" or "points-stored", of the cloud's points.
  absl::StatusOr<v1::UploadOrder> DescribeOrder() override {
    return FingerprintedOrder(spread_ ? "points-spread-256" : "points-stored", cloud_.size());
  }

 private:
  const PointCloud& cloud_;
  const bool spread_;
  const SpreadOrder order_;  // Of one block unless spread_.
  uint64_t done_ = 0;
};

// The points of a file's records (MappedPointFile::Point, relative to its origin), read where
// they lie in SpreadOrder, so that every prefix of the upload is spread over the whole file.
// With `colors`, their colours too where the file has them (MappedPointFile::Color). Each batch
// reads its records once; to skip back, the order is walked again from its start (resuming an
// upload reads the records before its first point again).
class FileRecordsUpload final : public PointUpload {
 public:
  explicit FileRecordsUpload(const MappedPointFile& file, bool colors = false)
      : file_(file), order_(file.records()), colors_(colors && file.has_colors()) {}

  absl::Status SkipTo(uint64_t first) override;
  absl::StatusOr<v1::PointBatch> Batch(uint64_t first, size_t count) override;
  // Records read (and skipped, at a resume) so far.
  uint64_t done() const override { return std::min(slot_, file_.records()); }
  uint64_t total() const override { return file_.records(); }
  // Known once the order has been walked to its end.
  std::optional<uint64_t> size() const override;
  // "file-records-spread-256", of the file's records.
  absl::StatusOr<v1::UploadOrder> DescribeOrder() override {
    return FingerprintedOrder("file-records-spread-256", file_.records());
  }

 private:
  // Reads the record at slot_ and moves on; gives `on_point` the record's point and number, if
  // it is one.
  template <typename OnPoint>
  void ReadNext(const OnPoint& on_point);

  const MappedPointFile& file_;
  const SpreadOrder order_;
  const bool colors_;
  uint64_t slot_ = 0;                // The next position of order_ to read.
  uint64_t block_first_record_ = 0;  // The first record of slot_'s block, once slot_ is in it.
  uint64_t points_ = 0;              // The points among the positions before slot_.
};

// The points of a LAZ file's chunks (MappedLazFile::Points), decoded a wave of kWaveChunks at
// a time: the waves take the chunks in SpreadOrder, and a wave's points go out in blocks of
// SpreadOrder::kBlockRecords taken from its chunks in turn, so that every prefix of the upload
// is spread over the file, the first batch over a wave's chunks. The order depends on the file
// alone (not on the threads that decode a wave). With `colors`, the points' colours too where
// the file has them. To skip back, the waves are decoded again from the first (resuming an
// upload decodes the chunks before its first point again).
class LazFileUpload final : public PointUpload {
 public:
  static constexpr size_t kWaveChunks = 8;

  explicit LazFileUpload(const MappedLazFile& file, bool colors = false)
      : file_(file),
        order_(file.chunks(), /*block_records=*/1),
        colors_(colors && file.has_colors()) {}

  absl::Status SkipTo(uint64_t first) override;
  absl::StatusOr<v1::PointBatch> Batch(uint64_t first, size_t count) override;
  // The records of the chunks decoded so far.
  uint64_t done() const override { return records_done_; }
  uint64_t total() const override { return file_.records(); }
  // Known once the last wave is decoded.
  std::optional<uint64_t> size() const override;
  // "laz-chunks-spread-8", of the file's records (its first wave holds the first points).
  absl::StatusOr<v1::UploadOrder> DescribeOrder() override {
    return FingerprintedOrder("laz-chunks-spread-8", file_.records());
  }

 private:
  // Decodes the next wave into wave_ (the chunks on several threads); false after the last.
  absl::StatusOr<bool> NextWave();

  const MappedLazFile& file_;
  const SpreadOrder order_;  // Of the chunks.
  const bool colors_;
  size_t next_chunk_ = 0;         // The next position of order_ to decode.
  std::vector<Vec3f> wave_;       // The points of the last wave decoded, in upload order,
  std::vector<Rgb> wave_colors_;  // and their colours (with colors_).
  uint64_t wave_first_ = 0;       // The upload's number of wave_'s first point.
  uint64_t records_done_ = 0;
};

// Points as they arrive on a stream (PointStream: text lines or a LAS file's records on
// standard input, `neuralmesh reconstruct - --server`), kept in memory as they come so that a batch
// can be sent again after a lost connection. A batch goes out as soon as it is full, or once
// `flush_after` has passed with points to send, so a slow stream's points reach the server within
// that time. Positions relative to an origin chosen from the first batch (Start); with `colors`,
// the colours of a stream whose points carry them, their scale (LAS: 8- or 16-bit levels; text:
// levels or fractions: PointStream::ColorScale) judged from the first batch's largest channel,
// as an upload off-core judges it from its probe.
class StreamUpload final : public PointUpload {
 public:
  static constexpr absl::Duration kFlushAfter = absl::Milliseconds(100);

  explicit StreamUpload(std::unique_ptr<PointStream> stream, bool colors = false,
                        absl::Duration flush_after = kFlushAfter)
      : stream_(std::move(stream)), flush_after_(flush_after), colors_wanted_(colors) {}

  // Waits for the first batch (`count` points, or fewer once flush_after has passed or the
  // stream ended), chooses the origin from it (OriginOfStreamedPoints) and, with colours
  // wanted, their scale. INVALID_ARGUMENT when the stream ends without a point; the stream's
  // errors; CANCELLED on an interrupt (InterruptScope).
  absl::Status Start(size_t count);
  const Origin& origin() const { return origin_; }
  // Whether the batches carry colours: wanted, and the first batch's points had them.
  bool has_colors() const { return color_scale_ > 0; }

  // Start's errors, and INVALID_ARGUMENT for a point beyond a float's range from the origin.
  absl::Status SkipTo(uint64_t first) override;
  absl::StatusOr<v1::PointBatch> Batch(uint64_t first, size_t count) override;
  // The points read so far, of an unknown total (0).
  uint64_t done() const override { return points_.size(); }
  uint64_t total() const override { return 0; }
  // Known once the stream ended.
  std::optional<uint64_t> size() const override;
  // "stream", of an unknown number of points (0), without a fingerprint (a stream is not
  // resumed, and its first points may be yet to come).
  absl::StatusOr<v1::UploadOrder> DescribeOrder() override { return MakeUploadOrder("stream", 0); }

 private:
  // Reads until there are `want` points, the stream ends, or `deadline` passes with more than
  // `least` points.
  absl::Status ReadUntil(uint64_t want, uint64_t least, absl::Time deadline);
  // Once the origin is chosen, moves the points arrived_ holds into points_, relative to it.
  absl::Status TakeArrived();

  std::unique_ptr<PointStream> stream_;
  absl::Duration flush_after_;
  const bool colors_wanted_;
  bool ended_ = false;
  StreamedPoints arrived_;     // Read, in the stream's coordinates, not yet in points_.
  std::vector<Vec3f> points_;  // Relative to origin_,
  std::vector<Rgb> colors_;    // and their colours, with has_colors().
  Origin origin_ = kNoOrigin;
  double color_scale_ = 0;  // The full scale of the colour levels, once has_colors().
  bool started_ = false;
};

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_POINT_UPLOAD_H_
