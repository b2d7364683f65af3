// LAS files whose records look like an airborne scan, every field of formats 0 to 3 and 6 to 8
// in use: pulses along flight lines with first and last returns, intensities, classes (and
// LAS 1.4's classification flags), scan angles and directions, edge flags, point sources, GPS
// times in interleaved sequences, the scanner channels of a multi-beam system, colours (grey
// and not), near infrared and extra bytes; optionally with records of random bytes among them,
// the extremes a coder must also take. For the LAZ codec's tests (core/io/internal/laz.h).
#ifndef NEURALMESH_TESTS_TESTING_LAS_SCAN_H_
#define NEURALMESH_TESTS_TESTING_LAS_SCAN_H_

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "tests/testing/las_file.h"

namespace neuralmesh::testing {

struct LasScan {
  int version_minor = 2;  // 4 for formats 6 to 8 whatever it says.
  int format = 0;         // 0 to 3, 6 to 8.
  int extra_bytes = 0;    // After the format's fields.
  // Formats 6-8: the pulses of this many scanner channels (1 to 4) take turns, three by three.
  int scanner_channels = 1;
  size_t records = 0;
  // One record in this many is random bytes (0: none).
  size_t random_every = 0;
  uint32_t seed = 1;
  // Variable-length records before the points, extended ones after them (LAS 1.4).
  std::string vlrs;
  uint32_t vlr_count = 0;
  std::string after_points;
  uint32_t evlr_count = 0;
};

// A LAS 1.4 scan of `format` with a coordinate system's record before its points and an
// extended record after them.
inline LasScan Las14Scan(int format, size_t records) {
  LasScan scan;
  scan.version_minor = 4;
  scan.format = format;
  scan.records = records;
  scan.vlrs = LasVariableLengthRecord("LASF_Projection", 2112, "PROJCS[\"UTM 32N\"]",
                                      /*extended=*/false);
  scan.vlr_count = 1;
  scan.after_points = LasVariableLengthRecord("tile_notes", 1, "notes", /*extended=*/true);
  scan.evlr_count = 1;
  return scan;
}

inline std::string ScanLasFile(const LasScan& scan) {
  LasLayout layout;
  layout.version_minor = scan.format >= 6 ? 4 : scan.version_minor;
  layout.format = scan.format;
  const int length = kLasRecordLength[scan.format] + scan.extra_bytes;
  layout.record_length = length;
  layout.vlrs = scan.vlrs;
  layout.vlr_count = scan.vlr_count;
  layout.after_points = scan.after_points;
  layout.evlr_count = scan.evlr_count;
  std::vector<LasPoint> points(scan.records, LasPoint{0, 0, 0});
  std::string file = LasFile(layout, points);
  const size_t first = file.size() - scan.after_points.size() - scan.records * length;
  std::mt19937 random(scan.seed);
  std::uniform_int_distribution<int> byte(0, 255);
  size_t pulse = 0;
  int return_number = 1, returns = 1;
  for (size_t i = 0; i < scan.records; ++i) {
    char* record = &file[first + i * length];
    if (scan.random_every != 0 && i % scan.random_every == scan.random_every - 1) {
      for (int k = 0; k < length; ++k) record[k] = static_cast<char>(byte(random));
      continue;
    }
    if (return_number == returns) {  // The next pulse: one return in four has two.
      ++pulse;
      return_number = 1;
      returns = random() % 4 == 0 ? 2 : 1;
    } else {
      ++return_number;
    }
    const size_t line = pulse / 1500, along = pulse % 1500;
    const int32_t x = static_cast<int32_t>(100000 + along * 35 + random() % 7);
    const int32_t y = static_cast<int32_t>(200000 + line * 900 + (along % 300) * 3);
    const int32_t z =
        static_cast<int32_t>(5000 + 300 * std::sin(x * 1e-4) + 200 * std::cos(y * 1e-4) -
                             (return_number == 2 ? 150 + random() % 40 : 0));
    const uint16_t intensity =
        static_cast<uint16_t>((return_number == 1 ? 800 : 300) + random() % 120);
    std::string fields;
    io_internal::AppendLittleEndian(x, &fields);
    io_internal::AppendLittleEndian(y, &fields);
    io_internal::AppendLittleEndian(z, &fields);
    io_internal::AppendLittleEndian(intensity, &fields);
    const bool edge = along == 0 || along == 1499;
    const char classification = random() % 50 == 0 ? 7 : return_number == returns ? 2 : 1;
    const char user_data = random() % 200 == 0 ? 5 : 0;
    const int angle = -20 + static_cast<int>(along * 40 / 1500);
    if (scan.format >= 6) {
      // Returns in 4 bits each; classification flags (an overlap now and then), the channel,
      // the scan direction and the edge; the class; the user data; the angle in 0.006 degrees.
      const int channel = static_cast<int>(pulse / 3 % scan.scanner_channels);
      fields += static_cast<char>(return_number | returns << 4);
      fields += static_cast<char>((random() % 100 == 0 ? 8 : 0) | channel << 4 | (line % 2) << 6 |
                                  edge << 7);
      fields += classification;
      fields += user_data;
      io_internal::AppendLittleEndian(static_cast<int16_t>(angle * 167 + pulse % 5), &fields);
    } else {
      fields += static_cast<char>(return_number | returns << 3 | (line % 2) << 6 | edge << 7);
      fields += classification;
      fields += static_cast<char>(static_cast<int8_t>(angle));
      fields += user_data;
    }
    io_internal::AppendLittleEndian(static_cast<uint16_t>(1 + line), &fields);
    std::memcpy(record, fields.data(), fields.size());
    if (kLasGpsTimeOffset[scan.format] != 0) {
      // Two aircraft's clocks, taking turns every 4,000 pulses; the returns of a pulse share
      // its time.
      const bool second = pulse / 4000 % 2 == 1;
      const double time = (second ? 4.5e8 : 3.0e5) + pulse * 1.5e-5;
      std::string bytes;
      io_internal::AppendLittleEndian(time, &bytes);
      std::memcpy(record + kLasGpsTimeOffset[scan.format], bytes.data(), 8);
    }
    if (kLasRgbOffset[scan.format] != 0) {
      const uint16_t red = static_cast<uint16_t>((90 + x % 60) * 256);
      const bool grey = line % 3 == 0;
      std::string bytes;
      for (const uint16_t channel :
           {red, static_cast<uint16_t>(grey ? red : red + 2560 + random() % 512),
            static_cast<uint16_t>(grey ? red : red / 2 + random() % 256)}) {
        io_internal::AppendLittleEndian(channel, &bytes);
      }
      std::memcpy(record + kLasRgbOffset[scan.format], bytes.data(), 6);
    }
    if (scan.format == 8) {  // The near infrared, after the colour.
      std::string bytes;
      io_internal::AppendLittleEndian(static_cast<uint16_t>(20000 + z * 3 + random() % 64), &bytes);
      std::memcpy(record + kLasRgbOffset[scan.format] + 6, bytes.data(), 2);
    }
    for (int k = 0; k < scan.extra_bytes; ++k) {
      record[kLasRecordLength[scan.format] + k] = static_cast<char>((pulse >> (2 * k)) & 0xFF);
    }
  }
  return file;
}

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_LAS_SCAN_H_
