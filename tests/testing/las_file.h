// LAS files for tests (core/io/internal/las.h reads them): the public header block of LAS 1.2
// or 1.4 and point records of any format, as the ASPRS specification lays them out.
#ifndef NEURALMESH_TESTS_TESTING_LAS_FILE_H_
#define NEURALMESH_TESTS_TESTING_LAS_FILE_H_

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "core/io/internal/binary.h"

namespace neuralmesh::testing {

struct LasPoint {
  int32_t x, y, z;
  uint16_t red = 0, green = 0, blue = 0;
  uint8_t classification = 0;  // ASPRS class: 2 ground, 7 low noise, 18 high noise, ...
  bool withheld = false;
};

struct LasLayout {
  int version_minor = 2;
  int format = 0;
  int record_length = 0;  // 0: the format's own.
  double scale[3] = {0.01, 0.01, 0.01};
  double offset[3] = {0, 0, 0};
};

// The record length and the red channel's place of each point format (0: no colour).
inline constexpr int kLasRecordLength[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
inline constexpr int kLasRgbOffset[] = {0, 0, 20, 28, 0, 28, 0, 30, 30, 0, 30};

// A LAS file as the specification lays it out: the public header block (227 bytes for 1.2,
// 375 for 1.4), no variable-length records, the point records.
inline std::string LasFile(const LasLayout& layout, const std::vector<LasPoint>& points) {
  const bool v14 = layout.version_minor >= 4;
  const size_t header_size = v14 ? 375 : 227;
  const int record_length =
      layout.record_length > 0 ? layout.record_length : kLasRecordLength[layout.format];
  std::string out = "LASF";
  out.resize(24, '\0');
  out += static_cast<char>(1);
  out += static_cast<char>(layout.version_minor);
  out.resize(94, '\0');
  io_internal::AppendLittleEndian<uint16_t>(header_size, &out);
  io_internal::AppendLittleEndian<uint32_t>(header_size, &out);  // Offset to the point data.
  io_internal::AppendLittleEndian<uint32_t>(0, &out);            // Variable-length records.
  out += static_cast<char>(layout.format);
  io_internal::AppendLittleEndian<uint16_t>(record_length, &out);
  io_internal::AppendLittleEndian<uint32_t>(v14 ? 0 : points.size(), &out);  // Legacy count.
  out.resize(131, '\0');
  for (double s : layout.scale) io_internal::AppendLittleEndian(s, &out);
  for (double o : layout.offset) io_internal::AppendLittleEndian(o, &out);
  for (int c = 0; c < 3; ++c) {
    int32_t low = INT32_MAX, high = INT32_MIN;
    for (const LasPoint& p : points) {
      const int32_t v = c == 0 ? p.x : c == 1 ? p.y : p.z;
      low = std::min(low, v);
      high = std::max(high, v);
    }
    io_internal::AppendLittleEndian(high * layout.scale[c] + layout.offset[c], &out);
    io_internal::AppendLittleEndian(low * layout.scale[c] + layout.offset[c], &out);
  }
  out.resize(227, '\0');
  if (v14) {
    out.resize(247, '\0');
    io_internal::AppendLittleEndian<uint64_t>(points.size(), &out);
    out.resize(375, '\0');
  }
  for (const LasPoint& p : points) {
    std::string record(record_length, '\0');
    std::string fields;
    io_internal::AppendLittleEndian(p.x, &fields);
    io_internal::AppendLittleEndian(p.y, &fields);
    io_internal::AppendLittleEndian(p.z, &fields);
    record.replace(0, 12, fields);
    // Formats 0-5: the class in the low five bits of byte 15, withheld in its top bit; formats
    // 6-10: withheld in bit 2 of byte 15, the class in byte 16.
    if (layout.format >= 6) {
      record[15] = static_cast<char>(p.withheld ? 0x04 : 0);
      record[16] = static_cast<char>(p.classification);
    } else {
      record[15] = static_cast<char>((p.classification & 0x1F) | (p.withheld ? 0x80 : 0));
    }
    if (kLasRgbOffset[layout.format] != 0) {
      std::string rgb;
      for (uint16_t channel : {p.red, p.green, p.blue})
        io_internal::AppendLittleEndian(channel, &rgb);
      record.replace(kLasRgbOffset[layout.format], 6, rgb);
    }
    out += record;
  }
  return out;
}

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_LAS_FILE_H_
