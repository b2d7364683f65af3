#include "core/io/internal/stl.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/internal/binary.h"
#include "core/io/internal/text.h"
#include "core/io/internal/vertex_merger.h"
#include "core/status_macros.h"

namespace neuralmesh::io_internal {
namespace {

constexpr const char* kAxisNames[3] = {"x", "y", "z"};

constexpr size_t kHeaderBytes = 80;
constexpr size_t kPreambleBytes = kHeaderBytes + 4;  // Header and triangle count.
constexpr size_t kTriangleBytes = 50;  // Normal, three vertices, attribute byte count.

bool IsFinite(const Vec3f& p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// True when `data` holds only printable ASCII and whitespace.
bool IsText(absl::string_view data) {
  for (const char c : data) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (!(u >= 0x20 && u < 0x7f) && u != '\n' && u != '\r' && u != '\t' && u != '\f' && u != '\v') {
      return false;
    }
  }
  return true;
}

absl::StatusOr<ParsedGeometry> ParseBinary(absl::string_view data, uint32_t count) {
  ParsedGeometry out;
  VertexMerger merger(&out.positions);
  out.faces.reserve(count);
  for (uint32_t t = 0; t < count; ++t) {
    const size_t offset = kPreambleBytes + size_t{t} * kTriangleBytes;
    std::array<uint32_t, 3> face;
    for (int k = 0; k < 3; ++k) {
      const char* p = data.data() + offset + 12 + 12 * k;
      const Vec3f v(LoadScalar<float>(p, false), LoadScalar<float>(p + 4, false),
                    LoadScalar<float>(p + 8, false));
      if (!IsFinite(v)) {
        return absl::InvalidArgumentError(
            absl::StrCat("byte ", offset, ": triangle ", t, " has a non-finite coordinate"));
      }
      face[k] = merger.Add(v);
    }
    out.faces.push_back(face);
  }
  return out;
}

absl::Status ExpectFacetEnd(int line, int vertices_in_facet) {
  if (vertices_in_facet != 3) {
    return LineError(line, absl::StrCat("a facet has ", vertices_in_facet,
                                        " vertices; STL facets are triangles"));
  }
  return absl::OkStatus();
}

// ASCII STL, read line by line: "solid", "facet normal ...", "outer loop", three "vertex x y z",
// "endloop", "endfacet", ..., "endsolid". Several solids may follow each other.
absl::StatusOr<ParsedGeometry> ParseAscii(absl::string_view data) {
  ParsedGeometry out;
  VertexMerger merger(&out.positions);
  LineCursor cursor(data);
  absl::string_view line;
  std::vector<absl::string_view> tokens;
  enum class State { kOutside, kSolid, kFacet, kLoop, kLoopDone } state = State::kOutside;
  std::array<uint32_t, 3> face{};
  int vertices_in_facet = 0;
  while (cursor.Next(&line)) {
    const int n = cursor.line_number();
    SplitWhitespace(line, &tokens);
    if (tokens.empty()) continue;
    const absl::string_view key = tokens[0];
    auto unexpected = [&](const char* expected) {
      return LineError(n, absl::StrCat("expected ", expected, ", found ", Quoted(key)));
    };
    switch (state) {
      case State::kOutside:
        if (key != "solid") return unexpected("'solid'");
        state = State::kSolid;
        break;
      case State::kSolid:
        if (key == "endsolid") {
          state = State::kOutside;
        } else if (key == "facet") {
          state = State::kFacet;
          vertices_in_facet = 0;
        } else {
          return unexpected("'facet' or 'endsolid'");
        }
        break;
      case State::kFacet:
        if (key != "outer" || tokens.size() != 2 || tokens[1] != "loop") {
          return unexpected("'outer loop'");
        }
        state = State::kLoop;
        break;
      case State::kLoop:
        if (key == "vertex") {
          if (tokens.size() != 4) return LineError(n, "expected 'vertex x y z'");
          Vec3f v;
          for (int c = 0; c < 3; ++c) {
            if (!ParseFloat(tokens[1 + c], &v[c])) {
              return LineError(n, absl::StrCat("expected a number for coordinate ", kAxisNames[c],
                                               ", found ", Quoted(tokens[1 + c])));
            }
          }
          if (!IsFinite(v)) return LineError(n, "vertex has a non-finite coordinate");
          if (vertices_in_facet == 3) NM_RETURN_IF_ERROR(ExpectFacetEnd(n, 4));
          face[vertices_in_facet++] = merger.Add(v);
        } else if (key == "endloop") {
          NM_RETURN_IF_ERROR(ExpectFacetEnd(n, vertices_in_facet));
          state = State::kLoopDone;
        } else {
          return unexpected("'vertex' or 'endloop'");
        }
        break;
      case State::kLoopDone:
        if (key != "endfacet") return unexpected("'endfacet'");
        out.faces.push_back(face);
        state = State::kSolid;
        break;
    }
  }
  if (state != State::kOutside) {
    return LineError(cursor.line_number(), "the file ends inside a solid; expected 'endsolid'");
  }
  return out;
}

}  // namespace

absl::StatusOr<ParsedGeometry> ParseStl(absl::string_view data) {
  const bool looks_ascii = absl::StartsWith(absl::StripLeadingAsciiWhitespace(data), "solid");
  if (data.size() < kPreambleBytes) {
    if (looks_ascii) return ParseAscii(data);
    return absl::InvalidArgumentError(absl::StrCat(
        "byte 0: the file has ", data.size(), " bytes, too few for a binary STL (at least ",
        kPreambleBytes, "), and does not start with 'solid' like an ASCII STL"));
  }
  const uint32_t count = LoadScalar<uint32_t>(data.data() + kHeaderBytes, false);
  const uint64_t expected = kPreambleBytes + uint64_t{count} * kTriangleBytes;
  if (expected == data.size()) return ParseBinary(data, count);
  const std::string size_mismatch =
      absl::StrCat("byte ", kHeaderBytes, ": the binary STL header declares ", count,
                   " triangles, which take ", expected, " bytes, but the file has ", data.size());
  if (!looks_ascii) return absl::InvalidArgumentError(size_mismatch);
  absl::StatusOr<ParsedGeometry> ascii = ParseAscii(data);
  if (ascii.ok() || IsText(data)) return ascii;
  // Some binary files also start with "solid"; for one of those, say both what the ASCII
  // reader found and why it was not read as binary.
  return absl::InvalidArgumentError(absl::StrCat(
      ascii.status().message(), " (read as ASCII STL; as binary STL: ", size_mismatch, ")"));
}

std::string FormatStl(const GeometryView& geometry) {
  std::string out(kHeaderBytes, ' ');
  constexpr char kBanner[] = "binary STL written by neuralmesh";
  out.replace(0, sizeof(kBanner) - 1, kBanner);
  AppendLittleEndian(static_cast<uint32_t>(geometry.faces.size()), &out);
  out.reserve(out.size() + geometry.faces.size() * kTriangleBytes);
  for (const auto& face : geometry.faces) {
    const Vec3f& a = geometry.positions[face[0]];
    const Vec3f& b = geometry.positions[face[1]];
    const Vec3f& c = geometry.positions[face[2]];
    Vec3f normal = OpenMesh::cross(b - a, c - a);
    const float length = normal.norm();
    normal = length > 0 && std::isfinite(length) ? normal / length : Vec3f(0, 0, 0);
    for (int k = 0; k < 3; ++k) AppendLittleEndian(normal[k], &out);
    for (const Vec3f* v : {&a, &b, &c}) {
      for (int k = 0; k < 3; ++k) AppendLittleEndian((*v)[k], &out);
    }
    AppendLittleEndian(uint16_t{0}, &out);
  }
  return out;
}

}  // namespace neuralmesh::io_internal
