// The LAS parser and writer (core/io/internal/las.h) against the properties of
// fuzz/geometry_parser_properties.h, and the writer's own: a parsed file written again reads
// back to the same number of points, each within the written scale (and a float's rounding) of
// where it was, with the same colours. The generic round trip, bit for bit, does not apply:
// LAS stores integers. A parsed file cleaned of every other point (FormatCleanedLas) reads back
// to the points kept; with those classified as noise instead, to the same points; joined
// with itself as a second tile, to the points kept twice; all with the default classes and
// with some asked for; joined with a tile of another format (its points written by the writer),
// to the points kept and the tile's, or refused. A LAZ input is read as the LAS file it
// compresses, and cleaned as that (laz_format_fuzzer checks the codec itself). Its records as
// off-core sampling reads them (LasRecords) agree with the parser
// (fuzz/point_records_properties.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "fuzz/fuzz_check.h"
#include "fuzz/geometry_parser_properties.h"
#include "fuzz/point_records_properties.h"

namespace {

using neuralmesh::io_internal::GeometryView;
using neuralmesh::io_internal::ParsedGeometry;

void CheckWrittenAgain(const ParsedGeometry& parsed) {
  const GeometryView view{parsed.positions, {}, {}, {}, parsed.colors, parsed.origin};
  const absl::StatusOr<std::string> written = neuralmesh::io_internal::FormatLas(view);
  FUZZ_CHECK(written.ok(), "the writer failed: %s", written.status().ToString().c_str());
  const absl::StatusOr<ParsedGeometry> reread = neuralmesh::io_internal::ParseLas(*written);
  FUZZ_CHECK(reread.ok(), "the writer's output does not parse: %s",
             reread.status().ToString().c_str());
  std::array<double, 3> scale;
  std::memcpy(scale.data(), written->data() + 131, sizeof scale);  // The header's three scales.
  neuralmesh::fuzz::CheckPositionsWithinScale(parsed, *reread, scale);
  FUZZ_CHECK(reread->colors == parsed.colors, "colours change when written and read back");
}

// The copy keeps the records' integers, so only the origin the reader picks (from the kept
// points' range) may change the floats: to within their rounding. Outliers classified as low
// noise are read again when the classes asked for hold it.
void CheckCleaned(absl::string_view data, const ParsedGeometry& parsed,
                  const std::optional<neuralmesh::LasClasses>& classes) {
  if (parsed.positions.empty()) return;  // A file of no points: nothing to clean.
  std::vector<bool> outliers(parsed.positions.size());
  ParsedGeometry expected;
  expected.origin = parsed.origin;
  for (size_t i = 0; i < outliers.size(); ++i) {
    outliers[i] = i % 2 == 1;
    if (!outliers[i]) expected.positions.push_back(parsed.positions[i]);
  }
  std::array<double, 3> scale;
  std::memcpy(scale.data(), data.data() + 131, sizeof scale);
  for (double& s : scale) s = std::fabs(s);
  for (const auto records : {neuralmesh::LasOutlierRecords::kLeftOut,
                             neuralmesh::LasOutlierRecords::kClassifiedAsNoise}) {
    const absl::StatusOr<std::string> cleaned =
        neuralmesh::io_internal::FormatCleanedLas({{"fuzz.las", data}}, outliers, records,
                                                  classes);
    FUZZ_CHECK(cleaned.ok(), "cleaning failed: %s", cleaned.status().ToString().c_str());
    const absl::StatusOr<ParsedGeometry> reread =
        neuralmesh::io_internal::ParseLas(*cleaned, classes);
    FUZZ_CHECK(reread.ok(), "the cleaned file does not parse: %s",
               reread.status().ToString().c_str());
    const bool noise_read = classes.has_value() && (*classes)[7];
    neuralmesh::fuzz::CheckPositionsWithinScale(
        records == neuralmesh::LasOutlierRecords::kClassifiedAsNoise && noise_read ? parsed
                                                                                   : expected,
        *reread, scale);
  }

  // The file joined with itself, as two tiles: the kept points twice; refused only for the
  // formats whose records point into their file's waveform data.
  std::vector<bool> twice = outliers;
  twice.insert(twice.end(), outliers.begin(), outliers.end());
  const absl::StatusOr<std::string> joined = neuralmesh::io_internal::FormatCleanedLas(
      {{"a.las", data}, {"b.las", data}}, twice, neuralmesh::LasOutlierRecords::kLeftOut,
      classes);
  const int format = static_cast<uint8_t>(data[104]);
  if (format == 4 || format == 5 || format == 9 || format == 10) {
    FUZZ_CHECK(absl::IsFailedPrecondition(joined.status()),
               "tiles of waveform format %d joined: %s", format,
               joined.status().ToString().c_str());
    return;
  }
  FUZZ_CHECK(joined.ok(), "joining failed: %s", joined.status().ToString().c_str());
  const absl::StatusOr<ParsedGeometry> reread = neuralmesh::io_internal::ParseLas(*joined, classes);
  FUZZ_CHECK(reread.ok(), "the joined file does not parse: %s",
             reread.status().ToString().c_str());
  ParsedGeometry both = expected;
  both.positions.insert(both.positions.end(), expected.positions.begin(),
                        expected.positions.end());
  neuralmesh::fuzz::CheckPositionsWithinScale(both, *reread, scale);
  if (classes.has_value()) return;

  // Joined with a tile of LAS 1.2's format 0 or 2 (its points as FormatLas writes them): the
  // records converted into the format that holds both's fields, every point read again, or
  // refused where the coordinates do not fit one grid.
  const GeometryView view{parsed.positions, {}, {}, {}, parsed.colors, parsed.origin};
  const absl::StatusOr<std::string> tile = neuralmesh::io_internal::FormatLas(view);
  FUZZ_CHECK(tile.ok(), "the writer failed: %s", tile.status().ToString().c_str());
  std::vector<bool> kept(outliers.size() + parsed.positions.size(), false);
  std::copy(outliers.begin(), outliers.end(), kept.begin());
  const absl::StatusOr<std::string> mixed = neuralmesh::io_internal::FormatCleanedLas(
      {{"a.las", data}, {"tile.las", *tile}}, kept, neuralmesh::LasOutlierRecords::kLeftOut);
  if (absl::IsFailedPrecondition(mixed.status())) return;
  FUZZ_CHECK(mixed.ok(), "joining another format failed: %s", mixed.status().ToString().c_str());
  const absl::StatusOr<ParsedGeometry> mixed_read = neuralmesh::io_internal::ParseLas(*mixed);
  FUZZ_CHECK(mixed_read.ok(), "the file joined with another format does not parse: %s",
             mixed_read.status().ToString().c_str());
  FUZZ_CHECK(mixed_read->positions.size() == expected.positions.size() + parsed.positions.size(),
             "%zu points read from the file joined with another format, not %zu + %zu",
             mixed_read->positions.size(), expected.positions.size(), parsed.positions.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const neuralmesh::fuzz::GeometryFormat las{
      [](absl::string_view bytes, neuralmesh::io_internal::FaceHandling,
         neuralmesh::io_internal::PositionPrecision) {
        return neuralmesh::io_internal::ParseLas(bytes);
      },
      nullptr, /*skips_faces=*/false};
  neuralmesh::fuzz::CheckGeometryParser(las, data, size);
  absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  std::string decompressed;
  if (neuralmesh::io_internal::IsLaz(bytes)) {
    absl::StatusOr<std::string> las = neuralmesh::io_internal::DecompressLaz(bytes);
    if (!las.ok()) return 0;  // ParseLas refuses it as well, checked above.
    decompressed = *std::move(las);
    bytes = decompressed;
  }
  const absl::StatusOr<ParsedGeometry> parsed = neuralmesh::io_internal::ParseLas(bytes);
  // The records as off-core sampling reads them (of the LAS file a LAZ input holds).
  const auto records = neuralmesh::io_internal::LasRecords::Create(bytes, std::nullopt);
  if (records.ok()) {
    neuralmesh::fuzz::CheckRecordsAgreeWithParser(**records, parsed.ok() ? &*parsed : nullptr);
  }
  if (parsed.ok()) {
    CheckWrittenAgain(*parsed);
    CheckCleaned(bytes, *parsed, std::nullopt);
  }
  // Ground, and a class the input picks (its last byte, often a record's).
  neuralmesh::LasClasses classes;
  classes.set(2).set(size > 0 ? data[size - 1] : 0);
  const absl::StatusOr<ParsedGeometry> selected =
      neuralmesh::io_internal::ParseLas(bytes, classes);
  if (selected.ok()) CheckCleaned(bytes, *selected, classes);
  return 0;
}
