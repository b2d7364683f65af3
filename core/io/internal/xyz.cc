#include "core/io/internal/xyz.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"
#include "core/rgb.h"

namespace neuralmesh::io_internal {
namespace {

// More columns than this are not a point list, header or not.
constexpr size_t kMaxColumns = 64;

// Three consecutive columns from `first`.
std::array<int, 3> Triple(int first) { return {first, first + 1, first + 2}; }

bool IsOneOf(absl::string_view name, std::initializer_list<absl::string_view> names) {
  for (absl::string_view candidate : names) {
    if (absl::EqualsIgnoreCase(name, candidate)) return true;
  }
  return false;
}

// The rows' values past x, y, z: row i's column k (k >= 3) at i * stride + k - 3.
struct ExtraColumns {
  std::vector<float> values;
  size_t stride = 0;

  size_t rows() const { return stride == 0 ? 0 : values.size() / stride; }
  float at(size_t row, int column) const { return values[row * stride + column - 3]; }
};

// Whether every row's columns `first`..`first`+2 are a unit vector (within 10%) or zero.
bool AreNormals(const ExtraColumns& extra, int first) {
  for (size_t i = 0; i < extra.rows(); ++i) {
    const double x = extra.at(i, first), y = extra.at(i, first + 1), z = extra.at(i, first + 2);
    const double squared = x * x + y * y + z * z;
    if (squared != 0 && (squared < 0.81 || squared > 1.21)) return false;
  }
  return true;
}

// Whether every value of columns `first`..`first`+2 is a colour channel: all integers from 0
// to 255, or all from 0 to 1.
bool AreColors(const ExtraColumns& extra, int first) {
  bool levels = true, fractions = true;
  for (size_t i = 0; i < extra.rows() && (levels || fractions); ++i) {
    for (int c = first; c < first + 3; ++c) {
      const float value = extra.at(i, c);
      levels = levels && value >= 0 && value <= 255 && value == std::floor(value);
      fractions = fractions && value >= 0 && value <= 1;
    }
  }
  return levels || fractions;
}

// The layout of a file without a header, from its column count and values (ParseXyz's table).
absl::StatusOr<XyzLayout> GuessLayout(const ExtraColumns& extra, size_t columns, int line) {
  XyzLayout layout;
  switch (columns) {
    case 3:
      return layout;
    case 4:
      layout.weight = 3;
      return layout;
    case 6:
      if (!AreNormals(extra, 3) && AreColors(extra, 3)) {
        layout.color = Triple(3);
      } else {
        layout.normal = Triple(3);
      }
      return layout;
    case 7:
      if (!AreNormals(extra, 3) && AreColors(extra, 4)) {
        layout.color = Triple(4);
      } else {
        layout.normal = Triple(3);
        layout.weight = 6;
      }
      return layout;
    case 9:
      if (AreNormals(extra, 3) && AreColors(extra, 6)) {
        layout.normal = Triple(3);
        layout.color = Triple(6);
      } else if (AreNormals(extra, 6) && AreColors(extra, 3)) {
        layout.color = Triple(3);
        layout.normal = Triple(6);
      } else {
        return LineError(line,
                         "9 columns are x y z, a normal and a colour (r g b, in either order), "
                         "but columns 4-6 and 7-9 are not a unit normal and a colour; a header "
                         "comment naming the columns (# x y z ...) says what they are");
      }
      return layout;
    default:
      return LineError(line, absl::StrCat("expected 3, 4, 6, 7 or 9 numbers (x y z [nx ny nz] "
                                          "[r g b] [weight]) or a header comment naming the "
                                          "columns (# x y z ...), found ",
                                          columns, " values"));
  }
}

// Fills `out`'s normals, colours and weights from `extra` as `layout` places them.
void TakeColumns(const XyzLayout& layout, const ExtraColumns& extra, ParsedGeometry* out) {
  const size_t rows = extra.rows();
  if (layout.normal[0] >= 0) {
    out->normals.reserve(rows);
    for (size_t i = 0; i < rows; ++i) {
      out->normals.emplace_back(extra.at(i, layout.normal[0]), extra.at(i, layout.normal[1]),
                                extra.at(i, layout.normal[2]));
    }
  }
  if (layout.color[0] >= 0) {
    float largest = 0;
    for (size_t i = 0; i < rows; ++i) {
      for (int column : layout.color) largest = std::max(largest, extra.at(i, column));
    }
    const double max = TextChannelScale(largest);
    out->colors.reserve(rows);
    for (size_t i = 0; i < rows; ++i) {
      Rgb rgb;
      for (int c = 0; c < 3; ++c) rgb[c] = ChannelFromLevel(extra.at(i, layout.color[c]), max);
      out->colors.push_back(rgb);
    }
  }
  if (layout.weight >= 0) {
    out->weights.reserve(rows);
    for (size_t i = 0; i < rows; ++i) out->weights.push_back(extra.at(i, layout.weight));
  }
}

}  // namespace

std::optional<XyzLayout> XyzLayoutFromHeader(absl::string_view text, size_t columns) {
  const std::vector<absl::string_view> names =
      absl::StrSplit(text, absl::ByAnyChar(" \t\v\f,;"), absl::SkipEmpty());
  if (names.size() != columns || !IsOneOf(names[0], {"x"}) || !IsOneOf(names[1], {"y"}) ||
      !IsOneOf(names[2], {"z"})) {
    return std::nullopt;
  }
  XyzLayout layout;
  const std::initializer_list<absl::string_view> normal_names[3] = {
      {"nx", "normal_x"}, {"ny", "normal_y"}, {"nz", "normal_z"}};
  const std::initializer_list<absl::string_view> color_names[3] = {
      {"r", "red"}, {"g", "green"}, {"b", "blue"}};
  for (int k = 3; k < static_cast<int>(columns); ++k) {
    for (int c = 0; c < 3; ++c) {
      if (IsOneOf(names[k], normal_names[c]) && layout.normal[c] < 0) layout.normal[c] = k;
      if (IsOneOf(names[k], color_names[c]) && layout.color[c] < 0) layout.color[c] = k;
    }
    if (IsOneOf(names[k], {"w", "weight", "confidence"}) && layout.weight < 0) layout.weight = k;
  }
  // A normal or colour of fewer than three channels is skipped.
  for (std::array<int, 3>* triple : {&layout.normal, &layout.color}) {
    if ((*triple)[0] < 0 || (*triple)[1] < 0 || (*triple)[2] < 0) *triple = {-1, -1, -1};
  }
  return layout;
}

std::optional<absl::string_view> XyzCommentText(absl::string_view line) {
  line = absl::StripLeadingAsciiWhitespace(line);
  if (absl::ConsumePrefix(&line, "#") || absl::ConsumePrefix(&line, "//")) return line;
  return std::nullopt;
}

absl::StatusOr<ParsedGeometry> ParseXyz(absl::string_view data, PositionPrecision precision) {
  ParsedGeometry out;
  PositionCollector positions(precision);
  ExtraColumns extra;
  LineCursor cursor(data);
  absl::string_view line;
  std::vector<absl::string_view> tokens;
  std::vector<absl::string_view> comments;  // Before the first point: the header's candidates.
  size_t columns = 0;                       // Set by the first point.
  int first_point_line = 0;
  std::optional<XyzLayout> header;
  bool first_content_line = true;
  while (cursor.Next(&line)) {
    const int n = cursor.line_number();
    const std::optional<absl::string_view> comment = XyzCommentText(line);
    if (comment.has_value()) {
      if (columns == 0) comments.push_back(*comment);
      continue;
    }
    SplitFields(StripHashComment(line), &tokens);
    if (tokens.empty()) continue;
    int64_t ignored_count = 0;
    if (first_content_line && tokens.size() == 1 && ParseInt64(tokens[0], &ignored_count)) {
      first_content_line = false;
      continue;
    }
    first_content_line = false;
    if (columns == 0) {
      if (tokens.size() < 3 || tokens.size() > kMaxColumns) {
        return LineError(n, absl::StrCat("expected x y z and at most ", kMaxColumns - 3,
                                         " more numbers, found ", tokens.size(), " values"));
      }
      columns = tokens.size();
      extra.stride = columns - 3;
      first_point_line = n;
      // Room for as many points as lines like this one fill the rest (an eighth more): no
      // copies as the vectors grow, which would hold twice the points for a moment. Pages
      // reserved and never written take no memory.
      const size_t points =
          (cursor.remaining() / std::max<size_t>(line.size() + 1, 12) + 1) * 9 / 8;
      positions.Reserve(points);
      extra.values.reserve(points * extra.stride);
      for (auto it = comments.rbegin(); it != comments.rend() && !header; ++it) {
        header = XyzLayoutFromHeader(*it, columns);
      }
    } else if (tokens.size() != columns) {
      return LineError(n, absl::StrCat("expected ", columns, " numbers like line ",
                                       first_point_line, ", found ", tokens.size()));
    }
    double values[kMaxColumns];
    for (size_t k = 0; k < columns; ++k) {
      if (!ParseDouble(tokens[k], &values[k])) {
        return LineError(
            n, absl::StrCat("expected a number in column ", k + 1, ", found ", Quoted(tokens[k])));
      }
      if (!std::isfinite(NarrowToFloat(values[k]))) {
        return LineError(n, absl::StrCat("column ", k + 1, " is not finite: ", Quoted(tokens[k])));
      }
    }
    positions.Add({values[0], values[1], values[2]});
    for (size_t k = 3; k < columns; ++k) extra.values.push_back(NarrowToFloat(values[k]));
  }
  positions.MoveTo(&out);
  if (columns == 0) return out;
  XyzLayout layout;
  if (header.has_value()) {
    layout = *header;
  } else {
    absl::StatusOr<XyzLayout> guessed = GuessLayout(extra, columns, first_point_line);
    if (!guessed.ok()) return guessed.status();
    layout = *guessed;
  }
  TakeColumns(layout, extra, &out);
  return out;
}

std::string FormatXyz(const GeometryView& geometry) {
  std::string out;
  const bool normals = !geometry.normals.empty();
  const bool weights = !geometry.weights.empty();
  const bool colors = !geometry.colors.empty();
  out.reserve(geometry.positions.size() *
              (32 + (normals ? 32 : 0) + (colors ? 12 : 0) + (weights ? 12 : 0)));
  // Levels read back as fractions when no channel is above 1 (ParseXyz): such colours are
  // written as fractions.
  const bool color_levels =
      std::any_of(geometry.colors.begin(), geometry.colors.end(),
                  [](const Rgb& rgb) { return rgb[0] > 1 || rgb[1] > 1 || rgb[2] > 1; });
  if (normals || colors) {  // Without the header, unnormalised normals might read as colours.
    absl::StrAppend(&out, "# x y z", normals ? " nx ny nz" : "", colors ? " r g b" : "",
                    weights ? " w" : "", "\n");
  }
  for (size_t i = 0; i < geometry.positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      if (c > 0) out += ' ';
      AppendCoordinate(geometry.positions[i][c], geometry.origin[c], &out);
    }
    if (normals) {
      for (int c = 0; c < 3; ++c) {
        out += ' ';
        AppendFloat(geometry.normals[i][c], &out);
      }
    }
    if (colors) {
      for (int c = 0; c < 3; ++c) {
        out += ' ';
        if (color_levels) {
          absl::StrAppend(&out, int{geometry.colors[i][c]});
        } else {
          AppendFloat(ChannelFraction(geometry.colors[i][c]), &out);
        }
      }
    }
    if (weights) {
      out += ' ';
      AppendFloat(geometry.weights[i], &out);
    }
    out += '\n';
  }
  return out;
}

}  // namespace neuralmesh::io_internal
