// Where the fields of a LAS file's public header block and variable-length records are (LAS
// 1.4, Tables 3 and 4; earlier versions share the first 227 bytes of the header), for the LAS
// reader and writers and the LAZ codec.
#ifndef NEURALMESH_CORE_IO_INTERNAL_LAS_LAYOUT_H_
#define NEURALMESH_CORE_IO_INTERNAL_LAS_LAYOUT_H_

#include <cstddef>
#include <cstdint>

namespace neuralmesh::io_internal::las_layout {

constexpr size_t kGlobalEncoding = 6;  // uint16; bit 0: GPS times are adjusted standard time.
constexpr size_t kVersionMajor = 24;
constexpr size_t kVersionMinor = 25;
constexpr size_t kGeneratingSoftware = 58;  // 32 characters.
constexpr size_t kHeaderSize = 94;
constexpr size_t kOffsetToPoints = 96;
constexpr size_t kVlrCount = 100;
constexpr size_t kPointFormat = 104;
constexpr size_t kRecordLength = 105;
constexpr size_t kLegacyPointCount = 107;
constexpr size_t kLegacyByReturn = 111;  // Returns 1-5: uint32 each.
constexpr size_t kScale = 131;           // x, y, z: doubles.
constexpr size_t kOffset = 155;          // x, y, z: doubles.
constexpr size_t kBounds = 179;          // Max x, min x, max y, ...: doubles.
constexpr size_t kLegacyHeaderSize = 227;
constexpr size_t kWaveformStart = 227;  // LAS 1.3 and 1.4: uint64.
constexpr size_t kHeaderSize13 = 235;
constexpr size_t kEvlrStart = 235;   // LAS 1.4: uint64.
constexpr size_t kPointCount = 247;  // LAS 1.4: uint64.
constexpr size_t kByReturn14 = 255;  // Returns 1-15: uint64 each.
constexpr size_t kHeaderSize14 = 375;

// A variable-length record's header: reserved (2 bytes), user id (16 characters), record id
// (uint16), length after the header (uint16), description (32 characters).
constexpr size_t kVlrUser = 2;
constexpr size_t kVlrRecordId = 18;
constexpr size_t kVlrLength = 20;
constexpr size_t kVlrHeaderSize = 54;

// Format bits that LASzip sets on compressed (LAZ) files.
constexpr uint8_t kCompressedBits = 0xC0;

}  // namespace neuralmesh::io_internal::las_layout

#endif  // NEURALMESH_CORE_IO_INTERNAL_LAS_LAYOUT_H_
