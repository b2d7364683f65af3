#include "core/io/internal/off.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"
#include "core/rgb.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

// The shortest vertex line ("0 0 0\n") and face line ("3 0 1 2\n").
constexpr size_t kMinVertexBytes = 6;
constexpr size_t kMinFaceBytes = 8;

// Reads the next line that holds something other than a comment; false at the end.
bool NextContentLine(LineCursor& cursor, std::vector<absl::string_view>* tokens) {
  absl::string_view line;
  while (cursor.Next(&line)) {
    SplitWhitespace(StripHashComment(line), tokens);
    if (!tokens->empty()) return true;
  }
  return false;
}

// Parses "[ST][C][N]OFF"; sets `has_colors` for the C variants, `has_normals` for the N ones.
absl::Status ParseKeyword(absl::string_view keyword, int line, bool* has_colors,
                          bool* has_normals) {
  *has_normals = false;
  if (!absl::EndsWith(keyword, "OFF")) {
    return LineError(line, absl::StrCat("not an OFF file: expected the keyword OFF (or COFF, "
                                        "NOFF, STOFF, ...), found ",
                                        Quoted(keyword)));
  }
  absl::string_view prefix = keyword.substr(0, keyword.size() - 3);
  absl::ConsumePrefix(&prefix, "ST");  // Texture coordinates, ignored.
  *has_colors = absl::ConsumePrefix(&prefix, "C");
  *has_normals = absl::ConsumePrefix(&prefix, "N");
  if (!prefix.empty()) {
    return LineError(line, absl::StrCat("unsupported OFF variant ", Quoted(keyword),
                                        "; supported: OFF, COFF, NOFF, CNOFF, STOFF and their "
                                        "combinations (no 4D, nD or binary OFF)"));
  }
  return absl::OkStatus();
}

absl::Status ParseCount(absl::string_view token, int line, const char* what, int64_t* count) {
  if (!ParseInt64(token, count) || *count < 0) {
    return LineError(
        line, absl::StrCat("expected a non-negative ", what, " count, found ", Quoted(token)));
  }
  return absl::OkStatus();
}

// A COFF vertex colour from the tokens after its position (and normal): "r g b [a]", integers
// from 0 to 255 or fractions from 0 to 1 (Geomview's rule: integers are levels). False when
// the tokens are missing; a malformed one is an error.
absl::StatusOr<bool> ParseColor(const std::vector<absl::string_view>& tokens, size_t first,
                                int line, int64_t vertex, Rgb* color) {
  if (tokens.size() < first + 3) return false;
  bool integers = true;
  double channels[3];
  for (int c = 0; c < 3; ++c) {
    const absl::string_view token = tokens[first + c];
    int64_t level = 0;
    if (ParseInt64(token, &level)) {
      channels[c] = static_cast<double>(level);
      continue;
    }
    integers = false;
    if (!ParseDouble(token, &channels[c]) || !std::isfinite(channels[c])) {
      return LineError(line, absl::StrCat("expected a colour channel in vertex ", vertex,
                                          ", found ", Quoted(token)));
    }
  }
  const double max = integers ? 255.0 : 1.0;
  for (int c = 0; c < 3; ++c) (*color)[c] = ChannelFromLevel(channels[c], max);
  return true;
}

}  // namespace

