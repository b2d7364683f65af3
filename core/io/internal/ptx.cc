#include "core/io/internal/ptx.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"
#include "core/rgb.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

// Reads the next line that is not blank into `tokens`; false at the end of the data.
bool NextTokens(LineCursor* cursor, std::vector<absl::string_view>* tokens) {
  absl::string_view line;
  while (cursor->Next(&line)) {
    SplitWhitespace(line, tokens);
    if (!tokens->empty()) return true;
  }
  return false;
}

// `count` finite numbers on the next line, or an error naming it as `what`.
absl::Status ReadNumbers(LineCursor* cursor, size_t count, absl::string_view what,
                         std::vector<absl::string_view>* tokens, double* values) {
  if (!NextTokens(cursor, tokens)) {
    return absl::InvalidArgumentError(
        absl::StrCat("PTX: the file ends within a scan's header, before its ", what));
  }
  if (tokens->size() != count) {
    return LineError(cursor->line_number(), absl::StrCat("the ", what, " takes ", count,
                                                         " numbers, not ", tokens->size()));
  }
  for (size_t i = 0; i < count; ++i) {
    if (!ParseDouble((*tokens)[i], &values[i]) || !std::isfinite(values[i])) {
      return LineError(
          cursor->line_number(),
          absl::StrCat("the ", what, " has ", Quoted((*tokens)[i]), ", not a finite number"));
    }
  }
  return absl::OkStatus();
}

// A count of the header (columns or rows).
absl::StatusOr<uint64_t> ReadCount(LineCursor* cursor, absl::string_view what,
                                   std::vector<absl::string_view>* tokens) {
  if (!NextTokens(cursor, tokens)) {
    return absl::InvalidArgumentError(
        absl::StrCat("PTX: the file ends within a scan's header, before its ", what));
  }
  int64_t value = 0;
  if (tokens->size() != 1 || !ParseInt64((*tokens)[0], &value) || value < 0) {
    return LineError(cursor->line_number(),
                     absl::StrCat("a scan begins with its ", what,
                                  ", one non-negative integer, not ", Quoted((*tokens)[0])));
  }
  return static_cast<uint64_t>(value);
}

// Whether AppendCoordinate writes every coordinate of `p` as zero (no digit but 0), which PTX
// reads as an empty cell. Only a coordinate within a float's rounding of -origin can be, so
// the others are not written to find out.
bool WrittenAsZero(const Vec3f& p, const Point3d& origin, std::string* text) {
  for (int c = 0; c < 3; ++c) {
    if (std::fabs(origin[c] + p[c]) > std::fabs(origin[c]) * 1e-6) return false;
    text->clear();
    AppendCoordinate(p[c], origin[c], text);
    if (text->find_first_of("123456789") != std::string::npos) return false;
  }
  return true;
}

}  // namespace

