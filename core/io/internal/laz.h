// LASzip-compressed LAS files (.laz): the same header and records as LAS, the records coded in
// chunks (50,000 records by default) by LASzip's arithmetic coder, described by a variable-length
// record (user "laszip encoded", record 22204), with a table of the chunks' sizes after them.
// Point formats 0 to 3 (LAS 1.0-1.4), LASzip's item coders of version 2: what LASzip 2 and 3,
// LAStools, PDAL and laz-perf write for these formats. LAS 1.4's formats 6 to 8, whose records
// LASzip 3 codes in layers with item coders of version 3 or 4 (laz_layered_items.h). The
// waveform formats 4, 5, 9 and 10 are refused, saying so.
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAZ_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAZ_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/byte_sink.h"
#include "core/io/internal/las_file_writer.h"

namespace neuralmesh::io_internal {

// Whether `data` starts as a LAS file whose point format carries LASzip's compression bits.
bool IsLaz(absl::string_view data);

struct LazReadOptions {
  // Threads decoding chunks (each on its own): 0 for one per hardware thread. The output is
  // the same.
  int threads = 0;
};

// The LAS file that `laz` holds compressed: its header (the point format without the
// compression bits, one variable-length record fewer, the offsets to the points and to the
// extended records moved), its other variable-length records, its records byte for byte, and
// what follows them (LAS 1.4's extended records).
// Returns INVALID_ARGUMENT saying what is wrong for a file that is not LAZ, a missing or
// malformed LASzip record, a chunk table or chunks that do not fit the file or list another
// number of records than the header counts, a chunk whose bytes run out before its records are
// decoded (truncated or corrupt), or records whose decompressed size would exceed 4,096 times
// the compressed data (a corrupt count), a layered chunk whose layers do not fit it or lack
// the layer of returns, X and Y; and for what LASzip writes that is not read here, saying so:
// the waveform formats 4, 5, 9 and 10 and LASzip 1's compression (one stream, item coders of
// version 1).
absl::StatusOr<std::string> DecompressLaz(absl::string_view laz,
                                          const LazReadOptions& options = {});
// The same bytes given to `out` a wave of chunks at a time, so that no more than a wave's
// records are held: DecompressLaz's errors, or `out`'s first.
absl::Status DecompressLazTo(absl::string_view laz, ByteSink* out,
                             const LazReadOptions& options = {});

// The chunks of a LAZ file, each decoded on its own (LASzip starts every chunk afresh): the
// records of a file read where it lies, a chunk at a time, instead of decompressed whole.
class LazChunks {
 public:
  // Where a chunk's bytes are, how many records it holds and the first one's number.
  struct ChunkSpan {
    size_t at = 0;
    size_t size = 0;
    uint64_t records = 0;
    uint64_t first = 0;
  };

  // DecompressLaz's checks of the header, the LASzip record, the records' count and the chunk
  // table, with its errors. `laz` must outlive the object.
  static absl::StatusOr<LazChunks> Open(absl::string_view laz);

  size_t size() const { return chunks_.size(); }
  const ChunkSpan& chunk(size_t i) const { return chunks_[i]; }
  uint64_t records_in(size_t i) const { return chunks_[i].records; }
  uint64_t first_record(size_t i) const { return chunks_[i].first; }
  uint64_t records() const { return records_; }
  size_t record_length() const { return record_length_; }
  // The LAS file's header and variable-length records, as DecompressLaz's output begins, and
  // what follows its records there (LAS 1.4's extended records).
  const std::string& las_header() const { return las_header_; }
  absl::string_view las_tail() const;
  // Decodes chunks first to last - 1 (<= size()) into their records' bytes, one chunk's after
  // another's, from `out` on. DecompressLaz's errors for a chunk that cannot be decoded. Safe
  // to call from several threads at once.
  absl::Status Decode(size_t first, size_t last, char* out) const;
  // Chunk i alone.
  absl::Status Decode(size_t i, char* out) const { return Decode(i, i + 1, out); }
  // Decodes every chunk, a wave of a few per thread at a time (`threads`: 0 for one per
  // hardware thread), and gives each chunk's records to visit(chunk, records) in order, first to
  // last: for reading a file's records without the whole of them in memory. Decode's error of
  // the first chunk that cannot be decoded, or visit's first error, which stops the decoding.
  absl::Status DecodeInOrder(const std::function<absl::Status(size_t, absl::string_view)>& visit,
                             int threads = 0) const;

  // The compressed records' bytes.
  uint64_t compressed_bytes() const { return compressed_; }

 private:
  LazChunks() = default;

  absl::string_view laz_;
  std::vector<ChunkSpan> chunks_;
  std::string las_header_;
  int format_ = 0;
  size_t record_length_ = 0;
  uint16_t item_version_ = 0;
  uint64_t records_ = 0;
  uint64_t compressed_ = 0;
  size_t points_end_ = 0;
  uint64_t evlr_start_ = 0;
};

class ChunkCoder;

// A LAZ file's records decoded as its bytes arrive in order, without the chunk table that
// LASzip writes after the chunks: standard input fed by `laszip -stdout` or `pdal translate`.
// A chunk ends where its decoding ends: a layered chunk states its layers' sizes, and a
// pointwise one's arithmetic coder ends exactly at its last byte (laz_arithmetic_coder.h).
class LazStreamDecoder {
 public:
  // From the file's header and variable-length records (its first bytes, up to the points):
  // LazChunks::Open's errors for the header and LASzip record, and INVALID_ARGUMENT for chunks
  // of varying size, or a header that states no record count (the chunks' end is then known
  // only from the chunk table after them).
  static absl::StatusOr<LazStreamDecoder> Create(absl::string_view header);

