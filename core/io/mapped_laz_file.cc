#include "core/io/mapped_laz_file.h"

#include <algorithm>
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "core/io/mapped_point_file.h"
#include "core/io/spread_order.h"
#include "core/parallel_ranges.h"
#include "core/status_macros.h"

namespace neuralmesh {

bool IsLazFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(512, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(std::max<std::streamsize>(0, in.gcount())));
  return io_internal::IsLaz(head);
}

absl::StatusOr<MappedLazFile> MappedLazFile::Open(const std::string& path,
                                                  const std::optional<LasClasses>& classes) {
  NM_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  const auto invalid = [&path](absl::string_view message) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "': ", message));
  };
  absl::StatusOr<io_internal::LazChunks> chunks = io_internal::LazChunks::Open(file.data());
  if (!chunks.ok()) return invalid(chunks.status().message());
  if (chunks->records() == 0) return invalid("the file has no point records");
  // The records' header, its bounds and scale.
  absl::StatusOr<std::unique_ptr<io_internal::LasRecords>> no_records =
      io_internal::LasRecords::Create(chunks->las_header(), absl::string_view(), classes);
  if (!no_records.ok()) return invalid(no_records.status().message());
  MappedLazFile opened(path, std::move(file), *std::move(chunks));
  opened.classes_ = classes;
  opened.has_colors_ = (*no_records)->has_colors();

  // The probe, with origin_ still (0, 0, 0): points in the file's coordinates. Its chunks are
  // decoded on every core: the first mesh of an upload waits for them.
  const SpreadOrder order(opened.chunks(), 1);
  const size_t probe_chunks = std::min(kProbeChunks, opened.chunks());
  std::vector<std::string> decoded(probe_chunks);
  std::vector<absl::StatusOr<std::unique_ptr<io_internal::LasRecords>>> probe(probe_chunks);
  ForEachRange(probe_chunks, /*threads=*/0, 1, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) probe[k] = opened.Records(order[k], &decoded[k]);
  });
  BoundingBox probed;
  uint64_t records = 0, kept = 0;
  uint16_t largest_level = 0;
  for (size_t k = 0; k < probe_chunks; ++k) {
    NM_RETURN_IF_ERROR(probe[k].status());
    const io_internal::LasRecords* chunk = probe[k]->get();
    records += chunk->size();
    for (uint64_t i = 0; i < chunk->size(); ++i) {
      const std::optional<Vec3> p = MappedPointFile::PointOfRecord(*chunk, i, kNoOrigin);
      if (!p.has_value()) continue;
      ++kept;
      probed.Extend(*p);
      if (const auto levels = chunk->ColorLevels(i); levels.has_value()) {
        largest_level = std::max({largest_level, (*levels)[0], (*levels)[1], (*levels)[2]});
      }
    }
    absl::MutexLock lock(&opened.probed_->mutex);
    opened.probed_->decoded.emplace_back(order[k], std::move(decoded[k]));
  }
  NM_RETURN_IF_ERROR(opened.CheckSize());
  opened.color_scale_ = LevelScale(largest_level);
  if (kept == 0) {
    return invalid(absl::StrCat(
        "none of the ", records, " records of ", probe_chunks,
        " chunks spread over the file is a point to read (",
        classes.has_value() ? "withheld, noise or of other classes" : "withheld or noise",
        ", or beyond a float's range); read the file whole"));
  }
  opened.kept_share_ = static_cast<double>(kept) / static_cast<double>(records);
  const ProbedPlacement placement = PlaceProbe(probed, **no_records);
  opened.origin_ = placement.origin;
  opened.bounds_ = placement.bounds;
  return opened;
}

bool MappedLazFile::TakeProbed(size_t chunk, std::string* decoded) const {
  absl::MutexLock lock(&probed_->mutex);
  std::vector<std::pair<size_t, std::string>>& probed = probed_->decoded;
  for (auto it = probed.begin(); it != probed.end(); ++it) {
    if (it->first != chunk) continue;
    *decoded = std::move(it->second);
    probed.erase(it);
    return true;
  }
  return false;
}

absl::StatusOr<std::unique_ptr<io_internal::LasRecords>> MappedLazFile::Records(
    size_t chunk, std::string* decoded) const {
  if (!TakeProbed(chunk, decoded)) {
    decoded->assign(chunks_.records_in(chunk) * chunks_.record_length(), '\0');
    if (const absl::Status status = chunks_.Decode(chunk, decoded->data()); !status.ok()) {
      return io_internal::WithPath(status, path_);
    }
  }
  return io_internal::LasRecords::Create(chunks_.las_header(), *decoded, classes_);
}

absl::StatusOr<MappedLazFile::ChunkPoints> MappedLazFile::Points(size_t chunk) const {
  std::string decoded;
  NM_ASSIGN_OR_RETURN(const std::unique_ptr<io_internal::LasRecords> records,
                      Records(chunk, &decoded));
  ChunkPoints points;
  points.positions.reserve(records->size());
  for (uint64_t i = 0; i < records->size(); ++i) {
    const std::optional<Vec3> p = MappedPointFile::PointOfRecord(*records, i, origin_);
    if (!p.has_value()) continue;
    points.positions.push_back(*p);
    if (const auto levels = records->ColorLevels(i); levels.has_value()) {
      points.colors.push_back(RgbFromLevels(*levels, color_scale_));
    }
  }
  return points;
}

}  // namespace neuralmesh
