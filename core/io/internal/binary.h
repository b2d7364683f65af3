// Fixed-width little- and big-endian scalars for the binary formats (PLY, STL, LAS).
#ifndef NEURALMESH_CORE_IO_INTERNAL_BINARY_H_
#define NEURALMESH_CORE_IO_INTERNAL_BINARY_H_

#include <algorithm>
#include <cstring>
#include <string>

namespace neuralmesh::io_internal {

inline constexpr bool kHostIsBigEndian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;

// Reads a T stored at `p` (no alignment needed) in big- or little-endian byte order.
template <typename T>
T LoadScalar(const char* p, bool big_endian) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (big_endian != kHostIsBigEndian) std::reverse(bytes, bytes + sizeof(T));
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

// Appends `value` to `out` in little-endian byte order.
template <typename T>
void AppendLittleEndian(T value, std::string* out) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (kHostIsBigEndian) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

// Writes `value` over the sizeof(T) bytes of `out` from `offset` (which must lie within it),
// in little-endian byte order.
template <typename T>
void StoreLittleEndian(T value, size_t offset, std::string* out) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (kHostIsBigEndian) std::reverse(bytes, bytes + sizeof(T));
  std::memcpy(out->data() + offset, bytes, sizeof(T));
}

// Writes `value` in little-endian byte order to the sizeof(T) bytes at `p` (no alignment
// needed).
template <typename T>
void StoreLittleEndian(T value, void* p) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (kHostIsBigEndian) std::reverse(bytes, bytes + sizeof(T));
  std::memcpy(p, bytes, sizeof(T));
}

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_BINARY_H_
