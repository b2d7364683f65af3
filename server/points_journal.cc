#include "server/points_journal.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "neuralmesh/v1/reconstruction.pb.h"
#include "server/proto_conversion.h"

namespace neuralmesh::server {
namespace {

constexpr uint32_t kMagic = 0x42504D4E;  // "NMPB" in little-endian byte order.
constexpr size_t kHeaderBytes = 12;
// Far above the largest batch the server takes (2M points of 31 bytes); a length beyond it is
// damage, not a record to allocate for.
constexpr uint32_t kMaxPayloadBytes = uint32_t{1} << 30;

// CRC-32 of the concatenation of `pieces`.
uint32_t Checksum(absl::Span<const absl::string_view> pieces) {
  uLong crc = crc32(0L, Z_NULL, 0);
  for (absl::string_view piece : pieces) {
    const auto* data = reinterpret_cast<const Bytef*>(piece.data());
    size_t left = piece.size();
    while (left > 0) {
      const uInt chunk =
          static_cast<uInt>(std::min<size_t>(left, std::numeric_limits<uInt>::max()));
      crc = crc32(crc, data, chunk);
      data += chunk;
      left -= chunk;
    }
  }
  return static_cast<uint32_t>(crc);
}

void PutVarint(uint64_t value, std::string* out) {
  while (value >= 0x80) {
    out->push_back(static_cast<char>((value & 0x7f) | 0x80));
    value >>= 7;
  }
  out->push_back(static_cast<char>(value));
}

size_t VarintSize(uint64_t value) {
  size_t size = 1;
  while (value >= 0x80) {
    value >>= 7;
    ++size;
  }
  return size;
}

template <typename T>
absl::string_view BytesOf(const std::vector<T>& values) {
  return absl::string_view(reinterpret_cast<const char*>(values.data()),
                           values.size() * sizeof(T));
}

// The record of `batch` as pieces to write in order: first the 12-byte header, left zero for
// the caller to fill, then the payload. The header and the protobuf framing live in `framing`
// (which must outlive the pieces), the point arrays stay in place. The payload is the wire
// format of a PointBatch whose PackedPoints hold the arrays (packed little-endian float32, as
// PackPoints makes them), written without copying the arrays: copies would cost
// more than the write, in fresh pages for each batch.
std::vector<absl::string_view> RecordPieces(const PointCloud& batch, std::string* framing) {
  // PackedPoints fields 1-4 (positions, weights, normals, colors) and PointBatch field 1
  // (packed), all length-delimited.
  constexpr int kArrays = 4;
  constexpr char kArrayTags[kArrays] = {0x0a, 0x12, 0x1a, 0x22};
  constexpr char kPackedTag = 0x0a;
  const absl::string_view arrays[kArrays] = {BytesOf(batch.positions), BytesOf(batch.weights),
                                             BytesOf(batch.normals), BytesOf(batch.colors)};
  size_t packed_size = 0;
  for (const absl::string_view array : arrays) {
    if (!array.empty()) packed_size += 1 + VarintSize(array.size()) + array.size();
  }
  // Where each piece is: a range of `framing` (array -1) or one of the arrays.
  struct Piece {
    size_t begin;
    size_t size;
    int array;
  };
  std::vector<Piece> layout = {{0, kHeaderBytes, -1}};
  framing->assign(kHeaderBytes, '\0');
  auto frame = [&](char tag, size_t size) {
    const size_t begin = framing->size();
    framing->push_back(tag);
    PutVarint(size, framing);
    layout.push_back({begin, framing->size() - begin, -1});
  };
  frame(kPackedTag, packed_size);
  for (int i = 0; i < kArrays; ++i) {
    if (arrays[i].empty()) continue;
    frame(kArrayTags[i], arrays[i].size());
    layout.push_back({0, 0, i});
  }
  std::vector<absl::string_view> pieces;
  const absl::string_view all = *framing;
  for (const Piece& piece : layout) {
    pieces.push_back(piece.array < 0 ? all.substr(piece.begin, piece.size) : arrays[piece.array]);
  }
  return pieces;
}

void PutUint32(uint32_t value, char* out) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<char>((value >> (8 * i)) & 0xff);
}

uint32_t GetUint32(const char* in) {
  uint32_t value = 0;
  for (int i = 0; i < 4; ++i) value |= uint32_t{static_cast<unsigned char>(in[i])} << (8 * i);
  return value;
}

// Writes all of `bytes` at `offset`; the errno of the failure otherwise (ENOSPC for a short
// write that made no progress).
int WriteAll(int fd, absl::string_view bytes, uint64_t offset) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = pwrite(fd, bytes.data() + done, bytes.size() - done,
                             static_cast<off_t>(offset + done));
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return ENOSPC;
    done += static_cast<size_t>(n);
  }
  return 0;
}