  // Moved, not copied: its coder holds the decoding's state.
  LazStreamDecoder(LazStreamDecoder&&) noexcept;
  LazStreamDecoder& operator=(LazStreamDecoder&&) noexcept;
  ~LazStreamDecoder();

  // The LAS file's header and variable-length records, as DecompressLaz's output begins.
  const std::string& las_header() const { return las_header_; }
  size_t record_length() const { return record_length_; }
  // Records the header states that are not decoded yet.
  uint64_t records_left() const { return records_left_; }
  // Whether the next chunk is the last (its records are the ones left).
  bool last_chunk_next() const { return records_left_ <= chunk_size_; }

  // Decodes the chunk that `bytes` start with (the stream's bytes after the points' offset and
  // the chunks decoded so far) and appends its records to `records`. Returns the bytes it
  // took, or 0 when `bytes` do not hold all of it yet (none once every record is decoded).
  // With `ended` (no more bytes will come), INVALID_ARGUMENT for a chunk cut short; a corrupt
  // chunk's errors as DecompressLaz's.
  absl::StatusOr<size_t> DecodeNext(absl::string_view bytes, bool ended, std::string* records);

 private:
  LazStreamDecoder();

  std::string las_header_;
  size_t record_length_ = 0;
  uint32_t chunk_size_ = 0;
  uint64_t records_left_ = 0;
  uint64_t chunks_ = 0;
  bool table_offset_skipped_ = false;
  std::unique_ptr<ChunkCoder> coder_;
};

// How `laz` is compressed, for reports (`neuralmesh stats`): the LASzip version that wrote it,
// the compressor, the item version and the chunks, as "LASzip 3.4 (revision 3), layered chunks,
// item version 3, 3 chunks of up to 50000 records". DecompressLaz's errors for a file it does
// not read.
absl::StatusOr<std::string> DescribeLazCompression(absl::string_view laz);

struct LazWriteOptions {
  // Records per chunk; each chunk starts afresh, so a reader can start at any chunk.
  uint32_t chunk_size = 50000;
  // The item version of formats 6 to 8: 3 (LASzip 3, laz-perf) or 4 (newer LASzip).
  uint16_t layered_version = 3;
  // Threads coding chunks (each on its own): 0 for one per hardware thread. The output is the
  // same.
  int threads = 0;
};

// A LAS file compressed as LAZ as its pieces come (LasFileWriter): the records are coded a wave
// of chunks at a time (a few per thread), so that no more than a wave's records and chunks are
// held, and the file is the one CompressLas makes of the LAS file of the same head, records and
// tail. The chunk table's offset, before the chunks, and the head's counts are patched in by
// Finish, which needs `out` to take patches.
class LazWriter final : public LasFileWriter {
 public:
  explicit LazWriter(ByteSink* out, const LazWriteOptions& options = {})
      : LasFileWriter(out), options_(options) {}

  // CompressLas's errors for the head, its point format and the options.
  absl::Status Start(absl::string_view head) override;
  absl::Status AppendRecords(absl::string_view records) override;
  // Also INVALID_ARGUMENT when the head counts other records than were appended.
  absl::Status Finish(absl::string_view head, absl::string_view tail) override;

 private:
  // The LAZ file's head for the LAS head `las`: its LASzip record after the others, the point
  // format's compression bits, and the chunk table's offset after it (zero: patched by Finish).
  absl::StatusOr<std::string> LazHead(absl::string_view las) const;
  // Codes `count` records at `records` (a wave at most) in chunks, appended in order.
  absl::Status CodeChunks(const char* records, uint64_t count);

  LazWriteOptions options_;
  std::string started_;   // The LAS head Start took.
  std::string laz_head_;  // Its LAZ head, appended with the first records.
  int format_ = 0;
  size_t record_length_ = 0;
  uint16_t version_ = 0;
  uint64_t wave_records_ = 0;
  uint64_t appended_ = 0;  // Records taken so far.
  std::string pending_;    // Records of a wave not complete yet.
  std::vector<std::string> coded_;
  std::vector<uint32_t> chunk_sizes_;
};

// `las` compressed as LAZ: what DecompressLaz turns back into `las`, byte for byte.
// Returns INVALID_ARGUMENT for a malformed LAS file (a header, records or variable-length
// records that do not fit it), a chunk size of 0 or an item version other than 3 or 4;
// FAILED_PRECONDITION for the waveform formats 4, 5, 9 and 10, which are not written as LAZ
// here.
absl::StatusOr<std::string> CompressLas(absl::string_view las, const LazWriteOptions& options = {});
// The same bytes given to `out` a wave of chunks at a time (LazWriter): CompressLas's errors,
// or `out`'s first.
absl::Status CompressLasTo(absl::string_view las, ByteSink* out,
                           const LazWriteOptions& options = {});
// The LAZ file `laz` compressed again into `out` with `options` (a copy from .laz to .laz): the
// bytes CompressLasTo gives of the LAS file it holds, its chunks decoded and coded a wave at a
// time (LazWriter), never the LAS file whole. DecompressLaz's errors, CompressLas's, or `out`'s.
absl::Status RecompressLazTo(absl::string_view laz, ByteSink* out,
                             const LazWriteOptions& options = {});

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAZ_H_
