#include "client/point_upload.h"

#include <algorithm>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "client/interrupt.h"
#include "core/parallel_ranges.h"
#include "core/status_macros.h"
#include "proto/packing.h"

namespace neuralmesh::client {
namespace {

// A batch of packed positions and colours (empty, or 3 bytes a point) from the upload's point
// `first` on.
v1::PointBatch MakeBatch(uint64_t first, std::string positions, std::string colors) {
  v1::PointBatch batch;
  batch.mutable_first_point()->set_value(first);
  batch.mutable_packed()->set_positions(std::move(positions));
  batch.mutable_packed()->set_colors(std::move(colors));
  return batch;
}

}  // namespace

v1::UploadOrder MakeUploadOrder(absl::string_view name, uint64_t items) {
  v1::UploadOrder order;
  order.set_name(std::string(name));
  order.set_items(items);
  return order;
}

uint64_t OrderFingerprint(absl::string_view positions) {
  uint64_t hash = 14695981039346656037ull;
  for (const char byte : positions) hash = (hash ^ static_cast<uint8_t>(byte)) * 1099511628211ull;
  return hash;
}

absl::StatusOr<v1::UploadOrder> PointUpload::FingerprintedOrder(absl::string_view name,
                                                                uint64_t items) {
  NM_ASSIGN_OR_RETURN(const v1::PointBatch first, Batch(0, kFingerprintPoints));
  v1::UploadOrder order = MakeUploadOrder(name, items);
  order.set_fingerprint(OrderFingerprint(first.packed().positions()));
  return order;
}

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
  v1::PointBatch batch;
  batch.mutable_first_point()->set_value(first);
  // The points go in runs: the rest of a block, or of the batch.
  for (uint64_t k = first; k < end;) {
    const uint64_t slot = order_.SlotOfNth(k);
    const uint64_t begin = order_[slot];
    const uint64_t run = std::min(
        {end - k, order_.block_records() - slot % order_.block_records(), cloud_.size() - begin});
    AppendPackedPoints(cloud_, begin, begin + run, batch.mutable_packed());
    k += run;
  }
  done_ = end;
  return batch;
}

std::optional<uint64_t> FileRecordsUpload::size() const {
  if (slot_ < order_.slots()) return std::nullopt;
  return points_;
}

template <typename OnPoint>
void FileRecordsUpload::ReadNext(const OnPoint& on_point) {
  // The order's blocks are runs of consecutive records: one look-up per block.
  if (slot_ % SpreadOrder::kBlockRecords == 0) block_first_record_ = order_[slot_];
  const uint64_t record = block_first_record_ + slot_ % SpreadOrder::kBlockRecords;
  ++slot_;
  if (record >= file_.records()) return;
  if (const std::optional<Vec3> point = file_.Point(record); point.has_value()) {
    ++points_;
    on_point(*point, record);
  }
}

