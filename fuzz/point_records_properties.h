// What off-core sampling reads (core/io/internal/point_records.h) must agree with what the
// format's parser reads whole, checked by the LAS, PLY and PCD fuzzers: where the parser takes
// the file, the kept records are its points, in order, each narrowing to the point the parser
// gives relative to its origin; and every record can be read (AddressSanitizer sees a read
// past the file).
#ifndef NEURALMESH_FUZZ_POINT_RECORDS_PROPERTIES_H_
#define NEURALMESH_FUZZ_POINT_RECORDS_PROPERTIES_H_

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>

#include "core/io/internal/geometry_data.h"
#include "core/io/internal/point_records.h"
#include "core/io/internal/text.h"
#include "core/rgb.h"
#include "fuzz/fuzz_check.h"

namespace neuralmesh::fuzz {

inline void CheckRecordsAgreeWithParser(const io_internal::PointRecords& records,
                                        const io_internal::ParsedGeometry* parsed) {
  uint64_t kept = 0;
  for (uint64_t i = 0; i < records.size(); ++i) {
    const std::optional<io_internal::Point3d> p = records.KeptPoint(i);
    if (!p.has_value()) continue;
    if (parsed != nullptr) {
      FUZZ_CHECK(kept < parsed->positions.size(), "more records kept than the %zu points read",
                 parsed->positions.size());
      for (int c = 0; c < 3; ++c) {
        const float narrowed = io_internal::NarrowToFloat((*p)[c] - parsed->origin[c]);
        FUZZ_CHECK(narrowed == parsed->positions[kept][c],
                   "record %llu (point %llu), axis %d: %.9g where the parser read %.9g",
                   static_cast<unsigned long long>(i), static_cast<unsigned long long>(kept), c,
                   narrowed, parsed->positions[kept][c]);
      }
    }
    ++kept;
  }
  if (parsed != nullptr) {
    FUZZ_CHECK(kept == parsed->positions.size(), "%llu records kept, %zu points read",
               static_cast<unsigned long long>(kept), parsed->positions.size());
  }
  // Colours read a record at a time are the parser's: stated ones (PLY, PCD) as they are, LAS
  // levels scaled by the largest level of all kept records as the parser scales them.
  if (parsed == nullptr || parsed->positions.empty()) return;
  FUZZ_CHECK(records.has_colors() == !parsed->colors.empty(),
             "the records %s colours, the parser read %zu", records.has_colors() ? "have" : "lack",
             parsed->colors.size());
  if (parsed->colors.empty()) return;
  uint16_t largest = 0;
  for (uint64_t i = 0; i < records.size(); ++i) {
    if (!records.KeptPoint(i).has_value()) continue;
    const std::optional<std::array<uint16_t, 3>> levels = records.ColorLevels(i);
    if (levels.has_value()) largest = std::max({largest, (*levels)[0], (*levels)[1], (*levels)[2]});
  }
  uint64_t point = 0;
  for (uint64_t i = 0; i < records.size(); ++i) {
    if (!records.KeptPoint(i).has_value()) continue;
    std::optional<Rgb> color = records.StatedColor(i);
    if (const auto levels = records.ColorLevels(i); levels.has_value()) {
      FUZZ_CHECK(!color.has_value(), "record %llu has stated colours and levels",
                 static_cast<unsigned long long>(i));
      color = RgbFromLevels(*levels, LevelScale(largest));
    }
    FUZZ_CHECK(color.has_value(), "record %llu has no colour", static_cast<unsigned long long>(i));
    for (int c = 0; c < 3; ++c) {
      FUZZ_CHECK((*color)[c] == parsed->colors[point][c],
                 "record %llu, channel %d: %u where the parser read %u",
                 static_cast<unsigned long long>(i), c, unsigned{(*color)[c]},
                 unsigned{parsed->colors[point][c]});
    }
    ++point;
  }
}

}  // namespace neuralmesh::fuzz

#endif  // NEURALMESH_FUZZ_POINT_RECORDS_PROPERTIES_H_