absl::StatusOr<ParsedGeometry> ParsePtx(absl::string_view data, PositionPrecision precision) {
  ParsedGeometry out;
  PositionCollector positions(precision);
  std::vector<Rgb> colors;
  bool colored = true;  // Every point so far has r g b.
  LineCursor cursor(data);
  std::vector<absl::string_view> tokens;
  int scan = 0;
  while (true) {
    // A scan's header: columns and rows, the scanner's position and axes (which the matrix
    // repeats), and the matrix, column by column.
    {
      LineCursor peek = cursor;
      if (!NextTokens(&peek, &tokens)) break;
    }
    ++scan;
    NM_ASSIGN_OR_RETURN(const uint64_t columns, ReadCount(&cursor, "number of columns", &tokens));
    NM_ASSIGN_OR_RETURN(const uint64_t rows, ReadCount(&cursor, "number of rows", &tokens));
    double ignored[3];
    for (const char* what :
         {"scanner position", "scanner's X axis", "scanner's Y axis", "scanner's Z axis"}) {
      NM_RETURN_IF_ERROR(ReadNumbers(&cursor, 3, what, &tokens, ignored));
    }
    std::array<std::array<double, 4>, 4> column;
    for (int c = 0; c < 4; ++c) {
      NM_RETURN_IF_ERROR(
          ReadNumbers(&cursor, 4, "transformation matrix", &tokens, column[c].data()));
    }
    if (rows != 0 && columns > std::numeric_limits<uint64_t>::max() / rows) {
      return LineError(cursor.line_number(),
                       absl::StrCat("scan ", scan, " of ", columns, " x ", rows, " points"));
    }
    const uint64_t points = columns * rows;
    for (uint64_t i = 0; i < points; ++i) {
      if (!NextTokens(&cursor, &tokens)) {
        return absl::InvalidArgumentError(absl::StrCat(
            "PTX: scan ", scan, " ends after ", i, " of its ", columns, " x ", rows, " points"));
      }
      const size_t n = tokens.size();
      if (n != 3 && n != 4 && n != 7) {
        return LineError(cursor.line_number(),
                         absl::StrCat("a point takes x y z, x y z intensity or x y z "
                                      "intensity r g b, not ",
                                      n, " values"));
      }
      double local[3];
      for (int c = 0; c < 3; ++c) {
        if (!ParseDouble(tokens[c], &local[c]) || !std::isfinite(local[c])) {
          return LineError(cursor.line_number(), absl::StrCat("coordinate ", Quoted(tokens[c]),
                                                              " is not a finite number"));
        }
      }
      Rgb color = {0, 0, 0};
      if (n == 7) {
        for (int c = 0; c < 3; ++c) {
          int64_t level = 0;
          if (!ParseInt64(tokens[4 + c], &level) || level < 0 || level > 255) {
            return LineError(cursor.line_number(), absl::StrCat("colour ", Quoted(tokens[4 + c]),
                                                                " is not a level from 0 to 255"));
          }
          color[c] = static_cast<uint8_t>(level);
        }
      }
      if (local[0] == 0 && local[1] == 0 && local[2] == 0) {  // An empty cell of the grid.
        ++out.left_out.invalid;
        continue;
      }
      Point3d p;
      for (int r = 0; r < 3; ++r) {
        p[r] = column[0][r] * local[0] + column[1][r] * local[1] + column[2][r] * local[2] +
               column[3][r];
        if (!(std::fabs(p[r]) <= std::numeric_limits<float>::max())) {
          return LineError(cursor.line_number(),
                           "the point lies beyond a float's range where its scan's "
                           "transformation puts it");
        }
      }
      positions.Add(p);
      colored = colored && n == 7;
      if (colored) colors.push_back(color);
    }
  }
  if (scan == 0) return absl::InvalidArgumentError("PTX: the file holds no scan");
  if (positions.size() == 0 && out.left_out.invalid > 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "PTX: all ", out.left_out.invalid, " points are empty cells of their grids (0 0 0)"));
  }
  positions.MoveTo(&out);
  if (colored) out.colors = std::move(colors);
  return out;
}

std::string FormatPtx(const GeometryView& points) {
  const size_t count = points.positions.size();
  const bool colored = !points.colors.empty();
  // The points that would read as empty cells go to scans of their own.
  std::vector<bool> at_zero(count);
  std::string text;
  for (size_t i = 0; i < count; ++i) {
    at_zero[i] = WrittenAsZero(points.positions[i], points.origin, &text);
  }
  std::string out;
  out.reserve(count * (colored ? 48 : 36) + 160);
  // A scan's header: its columns of one row, the scanner at the frame's origin with its axes,
  // and the transformation, column by column: for points at zero, a translation by 1 in x,
  // from which they lie at -1.
  const auto append_header = [&out](size_t columns, bool for_zero) {
    const char* translation = for_zero ? "1" : "0";
    absl::StrAppend(&out, columns, "\n1\n", translation, " 0 0\n1 0 0\n0 1 0\n0 0 1\n",
                    "1 0 0 0\n0 1 0 0\n0 0 1 0\n", translation, " 0 0 1\n");
  };
  if (count == 0) append_header(0, false);  // A file holds one scan at least.
  for (size_t begin = 0; begin < count;) {
    size_t end = begin;
    while (end < count && at_zero[end] == at_zero[begin]) ++end;
    append_header(end - begin, at_zero[begin]);
    for (size_t i = begin; i < end; ++i) {
      if (at_zero[i]) {
        out += "-1 0 0 ";
      } else {
        for (int c = 0; c < 3; ++c) {
          AppendCoordinate(points.positions[i][c], points.origin[c], &out);
          out += ' ';
        }
      }
      out += "0.5";
      if (colored) {
        const Rgb& rgb = points.colors[i];
        absl::StrAppend(&out, " ", int{rgb[0]}, " ", int{rgb[1]}, " ", int{rgb[2]});
      }
      out += '\n';
    }
    begin = end;
  }
  return out;
}

}  // namespace neuralmesh::io_internal