absl::StatusOr<ParsedGeometry> ParseOff(absl::string_view data, FaceHandling faces,
                                        PositionPrecision precision) {
  LineCursor cursor(data);
  std::vector<absl::string_view> tokens;
  if (!NextContentLine(cursor, &tokens)) {
    return LineError(cursor.line_number(), "expected the keyword OFF, found only comments");
  }
  bool has_colors = false, has_normals = false;
  NM_RETURN_IF_ERROR(ParseKeyword(tokens[0], cursor.line_number(), &has_colors, &has_normals));
  if (tokens.size() > 1 && tokens[1] == "BINARY") {
    return LineError(cursor.line_number(), "binary OFF is not supported");
  }
  tokens.erase(tokens.begin());
  if (tokens.empty() && !NextContentLine(cursor, &tokens)) {
    return LineError(cursor.line_number(), "expected the counts 'vertices faces edges'");
  }
  const int counts_line = cursor.line_number();
  if (tokens.size() < 2 || tokens.size() > 3) {
    return LineError(counts_line, absl::StrCat("expected the counts 'vertices faces edges', "
                                               "found ",
                                               tokens.size(), " values"));
  }
  int64_t num_vertices = 0, num_faces = 0;
  NM_RETURN_IF_ERROR(ParseCount(tokens[0], counts_line, "vertex", &num_vertices));
  NM_RETURN_IF_ERROR(ParseCount(tokens[1], counts_line, "face", &num_faces));
  if (static_cast<uint64_t>(num_vertices) > cursor.remaining() / kMinVertexBytes + 1) {
    return LineError(counts_line,
                     absl::StrCat("the header declares ", num_vertices, " vertices but only ",
                                  cursor.remaining(), " bytes follow"));
  }

  ParsedGeometry out;
  PositionCollector positions(precision);
  positions.Reserve(num_vertices);
  if (has_normals) out.normals.reserve(num_vertices);
  const size_t min_tokens = has_normals ? 6 : 3;
  for (int64_t i = 0; i < num_vertices; ++i) {
    if (!NextContentLine(cursor, &tokens)) {
      return LineError(cursor.line_number(),
                       absl::StrCat("the file ends after ", i, " of the ", num_vertices,
                                    " vertices the header declares"));
    }
    const int n = cursor.line_number();
    if (tokens.size() < min_tokens) {
      return LineError(n, absl::StrCat("expected ", has_normals ? "'x y z nx ny nz'" : "'x y z'",
                                       " for vertex ", i, ", found ", tokens.size(), " values"));
    }
    double values[6];
    for (size_t k = 0; k < min_tokens; ++k) {
      if (!ParseDouble(tokens[k], &values[k]) || !std::isfinite(NarrowToFloat(values[k]))) {
        return LineError(n, absl::StrCat("expected a finite number in vertex ", i, ", found ",
                                         Quoted(tokens[k])));
      }
    }
    positions.Add({values[0], values[1], values[2]});
    if (has_normals) {
      out.normals.emplace_back(NarrowToFloat(values[3]), NarrowToFloat(values[4]),
                               NarrowToFloat(values[5]));
    }
    if (has_colors) {
      Rgb color;
      NM_ASSIGN_OR_RETURN(const bool present, ParseColor(tokens, min_tokens, n, i, &color));
      if (present) {
        out.colors.push_back(color);
      } else {
        has_colors = false;  // Colours for every vertex or none.
        out.colors = {};
      }
    }
  }
  positions.MoveTo(&out);
  if (faces == FaceHandling::kSkip) return out;

  if (static_cast<uint64_t>(num_faces) > cursor.remaining() / kMinFaceBytes + 1) {
    return LineError(counts_line,
                     absl::StrCat("the header declares ", num_faces, " faces but only ",
                                  cursor.remaining(), " bytes follow the vertices"));
  }
  out.faces.reserve(num_faces);
  std::vector<uint32_t> polygon;
  for (int64_t f = 0; f < num_faces; ++f) {
    if (!NextContentLine(cursor, &tokens)) {
      return LineError(cursor.line_number(), absl::StrCat("the file ends after ", f, " of the ",
                                                          num_faces, " faces the header declares"));
    }
    const int n = cursor.line_number();
    int64_t count = 0;
    if (!ParseInt64(tokens[0], &count) || count < 3) {
      return LineError(n, absl::StrCat("expected a vertex count of at least 3 for face ", f,
                                       ", found ", Quoted(tokens[0])));
    }
    if (static_cast<int64_t>(tokens.size()) - 1 < count) {
      return LineError(n, absl::StrCat("face ", f, " declares ", count, " vertices but lists ",
                                       tokens.size() - 1));
    }
    polygon.clear();
    for (int64_t k = 1; k <= count; ++k) {
      int64_t index = 0;
      if (!ParseInt64(tokens[k], &index)) {
        return LineError(
            n, absl::StrCat("expected a vertex index in face ", f, ", found ", Quoted(tokens[k])));
      }
      if (index < 0 || index >= num_vertices) {
        return LineError(n, absl::StrCat("face ", f, " uses vertex ", index,
                                         "; valid indices are 0 to ", num_vertices - 1));
      }
      polygon.push_back(static_cast<uint32_t>(index));
    }
    for (size_t c = 1; c + 1 < polygon.size(); ++c) {
      out.faces.push_back({polygon[0], polygon[c], polygon[c + 1]});
    }
  }
  return out;
}

std::string FormatOff(const GeometryView& geometry) {
  const bool colors = !geometry.colors.empty();
  std::string out = absl::StrCat(colors ? "COFF\n" : "OFF\n", geometry.positions.size(), " ",
                                 geometry.faces.size(), " 0\n");
  out.reserve(out.size() + geometry.positions.size() * (colors ? 48 : 32) +
              geometry.faces.size() * 24);
  for (size_t i = 0; i < geometry.positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      if (c > 0) out += ' ';
      AppendCoordinate(geometry.positions[i][c], geometry.origin[c], &out);
    }
    if (colors) {
      const Rgb& rgb = geometry.colors[i];
      absl::StrAppend(&out, " ", rgb[0], " ", rgb[1], " ", rgb[2], " 255");
    }
    out += '\n';
  }
  for (const auto& face : geometry.faces) {
    absl::StrAppend(&out, "3 ", face[0], " ", face[1], " ", face[2], "\n");
  }
  return out;
}

}  // namespace neuralmesh::io_internal
