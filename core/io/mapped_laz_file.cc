#include "core/io/mapped_laz_file.h"

#include <algorithm>
#include <fstream>
#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/io/internal/file_util.h"
#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "core/io/mapped_point_file.h"
#include "core/io/spread_order.h"
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

  // The probe, with origin_ still (0, 0, 0): points in the file's coordinates.
  const SpreadOrder order(opened.chunks(), 1);
  std::string decoded;
  BoundingBox probed;
  uint64_t records = 0, kept = 0;
  uint16_t largest_level = 0;
  for (size_t k = 0; k < std::min(kProbeChunks, opened.chunks()); ++k) {
    NM_ASSIGN_OR_RETURN(const std::unique_ptr<io_internal::LasRecords> chunk,
                        opened.Records(order[k], &decoded));
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
  }
  NM_RETURN_IF_ERROR(opened.CheckSize());
  opened.color_scale_ = LevelScale(largest_level);
  if (kept == 0) {
    return invalid(absl::StrCat(
        "none of the ", records, " records of ", std::min(kProbeChunks, opened.chunks()),
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

absl::StatusOr<std::unique_ptr<io_internal::LasRecords>> MappedLazFile::Records(
    size_t chunk, std::string* decoded) const {
  decoded->assign(chunks_.records_in(chunk) * chunks_.record_length(), '\0');
  if (const absl::Status status = chunks_.Decode(chunk, decoded->data()); !status.ok()) {
    return io_internal::WithPath(status, path_);
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
