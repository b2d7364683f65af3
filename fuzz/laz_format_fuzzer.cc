// The LAZ codec (core/io/internal/laz.h): any input is decompressed or refused without a crash
// or a read out of bounds, and what decompresses compresses again to a file that decompresses
// to the same bytes: the LAS file that a LAZ file holds is one CompressLas writes exactly (for
// the point formats it writes, 0 to 3 and 6 to 8, and a LAS 1.4 header whose extended records
// start after the points or nowhere). The coders' round trip is checked on the records the
// input decodes to, which random inputs make as wild as records get, in item versions 3 and 4
// for the layered formats 6 to 8. Parsed and described (ParseLas and DescribeLas read a LAZ
// file a chunk at a time), the input gives what the LAS file it decompresses to gives: the same
// points, colours, origin and records left out, the same classes, or the same error. Written a
// wave of chunks at a time into a sink (DecompressLazTo), it gives DecompressLaz's bytes, and
// described in the pass that reads its points, DescribeLas's description. Cleaned, and
// compressed again, a chunk at a time, what the decompressed file gives.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "core/io/internal/las.h"
#include "core/io/internal/laz.h"
#include "fuzz/fuzz_check.h"
#include "fuzz/point_records_properties.h"

namespace {

// Whether the LAS file's header says where its extended records start in a way a LAZ file can
// say again: nowhere (0, or a version before 1.4), or after its points.
bool ExtendedRecordsPlaced(const std::string& las) {
  if (las.size() < 375 || las[25] < 4) return true;
  uint16_t header_size = 0, length = 0;
  uint32_t offset = 0;
  uint64_t count = 0, start = 0;
  std::memcpy(&header_size, las.data() + 94, 2);
  if (header_size < 375) return true;
  std::memcpy(&offset, las.data() + 96, 4);
  std::memcpy(&length, las.data() + 105, 2);
  uint32_t legacy = 0;
  std::memcpy(&legacy, las.data() + 107, 4);
  std::memcpy(&count, las.data() + 247, 8);
  if (count == 0) count = legacy;
  std::memcpy(&start, las.data() + 235, 8);
  const uint64_t points_end = offset + count * length;
  return start == 0 || (start >= points_end && start <= las.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  const absl::StatusOr<std::string> las = neuralmesh::io_internal::DecompressLaz(bytes);
  if (!las.ok()) return 0;
  FUZZ_CHECK(!neuralmesh::io_internal::IsLaz(*las), "the decompressed file says it is LAZ");
  // Written a wave of chunks at a time (a copy to .las), the same bytes.
  neuralmesh::StringSink streamed;
  FUZZ_CHECK(
      neuralmesh::io_internal::DecompressLazTo(bytes, &streamed).ok() && streamed.bytes() == *las,
      "decompressed a wave at a time, other bytes or an error");
  // Read a chunk at a time (the off-core upload: core/io/mapped_laz_file.h), the records are
  // the points that parsing the decompressed file reads.
  const absl::StatusOr<neuralmesh::io_internal::LazChunks> chunks =
      neuralmesh::io_internal::LazChunks::Open(bytes);
  FUZZ_CHECK(chunks.ok(), "a file that decompresses has no chunks: %s",
             chunks.status().ToString().c_str());
  const size_t records_at = chunks->las_header().size();
  const size_t records_size = chunks->records() * chunks->record_length();
  FUZZ_CHECK(las->size() >= records_at + records_size, "the records run past the LAS file");
  for (size_t i = 0; i < chunks->size(); ++i) {
    std::string decoded(chunks->records_in(i) * chunks->record_length(), '\0');
    FUZZ_CHECK(chunks->Decode(i, decoded.data()).ok(), "chunk %zu does not decode alone", i);
    FUZZ_CHECK(
        decoded == las->substr(records_at + chunks->first_record(i) * chunks->record_length(),
                               decoded.size()),
        "chunk %zu decodes alone to other records", i);
  }
  const absl::StatusOr<std::unique_ptr<neuralmesh::io_internal::LasRecords>> records =
      neuralmesh::io_internal::LasRecords::Create(
          chunks->las_header(), absl::string_view(*las).substr(records_at, records_size),
          std::nullopt);
  const absl::StatusOr<neuralmesh::io_internal::ParsedGeometry> parsed =
      neuralmesh::io_internal::ParseLas(*las, std::nullopt);
  if (records.ok()) {
    neuralmesh::fuzz::CheckRecordsAgreeWithParser(**records, parsed.ok() ? &*parsed : nullptr);
  }
  const absl::StatusOr<neuralmesh::io_internal::ParsedGeometry> chunked =
      neuralmesh::io_internal::ParseLas(bytes, std::nullopt);
  FUZZ_CHECK(chunked.status() == parsed.status(), "read a chunk at a time: %s; decompressed: %s",
             chunked.status().ToString().c_str(), parsed.status().ToString().c_str());
  const absl::StatusOr<neuralmesh::LasDescription> described =
      neuralmesh::io_internal::DescribeLas(*las);
  const absl::StatusOr<neuralmesh::LasDescription> described_by_chunk =
      neuralmesh::io_internal::DescribeLas(bytes);
  FUZZ_CHECK(described_by_chunk.status() == described.status(),
             "described a chunk at a time: %s; decompressed: %s",
             described_by_chunk.status().ToString().c_str(), described.status().ToString().c_str());
  if (described.ok()) {
    FUZZ_CHECK(described_by_chunk->records_by_class == described->records_by_class &&
                   described_by_chunk->withheld == described->withheld,
               "other classes described a chunk at a time");
  }
  // Described in the pass that reads the points (`neuralmesh stats`): as DescribeLas.
  neuralmesh::LasDescription in_passing;
  const absl::StatusOr<neuralmesh::io_internal::ParsedGeometry> read_and_described =
      neuralmesh::io_internal::ParseLas(bytes, std::nullopt, &in_passing);
  FUZZ_CHECK(read_and_described.status() == chunked.status(), "read and described: %s",
             read_and_described.status().ToString().c_str());
  if (read_and_described.ok() && described_by_chunk.ok()) {
    FUZZ_CHECK(in_passing.records_by_class == described_by_chunk->records_by_class &&
                   in_passing.withheld == described_by_chunk->withheld &&
                   in_passing.file_bytes == described_by_chunk->file_bytes &&
                   in_passing.compression == described_by_chunk->compression,
               "described in the pass that reads the points, otherwise");
  }
  if (parsed.ok()) {
    FUZZ_CHECK(chunked->positions.size() == parsed->positions.size(), "%zu points, not %zu",
               chunked->positions.size(), parsed->positions.size());
    FUZZ_CHECK(parsed->positions.empty() ||
                   std::memcmp(chunked->positions.data(), parsed->positions.data(),
                               parsed->positions.size() * sizeof(parsed->positions[0])) == 0,
               "other positions read a chunk at a time");
    FUZZ_CHECK(chunked->colors == parsed->colors, "other colours read a chunk at a time");
    FUZZ_CHECK(chunked->origin == parsed->origin, "another origin read a chunk at a time");
    FUZZ_CHECK(chunked->left_out.total() == parsed->left_out.total() &&
                   chunked->left_out.withheld == parsed->left_out.withheld &&
                   chunked->left_out.noise == parsed->left_out.noise,
               "other records left out read a chunk at a time");
  }
  // Cleaned of every other point a chunk at a time (WriteCleanedLasTo), what cleaning the
  // decompressed file gives, or its error.
  if (parsed.ok()) {
    std::vector<bool> outliers(parsed->positions.size());
    for (size_t i = 0; i < outliers.size(); i += 2) outliers[i] = true;
    for (const neuralmesh::LasOutlierRecords kind :
         {neuralmesh::LasOutlierRecords::kLeftOut,
          neuralmesh::LasOutlierRecords::kClassifiedAsNoise}) {
      const absl::StatusOr<std::string> cleaned =
          neuralmesh::io_internal::FormatCleanedLas({{"fuzz.las", *las}}, outliers, kind);
      const absl::StatusOr<std::string> cleaned_by_chunk =
          neuralmesh::io_internal::FormatCleanedLas({{"fuzz.las", bytes}}, outliers, kind);
      FUZZ_CHECK(cleaned.status() == cleaned_by_chunk.status() &&
                     (!cleaned.ok() || *cleaned == *cleaned_by_chunk),
                 "cleaned a chunk at a time: %s; decompressed: %s",
                 cleaned_by_chunk.status().ToString().c_str(),
                 cleaned.status().ToString().c_str());
    }
  }
  if (!ExtendedRecordsPlaced(*las)) return 0;
  // Compressed again a chunk at a time as it is decoded (a LAZ-to-LAZ copy), what CompressLas
  // makes of the decompressed file.
  const absl::StatusOr<std::string> recompressed = neuralmesh::io_internal::CompressLas(*las);
  neuralmesh::StringSink rewritten;
  const absl::Status rewriting = neuralmesh::io_internal::RecompressLazTo(bytes, &rewritten);
  FUZZ_CHECK(rewriting.code() == recompressed.status().code() &&
                 (!rewriting.ok() || rewritten.bytes() == *recompressed),
             "compressed again a chunk at a time: %s; whole: %s", rewriting.ToString().c_str(),
             recompressed.status().ToString().c_str());
  for (const uint32_t chunk_size : {50000u, 3u}) {
    const uint16_t version = chunk_size == 3 ? 4 : 3;
    const absl::StatusOr<std::string> laz =
        neuralmesh::io_internal::CompressLas(*las, {chunk_size, version});
    FUZZ_CHECK(laz.ok(), "what decompressed does not compress: %s",
               laz.status().ToString().c_str());
    const absl::StatusOr<std::string> again = neuralmesh::io_internal::DecompressLaz(*laz);
    FUZZ_CHECK(again.ok(), "a compressed file does not decompress: %s",
               again.status().ToString().c_str());
    FUZZ_CHECK(*again == *las, "compressed and decompressed, %zu bytes come back as %zu",
               las->size(), again->size());
  }
  return 0;
}
