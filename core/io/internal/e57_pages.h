// The physical layer of ASTM E57 files (.e57): the file is a sequence of 1,024-byte pages, each
// 1,020 bytes of data followed by the CRC-32C of those bytes. Offsets in the file's header and
// XML are physical (they count the checksums); the data they point to is read in the logical
// byte stream, the pages' data bytes one after another.
#ifndef NEURALMESH_CORE_IO_INTERNAL_E57_PAGES_H_
#define NEURALMESH_CORE_IO_INTERNAL_E57_PAGES_H_

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/internal/binary.h"

namespace neuralmesh::io_internal {

inline constexpr uint64_t kE57PageSize = 1024;
inline constexpr uint64_t kE57PageDataSize = 1020;

// The CRC-32C (Castagnoli) of `data`, as E57 computes it.
uint32_t Crc32c(absl::string_view data);

// The logical offset of physical offset `physical`, which must not fall on a checksum.
inline uint64_t E57LogicalOffset(uint64_t physical) {
  return physical / kE57PageSize * kE57PageDataSize + physical % kE57PageSize;
}
inline uint64_t E57PhysicalOffset(uint64_t logical) {
  return logical / kE57PageDataSize * kE57PageSize + logical % kE57PageDataSize;
}
// Whether physical offset `physical` falls on a page's checksum.
inline bool IsE57Checksum(uint64_t physical) { return physical % kE57PageSize >= kE57PageDataSize; }

// The logical bytes of a file, read where they lie: copies out of it skip the checksums.
class E57LogicalView {
 public:
  // Checks every page's checksum first. Returns INVALID_ARGUMENT for a file that is not a whole
  // number of pages or a page whose checksum does not match (naming the page: the file is
  // damaged).
  static absl::StatusOr<E57LogicalView> Open(absl::string_view file);

  uint64_t size() const { return size_; }
  // Appends the logical bytes [offset, offset + count), which must lie within size(), to `out`.
  void Append(uint64_t offset, uint64_t count, std::string* out) const;
  // The little-endian T at `offset` (its bytes within size()).
  template <typename T>
  T Load(uint64_t offset) const {
    std::string bytes;
    Append(offset, sizeof(T), &bytes);
    return LoadScalar<T>(bytes.data(), /*big_endian=*/false);
  }

 private:
  explicit E57LogicalView(absl::string_view file)
      : file_(file), size_(file.size() / kE57PageSize * kE57PageDataSize) {}

  absl::string_view file_;
  uint64_t size_;
};

// The pages of a file whose logical bytes are `logical`: zero-padded to a whole page, each page
// followed by its checksum.
std::string E57Pages(absl::string_view logical);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_E57_PAGES_H_
