// A LAS or LAZ file described for reports, as lasinfo and `pdal info` describe one: its
// version, point format and records, scale and offset, coordinate system, classes, and how a
// LAZ file is compressed.
#ifndef NEURALMESH_CORE_IO_LAS_DESCRIPTION_H_
#define NEURALMESH_CORE_IO_LAS_DESCRIPTION_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace neuralmesh {

// What a LAS or LAZ file's header and records say of it, for reports (`neuralmesh stats`).
struct LasDescription {
  int version_minor = 0;  // LAS 1.version_minor.
  int point_format = 0;
  size_t record_length = 0;
  size_t extra_bytes = 0;  // After the format's fields.
  uint64_t records = 0;
  std::array<double, 3> scale{}, offset{};
  std::string generating_software;
  bool standard_gps_time = false;  // Adjusted standard GPS time, else GPS week time.
  // The coordinate system's records: "WKT" (LASF_Projection 2112), "GeoTIFF" (34735), or
  // empty for none.
  std::string coordinate_system;
  uint32_t variable_length_records = 0;
  uint64_t withheld = 0;
  std::vector<uint64_t> records_by_class;  // 256 classes (0-31 in formats 0-5), withheld too.
  // LAZ: how the records are compressed (internal/laz.h, DescribeLazCompression); empty for LAS.
  std::string compression;
  size_t file_bytes = 0;
};

// Describes the LAS or LAZ file at `path`.
// Returns NOT_FOUND when it cannot be read; INVALID_ARGUMENT, naming it, when it is not a .las
// or .laz file or is malformed (ReadPointCloud's errors).
absl::StatusOr<LasDescription> DescribeLasFile(const std::string& path);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_IO_LAS_DESCRIPTION_H_
