#include "core/io/internal/obj.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/internal/position_collector.h"
#include "core/io/internal/text.h"
#include "core/rgb.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

constexpr const char* kAxisNames[3] = {"x", "y", "z"};
constexpr const char* kChannelNames[3] = {"red", "green", "blue"};

// The colours of 'v x y z r g b' lines as written, until the whole file says whether they are
// fractions (MeshLab, CloudCompare: every channel at most 1) or 0-255 levels.
struct ObjColors {
  std::vector<std::array<float, 3>> channels;
  bool every_vertex = true;  // False once a vertex without a colour is read.
  float largest = 0;
};

absl::Status ParseVertex(const std::vector<absl::string_view>& tokens, int line,
                         PositionCollector* positions, ObjColors* colors) {
  if (tokens.size() < 4) {
    return LineError(line,
                     absl::StrCat("expected 'v x y z', found ", tokens.size() - 1, " coordinates"));
  }
  Point3d p;
  for (int c = 0; c < 3; ++c) {
    if (!ParseDouble(tokens[1 + c], &p[c])) {
      return LineError(line, absl::StrCat("expected a number for coordinate ", kAxisNames[c],
                                          " of a vertex, found ", Quoted(tokens[1 + c])));
    }
    if (!std::isfinite(NarrowToFloat(p[c]))) {
      return LineError(line, "vertex has a non-finite coordinate");
    }
  }
  positions->Add(p);
  // 'v x y z w' carries a homogeneous weight, ignored; 'v x y z r g b', a colour.
  if (tokens.size() < 7) {
    colors->every_vertex = false;
    return absl::OkStatus();
  }
  std::array<float, 3> rgb;
  for (int c = 0; c < 3; ++c) {
    if (!ParseFloat(tokens[4 + c], &rgb[c]) || !std::isfinite(rgb[c])) {
      return LineError(line, absl::StrCat("expected a finite number for the ", kChannelNames[c],
                                          " of a vertex colour, found ", Quoted(tokens[4 + c])));
    }
    colors->largest = std::max(colors->largest, rgb[c]);
  }
  colors->channels.push_back(rgb);
  return absl::OkStatus();
}

// Colours for every vertex or none.
std::vector<Rgb> ResolveColors(const ObjColors& colors) {
  std::vector<Rgb> out;
  if (!colors.every_vertex || colors.channels.empty()) return out;
  const double max = TextChannelScale(colors.largest);
  out.reserve(colors.channels.size());
  for (const std::array<float, 3>& rgb : colors.channels) {
    out.push_back({ChannelFromLevel(rgb[0], max), ChannelFromLevel(rgb[1], max),
                   ChannelFromLevel(rgb[2], max)});
  }
  return out;
}

// Resolves the vertex part of one face reference ("7", "7/2", "7/2/5", "7//5", "-1").
// Positive indices may refer to vertices defined later; they are checked at the end.
absl::StatusOr<int64_t> ParseReference(absl::string_view reference, int line, size_t num_vertices) {
  absl::string_view parts[3];
  int num_parts = 0;
  for (size_t start = 0;;) {
    const size_t slash = reference.find('/', start);
    if (num_parts == 3) {
      return LineError(line, absl::StrCat("malformed face reference ", Quoted(reference),
                                          "; expected v, v/vt, v/vt/vn or v//vn"));
    }
    parts[num_parts++] = reference.substr(start, slash - start);
    if (slash == absl::string_view::npos) break;
    start = slash + 1;
  }
  int64_t index = 0;
  if (!ParseInt64(parts[0], &index)) {
    return LineError(line,
                     absl::StrCat("expected a vertex index in face reference ", Quoted(reference)));
  }
  // Texture and normal indices are ignored but must be integers when present.
  for (int k = 1; k < num_parts; ++k) {
    int64_t ignored = 0;
    if (!parts[k].empty() && !ParseInt64(parts[k], &ignored)) {
      return LineError(line, absl::StrCat("malformed face reference ", Quoted(reference)));
    }
  }
  if (index == 0) return LineError(line, "face index 0 is invalid; OBJ indices start at 1");
  if (index < 0) {
    const int64_t resolved = static_cast<int64_t>(num_vertices) + index;
    if (resolved < 0) {
      return LineError(line,
                       absl::StrCat("relative face index ", index, " points before the ",
                                    "first vertex; only ", num_vertices, " vertices precede it"));
    }
    return resolved;
  }
  if (index > static_cast<int64_t>(std::numeric_limits<uint32_t>::max())) {
    return LineError(line, absl::StrCat("face index ", index, " is too large"));
  }
  return index - 1;
}

}  // namespace

absl::StatusOr<ParsedGeometry> ParseObj(absl::string_view data, FaceHandling faces,
                                        PositionPrecision precision) {
  ParsedGeometry out;
  PositionCollector positions(precision);
  LineCursor cursor(data);
  absl::string_view line;
  std::vector<absl::string_view> tokens;
  std::vector<uint32_t> polygon;
  int64_t largest_index = -1;
  int largest_index_line = 0;
  ObjColors colors;
  while (cursor.Next(&line)) {
    const int n = cursor.line_number();
    SplitWhitespace(StripHashComment(line), &tokens);
    if (tokens.empty()) continue;
    if (tokens[0] == "v") {
      NM_RETURN_IF_ERROR(ParseVertex(tokens, n, &positions, &colors));
    } else if (tokens[0] == "f" && faces == FaceHandling::kRead) {
      if (tokens.size() < 4) {
        return LineError(
            n, absl::StrCat("a face needs at least 3 vertices, found ", tokens.size() - 1));
      }
      polygon.clear();
      for (size_t k = 1; k < tokens.size(); ++k) {
        NM_ASSIGN_OR_RETURN(const int64_t index,
                            ParseReference(tokens[k], n, positions.size()));
        if (index > largest_index) {
          largest_index = index;
          largest_index_line = n;
        }
        polygon.push_back(static_cast<uint32_t>(index));
      }
      for (size_t c = 1; c + 1 < polygon.size(); ++c) {
        out.faces.push_back({polygon[0], polygon[c], polygon[c + 1]});
      }
    }
  }
  if (largest_index >= static_cast<int64_t>(positions.size())) {
    return LineError(largest_index_line,
                     absl::StrCat("face uses vertex ", largest_index + 1, " but the file has ",
                                  positions.size(), " vertices"));
  }
  positions.MoveTo(&out);
  out.colors = ResolveColors(colors);
  return out;
}

std::string FormatObj(const GeometryView& geometry) {
  std::string out = "# written by neuralmesh\n";
  out.reserve(geometry.positions.size() * 32 + geometry.faces.size() * 24);
  const bool colors = !geometry.colors.empty();
  for (size_t i = 0; i < geometry.positions.size(); ++i) {
    out += "v";
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      AppendCoordinate(geometry.positions[i][c], geometry.origin[c], &out);
    }
    if (colors) {
      for (int c = 0; c < 3; ++c) {
        out += ' ';
        AppendFloat(ChannelFraction(geometry.colors[i][c]), &out);
      }
    }
    out += '\n';
  }
  for (const auto& face : geometry.faces) {
    absl::StrAppend(&out, "f ", face[0] + 1, " ", face[1] + 1, " ", face[2] + 1, "\n");
  }
  return out;
}

}  // namespace neuralmesh::io_internal