absl::Status FileRecordsUpload::SkipTo(uint64_t first) {
  if (first < points_) {
    slot_ = 0;
    points_ = 0;
  }
  while (points_ < first && slot_ < order_.slots()) ReadNext([](const Vec3&, uint64_t) {});
  NM_RETURN_IF_ERROR(file_.CheckSize());
  if (points_ < first) {
    return absl::OutOfRangeError(
        absl::StrCat("the upload cannot start at point ", first, " of ", points_));
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::PointBatch> FileRecordsUpload::Batch(uint64_t first, size_t count) {
  NM_RETURN_IF_ERROR(SkipTo(first));
  std::string positions, colors;
  positions.reserve(count * sizeof(Vec3f));
  if (colors_) colors.reserve(count * sizeof(Rgb));
  const uint64_t end = first + count;
  while (points_ < end && slot_ < order_.slots()) {
    ReadNext([&](const Vec3& p, uint64_t record) {
      const Vec3f f(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
      positions.append(reinterpret_cast<const char*>(f.data()), sizeof(Vec3f));
      if (colors_) {
        const Rgb color = file_.Color(record).value_or(Rgb{0, 0, 0});
        colors.append(reinterpret_cast<const char*>(color.data()), sizeof(Rgb));
      }
    });
  }
  NM_RETURN_IF_ERROR(file_.CheckSize());  // Else the batch may hold zeros read past its end.
  return MakeBatch(first, std::move(positions), std::move(colors));
}

std::optional<uint64_t> LazFileUpload::size() const {
  if (next_chunk_ < order_.slots()) return std::nullopt;
  return wave_first_ + wave_.size();
}

absl::StatusOr<bool> LazFileUpload::NextWave() {
  std::vector<size_t> chunks;
  for (; next_chunk_ < order_.slots() && chunks.size() < kWaveChunks; ++next_chunk_) {
    if (order_[next_chunk_] < file_.chunks()) chunks.push_back(order_[next_chunk_]);
  }
  if (chunks.empty()) return false;
  std::vector<absl::StatusOr<MappedLazFile::ChunkPoints>> decoded(chunks.size());
  ForEachRange(chunks.size(), /*threads=*/0, 1, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) decoded[i] = file_.Points(chunks[i]);
  });
  // A file that shrank while its chunks were decoded explains what they decoded to.
  NM_RETURN_IF_ERROR(file_.CheckSize());
  wave_first_ += wave_.size();
  wave_.clear();
  wave_colors_.clear();
  size_t longest = 0;
  for (size_t i = 0; i < chunks.size(); ++i) {
    NM_RETURN_IF_ERROR(decoded[i].status());
    records_done_ += file_.records_in(chunks[i]);
    longest = std::max(longest, decoded[i]->positions.size());
  }
  for (size_t block = 0; block < longest; block += SpreadOrder::kBlockRecords) {
    for (const absl::StatusOr<MappedLazFile::ChunkPoints>& points : decoded) {
      const size_t end = std::min(points->positions.size(), block + SpreadOrder::kBlockRecords);
      for (size_t j = block; j < end; ++j) {
        const Vec3& p = points->positions[j];
        wave_.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]),
                           static_cast<float>(p[2]));
        if (colors_) wave_colors_.push_back(points->colors[j]);
      }
    }
  }
  return true;
}

