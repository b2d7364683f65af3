#include "core/io/internal/xyz.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/internal/text.h"

namespace neuralmesh::io_internal {

absl::StatusOr<ParsedGeometry> ParseXyz(absl::string_view data) {
  ParsedGeometry out;
  LineCursor cursor(data);
  absl::string_view line;
  std::vector<absl::string_view> tokens;
  size_t columns = 0;  // Set by the first point.
  int first_point_line = 0;
  bool first_content_line = true;
  while (cursor.Next(&line)) {
    const int n = cursor.line_number();
    SplitWhitespace(StripHashComment(line), &tokens);
    if (tokens.empty()) continue;
    int64_t ignored_count = 0;
    if (first_content_line && tokens.size() == 1 && ParseInt64(tokens[0], &ignored_count)) {
      first_content_line = false;
      continue;
    }
    first_content_line = false;
    if (columns == 0) {
      if (tokens.size() != 3 && tokens.size() != 4 && tokens.size() != 6 && tokens.size() != 7) {
        return LineError(n, absl::StrCat("expected 3, 4, 6 or 7 numbers (x y z [nx ny nz] "
                                         "[weight]), found ",
                                         tokens.size(), " values"));
      }
      columns = tokens.size();
      first_point_line = n;
    } else if (tokens.size() != columns) {
      return LineError(n, absl::StrCat("expected ", columns, " numbers like line ",
                                       first_point_line, ", found ", tokens.size()));
    }
    float values[7];
    for (size_t k = 0; k < columns; ++k) {
      if (!ParseFloat(tokens[k], &values[k])) {
        return LineError(
            n, absl::StrCat("expected a number in column ", k + 1, ", found ", Quoted(tokens[k])));
      }
      if (!std::isfinite(values[k])) {
        return LineError(n, absl::StrCat("column ", k + 1, " is not finite: ", Quoted(tokens[k])));
      }
    }
    out.positions.emplace_back(values[0], values[1], values[2]);
    if (columns >= 6) out.normals.emplace_back(values[3], values[4], values[5]);
    if (columns == 4 || columns == 7) out.weights.push_back(values[columns - 1]);
  }
  return out;
}

std::string FormatXyz(const GeometryView& geometry) {
  std::string out;
  const bool normals = !geometry.normals.empty();
  const bool weights = !geometry.weights.empty();
  out.reserve(geometry.positions.size() * (32 + (normals ? 32 : 0) + (weights ? 12 : 0)));
  for (size_t i = 0; i < geometry.positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      if (c > 0) out += ' ';
      AppendFloat(geometry.positions[i][c], &out);
    }
    if (normals) {
      for (int c = 0; c < 3; ++c) {
        out += ' ';
        AppendFloat(geometry.normals[i][c], &out);
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
