#include "core/io/internal/e57_pages.h"

#include <algorithm>
#include <array>

#include "absl/strings/str_cat.h"

namespace neuralmesh::io_internal {
namespace {

// The table of the reflected CRC-32C polynomial 0x82F63B78.
std::array<uint32_t, 256> MakeCrc32cTable() {
  std::array<uint32_t, 256> table{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t crc = i;
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ ((crc & 1) != 0 ? 0x82F63B78u : 0u);
    table[i] = crc;
  }
  return table;
}

// E57 stores a page's checksum most significant byte first.
void AppendChecksum(uint32_t crc, std::string* out) {
  for (int shift = 24; shift >= 0; shift -= 8) out->push_back(static_cast<char>(crc >> shift));
}

}  // namespace

uint32_t Crc32c(absl::string_view data) {
  static const std::array<uint32_t, 256> kTable = MakeCrc32cTable();
  uint32_t crc = 0xFFFFFFFFu;
  for (char c : data) crc = kTable[(crc ^ static_cast<uint8_t>(c)) & 0xFF] ^ (crc >> 8);
  return crc ^ 0xFFFFFFFFu;
}

absl::StatusOr<E57LogicalView> E57LogicalView::Open(absl::string_view file) {
  if (file.empty() || file.size() % kE57PageSize != 0) {
    return absl::InvalidArgumentError(absl::StrCat("E57: the file's ", file.size(),
                                                   " bytes are not a whole number of ",
                                                   kE57PageSize, "-byte pages (truncated?)"));
  }
  for (uint64_t page = 0; page < file.size() / kE57PageSize; ++page) {
    std::string expected;
    AppendChecksum(Crc32c(file.substr(page * kE57PageSize, kE57PageDataSize)), &expected);
    if (file.substr(page * kE57PageSize + kE57PageDataSize, 4) != expected) {
      return absl::InvalidArgumentError(absl::StrCat(
          "E57: the checksum of page ", page, " (bytes ", page * kE57PageSize, " to ",
          (page + 1) * kE57PageSize - 1, ") does not match its data: the file is damaged"));
    }
  }
  return E57LogicalView(file);
}

void E57LogicalView::Append(uint64_t offset, uint64_t count, std::string* out) const {
  while (count > 0) {
    const uint64_t in_page = offset % kE57PageDataSize;
    const uint64_t n = std::min(count, kE57PageDataSize - in_page);
    out->append(file_.data() + E57PhysicalOffset(offset), n);
    offset += n;
    count -= n;
  }
}

std::string E57Pages(absl::string_view logical) {
  const uint64_t pages = (logical.size() + kE57PageDataSize - 1) / kE57PageDataSize;
  std::string file;
  file.reserve(pages * kE57PageSize);
  for (uint64_t page = 0; page < pages; ++page) {
    std::string data(logical.substr(page * kE57PageDataSize, kE57PageDataSize));
    data.resize(kE57PageDataSize, '\0');
    file += data;
    AppendChecksum(Crc32c(data), &file);
  }
  return file;
}

}  // namespace neuralmesh::io_internal
