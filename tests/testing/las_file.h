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
  uint16_t intensity = 0;
  uint8_t return_number = 1;  // Of `returns`.
  uint8_t returns = 1;
  double gps_time = 0;  // In the formats that hold it (1, 3-10).
  uint32_t extra = 0;   // In the record's extra bytes, when its length leaves 4 of them.
};

struct LasLayout {
  int version_minor = 2;
  int format = 0;
  int record_length = 0;  // 0: the format's own.
  double scale[3] = {0.01, 0.01, 0.01};
  double offset[3] = {0, 0, 0};
  // Variable-length records (raw bytes) between the header and the points, and how many.
  std::string vlrs;
  uint32_t vlr_count = 0;
  // Bytes after the points: LAS 1.3's waveform data or LAS 1.4's extended records (as many as
  // evlr_count), whose start the header gives.
  std::string after_points;
  uint32_t evlr_count = 0;
};

// The record length, the red channel's and the GPS time's places of each point format (0:
// none).
inline constexpr int kLasRecordLength[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
inline constexpr int kLasRgbOffset[] = {0, 0, 20, 28, 0, 28, 0, 30, 30, 0, 30};
inline constexpr int kLasGpsTimeOffset[] = {0, 20, 0, 20, 20, 20, 22, 22, 22, 22, 22};

// A (extended) variable-length record: its header of 54 (60) bytes, then `payload`.
inline std::string LasVariableLengthRecord(const std::string& user_id, uint16_t record_id,
                                           const std::string& payload, bool extended) {
  std::string out;
  io_internal::AppendLittleEndian<uint16_t>(0, &out);  // Reserved.
  out.append(user_id);
  out.resize(18, '\0');
  io_internal::AppendLittleEndian(record_id, &out);
  if (extended) {
    io_internal::AppendLittleEndian<uint64_t>(payload.size(), &out);
  } else {
    io_internal::AppendLittleEndian<uint16_t>(payload.size(), &out);
  }
  out.append("a record the tests made");
  out.resize(extended ? 60 : 54, '\0');
  out.append(payload);
  return out;
}

// A LAS file as the specification lays it out: the public header block (227 bytes for 1.2,
// 235 for 1.3, 375 for 1.4), the layout's variable-length records, the point records and the
// layout's bytes after them.
// LAS 1.4 of point format `format` in UTM millimetres, as a georeferenced scan: scale 0.001,
// offset (500000, 4100000, 0).
inline LasLayout UtmMillimetreLayout(int format) {
  LasLayout layout;
  layout.version_minor = 4;
  layout.format = format;
  for (double& s : layout.scale) s = 0.001;
  layout.offset[0] = 500000;
  layout.offset[1] = 4100000;
  return layout;
}

inline std::string LasFile(const LasLayout& layout, const std::vector<LasPoint>& points) {
  const bool v14 = layout.version_minor >= 4;
  const size_t header_size = v14 ? 375 : layout.version_minor == 3 ? 235 : 227;
  const int record_length =
      layout.record_length > 0 ? layout.record_length : kLasRecordLength[layout.format];
  std::string out = "LASF";
  out.resize(24, '\0');
  out += static_cast<char>(1);
  out += static_cast<char>(layout.version_minor);
  out.resize(94, '\0');
  io_internal::AppendLittleEndian<uint16_t>(header_size, &out);
  const size_t offset_to_points = header_size + layout.vlrs.size();
  io_internal::AppendLittleEndian<uint32_t>(offset_to_points, &out);
  io_internal::AppendLittleEndian<uint32_t>(layout.vlr_count, &out);
  out += static_cast<char>(layout.format);
  io_internal::AppendLittleEndian<uint16_t>(record_length, &out);
  io_internal::AppendLittleEndian<uint32_t>(v14 ? 0 : points.size(), &out);  // Legacy count.
  for (int r = 1; r <= 5; ++r) {  // Legacy counts by return.
    uint32_t n = 0;
    for (const LasPoint& p : points) n += !v14 && p.return_number == r;
    io_internal::AppendLittleEndian(n, &out);
  }
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
  const uint64_t points_end = offset_to_points + points.size() * uint64_t(record_length);
  const uint64_t after_start = layout.after_points.empty() ? 0 : points_end;
  if (layout.version_minor >= 3) {  // Start of the waveform data: after the points in 1.3.
    io_internal::AppendLittleEndian<uint64_t>(v14 ? 0 : after_start, &out);
  }
  if (v14) {
    io_internal::AppendLittleEndian<uint64_t>(after_start, &out);  // Start of the EVLRs.
    io_internal::AppendLittleEndian<uint32_t>(layout.evlr_count, &out);
    io_internal::AppendLittleEndian<uint64_t>(points.size(), &out);
    for (int r = 1; r <= 15; ++r) {
      uint64_t n = 0;
      for (const LasPoint& p : points) n += p.return_number == r;
      io_internal::AppendLittleEndian(n, &out);
    }
  }
  out.resize(header_size, '\0');
  out += layout.vlrs;
  for (const LasPoint& p : points) {
    std::string record(record_length, '\0');
    std::string fields;
    io_internal::AppendLittleEndian(p.x, &fields);
    io_internal::AppendLittleEndian(p.y, &fields);
    io_internal::AppendLittleEndian(p.z, &fields);
    io_internal::AppendLittleEndian(p.intensity, &fields);
    record.replace(0, 14, fields);
    record[14] = static_cast<char>(layout.format >= 6 ? p.return_number | p.returns << 4
                                                     : p.return_number | p.returns << 3);
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
    if (kLasGpsTimeOffset[layout.format] != 0) {
      std::string time;
      io_internal::AppendLittleEndian(p.gps_time, &time);
      record.replace(kLasGpsTimeOffset[layout.format], 8, time);
    }
    if (record_length >= kLasRecordLength[layout.format] + 4) {
      std::string extra;
      io_internal::AppendLittleEndian(p.extra, &extra);
      record.replace(kLasRecordLength[layout.format], 4, extra);
    }
    out += record;
  }
  out += layout.after_points;
  return out;
}

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_LAS_FILE_H_