absl::Status LazFileUpload::SkipTo(uint64_t first) {
  if (first < wave_first_) {
    next_chunk_ = 0;
    wave_.clear();
    wave_colors_.clear();
    wave_first_ = 0;
    records_done_ = 0;
  }
  while (first > wave_first_ + wave_.size()) {
    NM_ASSIGN_OR_RETURN(const bool more, NextWave());
    if (!more) {
      return absl::OutOfRangeError(absl::StrCat("the upload cannot start at point ", first, " of ",
                                                wave_first_ + wave_.size()));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::PointBatch> LazFileUpload::Batch(uint64_t first, size_t count) {
  NM_RETURN_IF_ERROR(SkipTo(first));
  std::string positions, colors;
  positions.reserve(count * sizeof(Vec3f));
  uint64_t next = first;
  while (next < first + count) {
    if (next == wave_first_ + wave_.size()) {
      NM_ASSIGN_OR_RETURN(const bool more, NextWave());
      if (!more) break;
      continue;
    }
    const size_t from = next - wave_first_;
    const size_t take = std::min<uint64_t>(wave_.size() - from, first + count - next);
    positions.append(reinterpret_cast<const char*>(wave_.data() + from), take * sizeof(Vec3f));
    if (colors_) {
      colors.append(reinterpret_cast<const char*>(wave_colors_.data() + from), take * sizeof(Rgb));
    }
    next += take;
  }
  return MakeBatch(first, std::move(positions), std::move(colors));
}

std::optional<uint64_t> StreamUpload::size() const {
  if (!ended_) return std::nullopt;
  return points_.size();
}

absl::Status StreamUpload::ReadUntil(uint64_t want, uint64_t least, absl::Time deadline) {
  constexpr absl::Duration kLongestWait = absl::Milliseconds(50);  // Between interrupt checks.
  while (!ended_ && points_.size() + arrived_.size() < want) {
    const absl::Time now = absl::Now();
    if (now >= deadline && points_.size() + arrived_.size() > least) break;
    if (InterruptScope::interrupted()) {
      return absl::CancelledError(absl::StrCat("interrupted while reading ", stream_->name()));
    }
    // Past the deadline with nothing to send: wait for the next point as long as it takes.
    const absl::Duration wait =
        now >= deadline ? kLongestWait : std::min(deadline - now, kLongestWait);
    NM_ASSIGN_OR_RETURN(const bool more, stream_->Read(wait, &arrived_));
    ended_ = !more;
    NM_RETURN_IF_ERROR(TakeArrived());
  }
  return absl::OkStatus();
}

absl::Status StreamUpload::TakeArrived() {
  if (!started_) return absl::OkStatus();
  // A stream's format (a LAS format, a text header) gives every point a colour or none.
  if (has_colors() && arrived_.colors.size() != arrived_.size()) {
    return absl::InternalError(absl::StrCat(stream_->name(), " gave ", arrived_.size(),
                                            " points with ", arrived_.colors.size(), " colours"));
  }
  for (size_t i = 0; i < arrived_.size(); ++i) {
    const Vec3& p = arrived_.positions[i];
    const Vec3 relative(p[0] - origin_[0], p[1] - origin_[1], p[2] - origin_[2]);
    if (!MappedPointFile::Learnable(relative)) {
      return absl::InvalidArgumentError(absl::StrCat(
          stream_->name(), ", point ", points_.size() + 1, ": (", p[0], ", ", p[1], ", ", p[2],
          ") lies beyond a float's range from the origin the first points chose (", origin_[0],
          ", ", origin_[1], ", ", origin_[2], ")"));
    }
    points_.emplace_back(static_cast<float>(relative[0]), static_cast<float>(relative[1]),
                         static_cast<float>(relative[2]));
    if (has_colors()) {
      const std::array<float, 3>& channels = arrived_.colors[i];
      colors_.push_back({ChannelFromLevel(channels[0], color_scale_),
                         ChannelFromLevel(channels[1], color_scale_),
                         ChannelFromLevel(channels[2], color_scale_)});
    }
  }
  arrived_.clear();
  return absl::OkStatus();
}

absl::Status StreamUpload::Start(size_t count) {
  NM_RETURN_IF_ERROR(ReadUntil(count, 0, absl::Now() + flush_after_));
  if (arrived_.size() == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        stream_->name(), " ended before its first point (", stream_->ReadSoFar(), " read)"));
  }
  BoundingBox box;
  for (const Vec3& p : arrived_.positions) box.Extend(p);
  origin_ = OriginOfStreamedPoints(box);
  if (colors_wanted_ && !arrived_.colors.empty()) {
    float largest = 0;
    for (const std::array<float, 3>& channels : arrived_.colors) {
      largest = std::max({largest, channels[0], channels[1], channels[2]});
    }
    color_scale_ = stream_->ColorScale(largest);
  }
  started_ = true;
  return TakeArrived();
}

absl::Status StreamUpload::SkipTo(uint64_t first) {
  NM_RETURN_IF_ERROR(ReadUntil(first, first, absl::InfiniteFuture()));
  if (points_.size() < first) {
    return absl::OutOfRangeError(
        absl::StrCat("the upload cannot start at point ", first, " of ", points_.size()));
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::PointBatch> StreamUpload::Batch(uint64_t first, size_t count) {
  NM_RETURN_IF_ERROR(SkipTo(first));
  NM_RETURN_IF_ERROR(ReadUntil(first + count, first, absl::Now() + flush_after_));
  const uint64_t end = std::min<uint64_t>(points_.size(), first + count);
  return MakeBatch(first,
                   std::string(reinterpret_cast<const char*>(points_.data() + first),
                               (end - first) * sizeof(Vec3f)),
                   has_colors() ? std::string(reinterpret_cast<const char*>(colors_.data() + first),
                                              (end - first) * sizeof(Rgb))
                                : "");
}

}  // namespace neuralmesh::client
