// The glTF files neuralmesh writes, read by an independent reader: three.js's GLTFLoader (with
// its DRACOLoader) in headless Chromium, through gltf_three_reader.py. Checks that three.js
// finds the same vertices, triangles and colours, the matte double-sided material, and draws
// the mesh, for plain .glb and .gltf, Draco-compressed .glb, a mesh too large for 16-bit
// indices, and vertices without faces.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/analysis/json_reader.h"
#include "core/io/mesh_io.h"
#include "core/rgb.h"
#include "tests/client/subprocess.h"
#include "tests/testing/shapes.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh {
namespace {

// What three.js found in one file.
struct ThreeMesh {
  std::string kind;
  std::vector<Vec3f> positions;
  std::vector<std::array<uint32_t, 3>> faces;
  std::vector<Rgb> colors;  // Converted from three.js's linear values.
  bool has_index = false, vertex_colors = false, double_sided = false;
  double metalness = -1;
};

struct ThreeFile {
  std::vector<ThreeMesh> meshes;
  double drawn = 0;
};

// Member `key` of `object`, or null when it is missing (JSON.stringify leaves out undefined).
const JsonValue& Member(const JsonValue& object, const char* key) {
  static const JsonValue kNull;
  const JsonValue* value = object.Find(key);
  return value != nullptr ? *value : kNull;
}

ThreeMesh ToThreeMesh(const JsonValue& m) {
  ThreeMesh mesh;
  mesh.kind = Member(m, "kind").text;
  const std::vector<JsonValue>& p = Member(m, "positions").items;
  for (size_t i = 0; i + 2 < p.size(); i += 3) {
    mesh.positions.push_back(Vec3f(static_cast<float>(p[i].number),
                                   static_cast<float>(p[i + 1].number),
                                   static_cast<float>(p[i + 2].number)));
  }
  const JsonValue* index = &Member(m, "index");
  mesh.has_index = index->is_array();
  for (size_t i = 0; mesh.has_index && i + 2 < index->items.size(); i += 3) {
    mesh.faces.push_back({static_cast<uint32_t>(index->items[i].number),
                          static_cast<uint32_t>(index->items[i + 1].number),
                          static_cast<uint32_t>(index->items[i + 2].number)});
  }
  const JsonValue* colors = &Member(m, "colors");
  for (size_t i = 0; colors->is_array() && i + 2 < colors->items.size(); i += 3) {
    mesh.colors.push_back({SrgbFromLinear(colors->items[i].number),
                           SrgbFromLinear(colors->items[i + 1].number),
                           SrgbFromLinear(colors->items[i + 2].number)});
  }
  mesh.vertex_colors = Member(m, "vertexColors").boolean;
  mesh.double_sided = Member(m, "doubleSided").boolean;
  mesh.metalness = Member(m, "metalness").is_number() ? Member(m, "metalness").number : -1;
  return mesh;
}

// Runs the reader on `files`; fails the test when it cannot.
std::vector<ThreeFile> ReadWithThreeJs(const std::vector<std::string>& files) {
  const std::string dir = testing::MakeTempDir("three");
  std::string command =
      "/usr/bin/python3 tests/client/web/gltf_three_reader.py "
      "--three=client/web/node_modules/three --timeout=90";
  for (const std::string& file : files) absl::StrAppend(&command, " ", file);
  absl::StrAppend(&command, " > ", dir, "/out.json 2> ", dir, "/err.txt");
  const int exit = std::system(command.c_str());
  const std::string out = testing::ReadWholeFile(dir + "/out.json");
  EXPECT_EQ(exit, 0) << "the reader failed:\n" << testing::ReadWholeFile(dir + "/err.txt");
  const absl::StatusOr<JsonValue> doc = ParseJson(out);
  EXPECT_TRUE(doc.ok()) << doc.status() << "\n" << out.substr(0, 500);
  std::vector<ThreeFile> result;
  if (!doc.ok()) return result;
  for (size_t i = 0; i < doc->items.size(); ++i) {
    const JsonValue& file = doc->items[i];
    if (const JsonValue* error = file.Find("error")) {
      ADD_FAILURE() << "three.js could not read " << files[i] << ": " << error->text;
    }
    ThreeFile read;
    if (const JsonValue* meshes = file.Find("meshes")) {
      for (const JsonValue& m : meshes->items) read.meshes.push_back(ToThreeMesh(m));
    }
    if (const JsonValue* drawn = file.Find("drawn")) read.drawn = drawn->number;
    result.push_back(std::move(read));
  }
  return result;
}

TEST(GltfThreeJsTest, ThreeJsReadsAndDrawsTheGltfFilesWeWrite) {
  if (std::system("command -v chromium > /dev/null && /usr/bin/python3 -c 'import websocket'") !=
      0) {
    FAIL() << "chromium and Debian's python3-websocket are required (scripts/install-deps.sh)";
  }
  const TriangleMesh colored = testing::ColoredIcosphere(3);
  const TriangleMesh large = testing::Icosphere(7);  // 163,842 vertices: 32-bit indices.
  TriangleMesh points = testing::Icosphere(1);
  points.faces.clear();

  const std::string dir = testing::MakeTempDir("gltf");
  const std::vector<std::string> files = {dir + "/colored.glb", dir + "/colored.gltf",
                                          dir + "/draco.glb", dir + "/large.glb",
                                          dir + "/points.glb"};
  ASSERT_TRUE(WriteMesh(colored, files[0]).ok());
  ASSERT_TRUE(WriteMesh(colored, files[1]).ok());
  MeshWriteOptions draco;
  draco.gltf_draco = true;
  draco.draco.position_quantization_bits = 14;
  ASSERT_TRUE(WriteMesh(colored, files[2], draco).ok());
  ASSERT_TRUE(WriteMesh(large, files[3]).ok());
  ASSERT_TRUE(WriteMesh(points, files[4]).ok());

  const std::vector<ThreeFile> read = ReadWithThreeJs(files);
  ASSERT_EQ(read.size(), files.size());
  for (size_t f = 0; f < files.size(); ++f) {
    SCOPED_TRACE(files[f]);
    ASSERT_EQ(read[f].meshes.size(), 1u);
    // Points are drawn a pixel each, in the default material's white: not counted.
    if (read[f].meshes[0].kind == "points") continue;
    EXPECT_GT(read[f].drawn, 0.05) << "three.js drew almost nothing";
    EXPECT_EQ(read[f].meshes[0].metalness, 0.0);
    EXPECT_TRUE(read[f].meshes[0].double_sided);
  }
  for (size_t f : {0, 1}) {
    SCOPED_TRACE(files[f]);
    const ThreeMesh& mesh = read[f].meshes[0];
    EXPECT_EQ(mesh.kind, "mesh");
    EXPECT_EQ(mesh.positions, colored.positions);
    EXPECT_EQ(mesh.faces, colored.faces);
    EXPECT_TRUE(mesh.vertex_colors);
    EXPECT_EQ(mesh.colors, colored.colors) << "every sRGB level comes back from linear light";
  }
  {
    SCOPED_TRACE("draco.glb");
    const ThreeMesh& mesh = read[2].meshes[0];
    ASSERT_EQ(mesh.positions.size(), colored.positions.size());
    EXPECT_EQ(mesh.faces.size(), colored.faces.size());
    ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
    const float tolerance = 2.0f / ((1 << 14) - 1) * 0.5f * 1.001f + 1e-6f;
    int unmatched = 0, recoloured = 0;
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      size_t nearest = 0;
      for (size_t j = 1; j < colored.positions.size(); ++j) {
        if ((colored.positions[j] - mesh.positions[i]).sqrnorm() <
            (colored.positions[nearest] - mesh.positions[i]).sqrnorm()) {
          nearest = j;
        }
      }
      const Vec3f d = colored.positions[nearest] - mesh.positions[i];
      unmatched += std::max({std::abs(d[0]), std::abs(d[1]), std::abs(d[2])}) > tolerance;
      recoloured += mesh.colors[i] != colored.colors[nearest];
    }
    EXPECT_EQ(unmatched, 0) << "vertices farther than a quantization step from ours";
    EXPECT_EQ(recoloured, 0) << "vertices whose colour changed";
  }
  {
    SCOPED_TRACE("large.glb");
    const ThreeMesh& mesh = read[3].meshes[0];
    EXPECT_EQ(mesh.positions, large.positions);
    EXPECT_EQ(mesh.faces, large.faces);
    EXPECT_TRUE(mesh.colors.empty());
    EXPECT_FALSE(mesh.vertex_colors);
  }
  {
    SCOPED_TRACE("points.glb");
    const ThreeMesh& mesh = read[4].meshes[0];
    EXPECT_EQ(mesh.kind, "points");
    EXPECT_EQ(mesh.positions, points.positions);
    EXPECT_FALSE(mesh.has_index);
  }
}

}  // namespace
}  // namespace neuralmesh
