#include "core/io/internal/ply_vertex_records.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/io/internal/ply.h"
#include "core/io/internal/ply_header.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

absl::Status Invalid(absl::string_view message) {
  return absl::InvalidArgumentError(absl::StrCat("PLY: ", message));
}

// The size of one record of `element`, or an error for a list property.
absl::StatusOr<size_t> RecordSize(const PlyElement& element) {
  size_t size = 0;
  for (const PlyProperty& property : element.properties) {
    if (property.is_list) {
      return Invalid(absl::StrCat(
          "element '", element.name, "' has the list property '", property.name,
          "': its records differ in size, so none can be found without reading those before"));
    }
    size += PlyTypeSize(property.type);
  }
  return size;
}

class VertexRecords final : public PointRecords {
 public:
  VertexRecords(absl::string_view data, size_t first, size_t length, uint64_t count,
                bool big_endian, bool has_colors)
      : data_(data),
        first_(first),
        length_(length),
        count_(count),
        big_endian_(big_endian),
        has_colors_(has_colors) {}

  void SetAxis(int c, size_t offset, PlyType type) {
    offsets_[c] = offset;
    types_[c] = type;
  }

  uint64_t size() const override { return count_; }
  // Kept when its coordinates are finite.
  std::optional<Point3d> KeptPoint(uint64_t i) const override {
    const char* record = Address(i);
    Point3d p;
    for (int c = 0; c < 3; ++c) {
      p[c] = LoadPlyValue(record + offsets_[c], types_[c], big_endian_);
      if (!std::isfinite(p[c])) return std::nullopt;
    }
    return p;
  }
  const char* Address(uint64_t i) const override { return data_.data() + first_ + i * length_; }
  bool has_colors() const override { return has_colors_; }
  std::optional<Point3d> Resolution() const override { return std::nullopt; }
  std::optional<std::pair<Point3d, Point3d>> StatedBounds() const override { return std::nullopt; }

 private:
  absl::string_view data_;
  size_t first_, length_;
  uint64_t count_;
  bool big_endian_, has_colors_;
  size_t offsets_[3] = {0, 0, 0};
  PlyType types_[3] = {PlyType::kFloat32, PlyType::kFloat32, PlyType::kFloat32};
};

}  // namespace

absl::StatusOr<std::unique_ptr<PointRecords>> PlyVertexRecords(absl::string_view data) {
  NM_ASSIGN_OR_RETURN(const PlyHeader header, ParsePlyHeader(data));
  if (header.format == PlyFormat::kAscii) {
    return Invalid(
        "the body is ASCII: its lines differ in length, so none can be found "
        "without reading those before");
  }
  size_t at = header.body_offset;
  for (const PlyElement& element : header.elements) {
    NM_ASSIGN_OR_RETURN(const size_t length, RecordSize(element));
    const size_t left = data.size() - at;
    if (length > 0 && element.count > left / length) {
      return Invalid(absl::StrCat(element.count, " records of element '", element.name, "' (",
                                  length, " bytes each) from byte ", at,
                                  " do not fit in the file's ", data.size(), " bytes"));
    }
    if (element.name != "vertex") {
      at += element.count * length;
      continue;
    }
    NM_ASSIGN_OR_RETURN(const PlyVertexLayout layout, FindPlyVertexLayout(element));
    auto records = std::make_unique<VertexRecords>(data, at, length, element.count,
                                                   header.format == PlyFormat::kBinaryBigEndian,
                                                   layout.has_colors);
    for (int c = 0; c < 3; ++c) {
      size_t offset = 0;
      for (int i = 0; i < layout.axes[c]; ++i) {
        offset += PlyTypeSize(element.properties[i].type);
      }
      records->SetAxis(c, offset, element.properties[layout.axes[c]].type);
    }
    return records;
  }
  return Invalid("no 'vertex' element");
}

}  // namespace neuralmesh::io_internal
