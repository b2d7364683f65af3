// E57 files for tests (core/io/internal/e57.h reads them), laid out as ASTM E2807 describes
// them, independently of neuralmesh's writer: the 48-byte header, compressed vector sections of
// data packets (split at any byte, with index and empty packets between them if asked), the
// XML, and 1,024-byte pages that each end in the CRC-32C of their data, most significant byte
// first.
#ifndef NEURALMESH_TESTS_TESTING_E57_FILE_H_
#define NEURALMESH_TESTS_TESTING_E57_FILE_H_

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/internal/binary.h"

namespace neuralmesh::testing {

// One field of a scan's prototype: its XML element and its whole bytestream.
struct E57Field {
  std::string xml;
  std::string stream;
};

struct E57Scan {
  uint64_t records = 0;
  std::vector<E57Field> fields;
  std::string elements;  // More children of the scan's element: <pose>, <colorLimits>, ...
  // Each data packet carries at most this many bytes of each stream (0: all in one packet).
  size_t bytes_per_packet = 0;
  // An empty packet and an index packet before every data packet after the first.
  bool other_packets = false;
};

// `values`, each `bits` wide, packed least significant bit first (E57's bitpack codec).
inline std::string E57PackBits(const std::vector<uint64_t>& values, int bits) {
  std::string out;
  uint64_t bit = 0;
  for (uint64_t value : values) {
    for (int b = 0; b < bits; ++b, ++bit) {
      if (bit / 8 >= out.size()) out.push_back('\0');
      if ((value >> b) & 1) out[bit / 8] = static_cast<char>(out[bit / 8] | (1 << (bit % 8)));
    }
  }
  return out;
}

// Floats or doubles, little-endian.
template <typename T>
std::string E57Floats(const std::vector<T>& values) {
  std::string out;
  for (T value : values) io_internal::AppendLittleEndian(value, &out);
  return out;
}

inline uint32_t E57Crc32c(const std::string& data) {
  uint32_t crc = 0xFFFFFFFFu;
  for (char c : data) {
    crc ^= static_cast<uint8_t>(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0x82F63B78u & (0u - (crc & 1)));
  }
  return ~crc;
}

inline uint64_t E57Physical(uint64_t logical) { return logical / 1020 * 1024 + logical % 1020; }

// The file: header, each scan's section, the XML (`root_children` go into <e57Root> before
// data3D; `xml_override`, when not empty, replaces the whole XML).
inline std::string E57File(const std::vector<E57Scan>& scans, const std::string& root_children = "",
                           const std::string& xml_override = "") {
  using io_internal::AppendLittleEndian;
  std::string logical(48, '\0');
  std::string data3d;
  for (const E57Scan& scan : scans) {
    const uint64_t start = logical.size();
    std::string packets;
    std::vector<size_t> taken(scan.fields.size(), 0);
    for (bool first = true;; first = false) {
      bool any = false;
      for (size_t f = 0; f < scan.fields.size(); ++f)
        any |= taken[f] < scan.fields[f].stream.size();
      if (!any && !first) break;
      if (!first && scan.other_packets) {
        packets += std::string("\x02\x00\x07\x00\x00\x00\x00\x00", 8);  // Empty, 8 bytes.
        std::string index(16, '\0');                                    // Index, no entries.
        index[2] = 15;
        packets += index;
      }
      std::string sizes, buffers;
      for (size_t f = 0; f < scan.fields.size(); ++f) {
        const std::string& stream = scan.fields[f].stream;
        const size_t n =
            std::min(stream.size() - taken[f],
                     scan.bytes_per_packet == 0 ? stream.size() : scan.bytes_per_packet);
        AppendLittleEndian(static_cast<uint16_t>(n), &sizes);
        buffers += stream.substr(taken[f], n);
        taken[f] += n;
      }
      const size_t length = (6 + sizes.size() + buffers.size() + 3) / 4 * 4;
      packets.push_back('\x01');
      packets.push_back('\0');
      AppendLittleEndian(static_cast<uint16_t>(length - 1), &packets);
      AppendLittleEndian(static_cast<uint16_t>(scan.fields.size()), &packets);
      packets += sizes + buffers;
      packets.resize(packets.size() + length - 6 - sizes.size() - buffers.size(), '\0');
      if (!any) break;
    }
    logical.push_back('\x01');
    logical.append(7, '\0');
    AppendLittleEndian(static_cast<uint64_t>(32 + packets.size()), &logical);
    AppendLittleEndian(E57Physical(start + 32), &logical);
    AppendLittleEndian(uint64_t{0}, &logical);
    logical += packets;
    std::string prototype;
    for (const E57Field& field : scan.fields) prototype += field.xml;
    absl::StrAppend(&data3d, "<vectorChild type=\"Structure\"><guid type=\"String\">{scan ", start,
                    "}</guid>", scan.elements, "<points type=\"CompressedVector\" fileOffset=\"",
                    E57Physical(start), "\" recordCount=\"", scan.records,
                    "\"><prototype type=\"Structure\">", prototype,
                    "</prototype><codecs type=\"Vector\"/></points></vectorChild>");
  }
  const std::string xml =
      !xml_override.empty()
          ? xml_override
          : absl::StrCat("<?xml version=\"1.0\"?>\n<e57Root type=\"Structure\">",
                         "<formatName type=\"String\">ASTM E57 3D Imaging Data File</formatName>"
                         "<guid type=\"String\">{test}</guid>"
                         "<versionMajor type=\"Integer\">1</versionMajor>"
                         "<versionMinor type=\"Integer\">0</versionMinor>",
                         root_children, "<data3D type=\"Vector\">", data3d,
                         "</data3D><images2D type=\"Vector\"/></e57Root>\n");
  const uint64_t xml_start = logical.size();
  logical += xml;
  const uint64_t pages = (logical.size() + 1019) / 1020;
  std::string header = "ASTM-E57";
  AppendLittleEndian(uint32_t{1}, &header);
  AppendLittleEndian(uint32_t{0}, &header);
  AppendLittleEndian(pages * 1024, &header);
  AppendLittleEndian(E57Physical(xml_start), &header);
  AppendLittleEndian(static_cast<uint64_t>(xml.size()), &header);
  AppendLittleEndian(uint64_t{1024}, &header);
  logical.replace(0, 48, header);
  logical.resize(pages * 1020, '\0');
  std::string file;
  for (uint64_t page = 0; page < pages; ++page) {
    const std::string data = logical.substr(page * 1020, 1020);
    const uint32_t crc = E57Crc32c(data);
    file += data;
    for (int shift = 24; shift >= 0; shift -= 8) file.push_back(static_cast<char>(crc >> shift));
  }
  return file;
}

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_E57_FILE_H_