// A full disk, a quota or a file size limit: RESOURCE_EXHAUSTED; otherwise errno's code.
absl::Status WriteError(int error, const std::string& what) {
  if (error == ENOSPC || error == EDQUOT || error == EFBIG) {
    return absl::ResourceExhaustedError(absl::StrCat(what, ": ", std::strerror(error)));
  }
  return absl::ErrnoToStatus(error, what);
}

}  // namespace

absl::StatusOr<JournalReadResult> ReadPointsJournal(
    const std::string& path, const std::function<absl::Status(const PointCloud&)>& visit) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    return absl::NotFoundError(absl::StrCat("cannot open '", path, "': ", std::strerror(errno)));
  }
  std::error_code size_error;
  const uint64_t file_size = std::filesystem::file_size(path, size_error);
  JournalReadResult result;
  std::string payload;
  absl::Status status;
  while (true) {
    char header[kHeaderBytes];
    const size_t got = std::fread(header, 1, kHeaderBytes, file);
    if (got == 0 && std::feof(file)) break;
    if (got < kHeaderBytes) {
      result.damage = absl::StrCat("a torn record header at byte ", result.valid_bytes);
      break;
    }
    const uint32_t length = GetUint32(header + 4);
    if (GetUint32(header) != kMagic || length > kMaxPayloadBytes) {
      result.damage = absl::StrCat("no record header at byte ", result.valid_bytes);
      break;
    }
    // A length beyond the end of the file is a torn record, found without allocating for it.
    const uint64_t read_so_far = result.valid_bytes + kHeaderBytes;
    const uint64_t left = size_error ? std::numeric_limits<uint64_t>::max()
                          : file_size > read_so_far ? file_size - read_so_far
                                                    : 0;
    bool torn = length > left;
    if (!torn) {
      payload.resize(length);
      torn = std::fread(payload.data(), 1, length, file) != length;
    }
    if (torn) {
      result.damage = absl::StrCat("a torn record at byte ", result.valid_bytes);
      break;
    }
    v1::PointBatch batch;
    if (Checksum({absl::string_view(payload)}) != GetUint32(header + 8) ||
        !batch.ParseFromString(payload)) {
      result.damage = absl::StrCat("a damaged record at byte ", result.valid_bytes);
      break;
    }
    absl::StatusOr<PointCloud> points =
        PointBatchFromProto(batch, std::numeric_limits<size_t>::max());
    if (!points.ok()) {
      result.damage = absl::StrCat("a record at byte ", result.valid_bytes,
                                   " that holds no batch: ", points.status().message());
      break;
    }
    status = visit(*points);
    if (!status.ok()) break;
    result.valid_bytes += kHeaderBytes + length;
    ++result.batches;
    result.points += points->positions.size();
  }
  std::fclose(file);
  if (!status.ok()) return status;
  return result;
}

absl::StatusOr<std::unique_ptr<PointsJournal>> PointsJournal::Open(const std::string& path,
                                                                   uint64_t valid_bytes,
                                                                   bool sync) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open '", path, "'"));
  if (ftruncate(fd, static_cast<off_t>(valid_bytes)) != 0) {
    const int error = errno;
    close(fd);
    return absl::ErrnoToStatus(error, absl::StrCat("cannot cut '", path, "' to its whole records"));
  }
  return std::unique_ptr<PointsJournal>(new PointsJournal(path, fd, valid_bytes, sync));
}

PointsJournal::~PointsJournal() { close(fd_); }

absl::Status PointsJournal::Append(const PointCloud& batch) {
  std::string framing;
  const std::vector<absl::string_view> pieces = RecordPieces(batch, &framing);
  const absl::Span<const absl::string_view> payload = absl::MakeConstSpan(pieces).subspan(1);
  size_t payload_size = 0;
  for (const absl::string_view piece : payload) payload_size += piece.size();
  if (payload_size > kMaxPayloadBytes) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a batch of ", payload_size, " bytes is too large for the points journal"));
  }
  // pieces[0] views these bytes.
  PutUint32(kMagic, framing.data());
  PutUint32(static_cast<uint32_t>(payload_size), framing.data() + 4);
  PutUint32(Checksum(payload), framing.data() + 8);
  int error = 0;
  uint64_t offset = size_;
  for (const absl::string_view piece : pieces) {
    error = WriteAll(fd_, piece, offset);
    if (error != 0) break;
    offset += piece.size();
  }
  if (error == 0 && sync_ && fdatasync(fd_) != 0) error = errno;
  if (error != 0) {
    // Nothing of the batch may stay: a later record after a torn one would be unreadable.
    (void)!ftruncate(fd_, static_cast<off_t>(size_));
    return WriteError(error, absl::StrCat("cannot store the batch in '", path_, "'"));
  }
  size_ = offset;
  return absl::OkStatus();
}

}  // namespace neuralmesh::server
