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

// Where a scalar property lies in a record, and its type.
struct Field {
  size_t offset = 0;
  PlyType type = PlyType::kFloat32;
};

class VertexRecords final : public PointRecords {
 public:
  VertexRecords(absl::string_view data, size_t first, size_t length, uint64_t count,
                bool big_endian)
      : data_(data), first_(first), length_(length), count_(count), big_endian_(big_endian) {}

  void SetAxis(int c, Field field) { axes_[c] = field; }
  void SetChannel(int c, Field field, double scale) {
    channels_[c] = field;
    channel_scales_[c] = scale;
    has_colors_ = true;
  }

  uint64_t size() const override { return count_; }
  // Kept when its coordinates are finite.
  std::optional<Point3d> KeptPoint(uint64_t i) const override {
    const char* record = Address(i);
    Point3d p;
    for (int c = 0; c < 3; ++c) {
      p[c] = LoadPlyValue(record + axes_[c].offset, axes_[c].type, big_endian_);
      if (!std::isfinite(p[c])) return std::nullopt;
    }
    return p;
  }
  const char* Address(uint64_t i) const override { return data_.data() + first_ + i * length_; }
  bool has_colors() const override { return has_colors_; }
  // As ParsePly scales the channels.
  std::optional<Rgb> StatedColor(uint64_t i) const override {
    if (!has_colors_) return std::nullopt;
    const char* record = Address(i);
    Rgb color;
    for (int c = 0; c < 3; ++c) {
      color[c] = ChannelFromLevel(
          LoadPlyValue(record + channels_[c].offset, channels_[c].type, big_endian_),
          channel_scales_[c]);
    }
    return color;
  }
  std::optional<Point3d> Resolution() const override { return std::nullopt; }
  std::optional<std::pair<Point3d, Point3d>> StatedBounds() const override { return std::nullopt; }

 private:
  absl::string_view data_;
  size_t first_, length_;
  uint64_t count_;
  bool big_endian_;
  bool has_colors_ = false;
  Field axes_[3];
  Field channels_[3];
  double channel_scales_[3] = {1, 1, 1};
};

// Where property `index` of `element` lies in its records (none of them lists).
Field FieldOf(const PlyElement& element, int index) {
  Field field{0, element.properties[index].type};
  for (int i = 0; i < index; ++i) field.offset += PlyTypeSize(element.properties[i].type);
  return field;
}

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
                                                   header.format == PlyFormat::kBinaryBigEndian);
    for (int c = 0; c < 3; ++c) {
      records->SetAxis(c, FieldOf(element, layout.axes[c]));
      if (layout.has_colors()) {
        records->SetChannel(c, FieldOf(element, layout.channels[c]), layout.channel_scales[c]);
      }
    }
    return records;
  }
  return Invalid("no 'vertex' element");
}

}  // namespace neuralmesh::io_internal
