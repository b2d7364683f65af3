// glTF 2.0 through ReadMesh, ReadPointCloud and WriteMesh: what neuralmesh writes (.glb and
// .gltf, with and without Draco) read back, files shaped as other tools write them (node
// transforms, strips and fans, interleaved and external buffers, instancing), and malformed
// files refused with what is wrong. tests/client/web/gltf_three_test.cc has three.js read them.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/analysis/json_reader.h"
#include "core/io/mesh_io.h"
#include "core/io/point_cloud_io.h"
#include "core/rgb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using io_test::ExpectSameMesh;
using io_test::Put;
using io_test::QuantizationTolerance;
using io_test::ReadBytes;
using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;

// A .glb container of `json` and, when not empty, the BIN chunk `bin`.
std::string Glb(std::string json, std::string bin) {
  while (json.size() % 4 != 0) json.push_back(' ');
  while (bin.size() % 4 != 0) bin.push_back('\0');
  std::string out = "glTF";
  Put<uint32_t>(2, false, &out);
  Put<uint32_t>(static_cast<uint32_t>(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())),
                false, &out);
  Put<uint32_t>(static_cast<uint32_t>(json.size()), false, &out);
  out += "JSON";
  out += json;
  if (!bin.empty()) {
    Put<uint32_t>(static_cast<uint32_t>(bin.size()), false, &out);
    out += std::string("BIN\0", 4);
    out += bin;
  }
  return out;
}

// The JSON chunk of a .glb.
std::string GlbJson(const std::string& glb) {
  uint32_t length = 0;
  std::memcpy(&length, glb.data() + 12, 4);
  return glb.substr(20, length);
}

absl::StatusOr<TriangleMesh> ReadGlb(const std::string& name, const std::string& bytes) {
  const std::string path = TempPath(name);
  WriteBytes(path, bytes);
  return ReadMesh(path);
}

TEST(GltfIoTest, LinearColoursKeepEverySrgbLevel) {
  for (int level = 0; level < 256; ++level) {
    const uint8_t c = static_cast<uint8_t>(level);
    EXPECT_EQ(SrgbFromLinear(LinearShortFromSrgb(c) / 65535.0), c) << level;
    EXPECT_EQ(SrgbFromLinear(LinearFromSrgb(c)), c) << level;
  }
  EXPECT_NEAR(LinearFromSrgb(128), 0.2158605, 1e-6) << "IEC 61966-2-1's curve";
  EXPECT_EQ(SrgbFromLinear(0.5), 188);
  EXPECT_EQ(SrgbFromLinear(-1), 0);
  EXPECT_EQ(SrgbFromLinear(2), 255);
}

TEST(GltfIoTest, MeshesRoundTripInEveryVariant) {
  const TriangleMesh mesh = testing::ColoredIcosphere(2);
  for (const char* name : {"plain.glb", "plain.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    ASSERT_TRUE(WriteMesh(mesh, path).ok());
    const absl::StatusOr<TriangleMesh> read = ReadMesh(path);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->positions, mesh.positions) << "plain glTF keeps floats and their order";
    EXPECT_EQ(read->faces, mesh.faces);
    EXPECT_EQ(read->colors, mesh.colors) << "16-bit linear colours give back every sRGB level";
  }
  MeshWriteOptions draco;
  draco.gltf_draco = true;
  draco.draco.position_quantization_bits = 14;
  for (const char* name : {"draco.glb", "draco.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    ASSERT_TRUE(WriteMesh(mesh, path, draco).ok());
    const absl::StatusOr<TriangleMesh> read = ReadMesh(path);
    ASSERT_TRUE(read.ok()) << read.status();
    const float tolerance = QuantizationTolerance(2.0f, 14);
    ExpectSameMesh(mesh, *read, tolerance, name);
    ASSERT_EQ(read->colors.size(), read->positions.size());
    const std::vector<int> match = io_test::MatchPoints(mesh.positions, read->positions, tolerance);
    for (size_t i = 0; i < match.size(); ++i) {
      ASSERT_GE(match[i], 0);
      EXPECT_EQ(read->colors[i], mesh.colors[match[i]]) << "vertex " << i;
    }
  }
  const std::string plain = ReadBytes(TempPath("plain.glb"));
  const std::string compressed = ReadBytes(TempPath("draco.glb"));
  EXPECT_LT(compressed.size() * 2, plain.size())
      << "Draco: " << compressed.size() << " bytes, plain: " << plain.size();

  const absl::StatusOr<PointCloud> points = ReadPointCloud(TempPath("plain.glb"));
  ASSERT_TRUE(points.ok()) << points.status();
  EXPECT_EQ(points->positions, mesh.positions);
  EXPECT_EQ(points->colors, mesh.colors);
}

TEST(GltfIoTest, WrittenFilesDescribeThemselves) {
  TriangleMesh mesh = testing::Icosphere(1);
  const std::string path = TempPath("described.glb");
  ASSERT_TRUE(WriteMesh(mesh, path).ok());
  const std::string glb = ReadBytes(path);
  ASSERT_EQ(glb.substr(0, 4), "glTF");
  uint32_t length = 0;
  std::memcpy(&length, glb.data() + 8, 4);
  EXPECT_EQ(length, glb.size());
  EXPECT_EQ(glb.size() % 4, 0u);
  const absl::StatusOr<JsonValue> doc = ParseJson(GlbJson(glb));
  ASSERT_TRUE(doc.ok()) << doc.status();
  EXPECT_EQ(doc->Find("asset")->Find("version")->text, "2.0");
  const JsonValue& position = doc->Find("accessors")->items[0];
  EXPECT_EQ(position.Find("count")->number, mesh.positions.size());
  ASSERT_EQ(position.Find("min")->items.size(), 3u) << "POSITION needs min and max";
  EXPECT_EQ(position.Find("min")->items[1].number, -1.0);
  EXPECT_EQ(position.Find("max")->items[1].number, 1.0);
  const JsonValue& material = doc->Find("materials")->items[0];
  EXPECT_EQ(material.Find("pbrMetallicRoughness")->Find("metallicFactor")->number, 0.0)
      << "glTF's default material is fully metallic";
  EXPECT_TRUE(material.Find("doubleSided")->boolean) << "open reconstructions show both sides";
  EXPECT_EQ(doc->Find("extensionsRequired"), nullptr);
  EXPECT_EQ(doc->Find("accessors")->items.size(), 2u) << "positions and indices, no colours";

  MeshWriteOptions draco;
  draco.gltf_draco = true;
  ASSERT_TRUE(WriteMesh(mesh, path, draco).ok());
  const absl::StatusOr<JsonValue> compressed = ParseJson(GlbJson(ReadBytes(path)));
  ASSERT_TRUE(compressed.ok()) << compressed.status();
  ASSERT_NE(compressed->Find("extensionsRequired"), nullptr);
  EXPECT_EQ(compressed->Find("extensionsRequired")->items[0].text, "KHR_draco_mesh_compression");
  EXPECT_EQ(compressed->Find("accessors")->items[0].Find("bufferView"), nullptr)
      << "Draco accessors have no data of their own";

  // Without faces: POINTS, which only plain glTF can hold.
  TriangleMesh points = mesh;
  points.faces.clear();
  ASSERT_TRUE(WriteMesh(points, path).ok());
  const absl::StatusOr<TriangleMesh> read = ReadMesh(path);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->positions, points.positions);
  EXPECT_TRUE(read->faces.empty());
  const absl::Status refused = WriteMesh(points, path, draco);
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(refused.message()), HasSubstr("no faces"));
}

// Two triangles of a unit square as other tools lay them out: an interleaved buffer view of
// position and an 8-bit RGBA colour (stride 16), 8-bit indices.
struct SquareBuffer {
  std::string bin;
  static constexpr float kCorners[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  SquareBuffer() {
    const uint8_t colors[4][4] = {
        {255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {188, 188, 188, 255}};
    for (int v = 0; v < 4; ++v) {
      for (float c : kCorners[v]) Put(c, false, &bin);
      for (uint8_t c : colors[v]) Put(c, false, &bin);
    }
    for (uint8_t i : {0, 1, 2, 0, 2, 3}) Put(i, false, &bin);
    bin += std::string(2, '\0');  // 70 bytes of data, padded to 72.
  }
};

// The JSON of SquareBuffer's data, with `scene` (scenes, nodes) and `extra` members spliced in.
std::string SquareJson(const std::string& scene, const std::string& buffer_uri = "") {
  return absl::StrCat(
      R"({"asset":{"version":"2.0","generator":"a test"},)", scene,
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"COLOR_0":1},"indices":2}]}],)",
      R"("accessors":[)", R"({"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},)",
      R"({"bufferView":0,"byteOffset":12,"componentType":5121,"normalized":true,"count":4,)",
      R"("type":"VEC4"},)", R"({"bufferView":1,"componentType":5121,"count":6,"type":"SCALAR"}],)",
      R"("bufferViews":[{"buffer":0,"byteLength":64,"byteStride":16},)",
      R"({"buffer":0,"byteOffset":64,"byteLength":6}],)", R"("buffers":[{"byteLength":72)",
      buffer_uri, "}]}");
}

TEST(GltfIoTest, ReadsInterleavedBuffersAndPlacesNodes) {
  const SquareBuffer square;
  // Node 0 moves its child (node 1, the square, scaled by 2) by (10, 0, 0); node 2 draws the
  // square again, mirrored in x, which reverses its winding.
  const std::string scene = R"("scene":0,"scenes":[{"nodes":[0,2]}],"nodes":[)"
                            R"({"translation":[10,0,0],"children":[1]},{"mesh":0,"scale":[2,2,2]},)"
                            R"({"mesh":0,"matrix":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}],)";
  const absl::StatusOr<TriangleMesh> read =
      ReadGlb("nodes.glb", Glb(SquareJson(scene), square.bin));
  ASSERT_TRUE(read.ok()) << read.status();
  const std::vector<Vec3f> expected = {{10, 0, 0}, {12, 0, 0}, {12, 2, 0}, {10, 2, 0},
                                       {0, 0, 5},  {-1, 0, 5}, {-1, 1, 5}, {0, 1, 5}};
  EXPECT_EQ(read->positions, expected);
  const std::vector<std::array<uint32_t, 3>> faces = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}};
  EXPECT_EQ(read->faces, faces) << "the mirrored copy's triangles keep facing out";
  ASSERT_EQ(read->colors.size(), 8u);
  EXPECT_EQ(read->colors[0], (Rgb{255, 0, 0}));
  EXPECT_EQ(read->colors[3], (Rgb{SrgbFromLinear(188 / 255.0), SrgbFromLinear(188 / 255.0),
                                  SrgbFromLinear(188 / 255.0)}))
      << "glTF colours are linear";
  EXPECT_EQ(read->colors[3][0], 223);

  // Without scenes every mesh is read once, where it is.
  const absl::StatusOr<TriangleMesh> bare = ReadGlb("bare.glb", Glb(SquareJson(""), square.bin));
  ASSERT_TRUE(bare.ok()) << bare.status();
  EXPECT_EQ(bare->positions.size(), 4u);
  EXPECT_EQ(bare->positions[2], Vec3f(1, 1, 0));

  // A rotation of 90 degrees about z (quaternion x, y, z, w).
  const std::string rotated =
      R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"rotation":[0,0,0.70710678,0.70710678]}],)";
  const absl::StatusOr<TriangleMesh> turned =
      ReadGlb("rotated.glb", Glb(SquareJson(rotated), square.bin));
  ASSERT_TRUE(turned.ok()) << turned.status();
  EXPECT_NEAR(turned->positions[1][0], 0.0f, 1e-6);
  EXPECT_NEAR(turned->positions[1][1], 1.0f, 1e-6);
}

TEST(GltfIoTest, ReadsExternalAndEmbeddedBuffersOfGltfFiles) {
  const SquareBuffer square;
  const std::string dir = TempPath("external");
  ASSERT_EQ(std::system(absl::StrCat("mkdir -p '", dir, "/data dir'").c_str()), 0);
  WriteBytes(dir + "/data dir/square.bin", square.bin);
  const std::string gltf = dir + "/square.gltf";
  WriteBytes(gltf, SquareJson("", R"(,"uri":"data%20dir/square.bin")"));
  absl::StatusOr<TriangleMesh> read = ReadMesh(gltf);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->faces.size(), 2u);
  EXPECT_EQ(read->colors.size(), 4u);

  std::string base64;
  absl::Base64Escape(square.bin, &base64);
  WriteBytes(gltf, SquareJson("", absl::StrCat(R"(,"uri":"data:application/gltf-buffer;base64,)",
                                               base64, "\"")));
  read = ReadMesh(gltf);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->faces.size(), 2u);

  WriteBytes(gltf, SquareJson("", R"(,"uri":"missing.bin")"));
  read = ReadMesh(gltf);
  EXPECT_EQ(read.status().code(), absl::StatusCode::kNotFound) << read.status();
  EXPECT_THAT(std::string(read.status().message()), HasSubstr("buffer 'missing.bin'"));
  for (const char* uri : {"/etc/passwd", "http://example.com/a.bin", "file:a.bin"}) {
    WriteBytes(gltf, SquareJson("", absl::StrCat(R"(,"uri":")", uri, "\"")));
    read = ReadMesh(gltf);
    EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument) << uri;
    EXPECT_THAT(std::string(read.status().message()), HasSubstr("not a relative file name"));
  }
  // A .glb may keep its buffers beside it too.
  const std::string beside = TempPath("beside.bin");
  WriteBytes(beside, square.bin);
  const std::string name = beside.substr(beside.find_last_of('/') + 1);
  const absl::StatusOr<TriangleMesh> from_glb =
      ReadGlb("external.glb", Glb(SquareJson("", absl::StrCat(R"(,"uri":")", name, "\"")), ""));
  ASSERT_TRUE(from_glb.ok()) << from_glb.status();
  EXPECT_EQ(from_glb->faces.size(), 2u);
}

TEST(GltfIoTest, ReadsStripsFansInstancesAndDropsPartialColours) {
  // One position buffer of a fan of 5 vertices (centre 0), drawn as a fan, as a strip, and as
  // points; the second mesh has no colours, so the file's colours are dropped.
  std::string bin;
  const float fan[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}};
  for (const auto& p : fan) {
    for (float c : p) Put(c, false, &bin);
  }
  for (int v = 0; v < 5; ++v) {
    for (int c = 0; c < 3; ++c) Put(0.5f, false, &bin);
  }
  const std::string json = absl::StrCat(
      R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0,1,2]}],)",
      R"("nodes":[{"mesh":0},{"mesh":1,"translation":[0,0,1]},{"mesh":1,"translation":[0,0,2]}],)",
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"COLOR_0":1},"mode":6}]},)",
      R"({"primitives":[{"attributes":{"POSITION":0},"mode":5},)",
      R"({"attributes":{"POSITION":0},"mode":0}]}],)",
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":5,"type":"VEC3"},)",
      R"({"bufferView":0,"byteOffset":60,"componentType":5126,"count":5,"type":"VEC3"}],)",
      R"("bufferViews":[{"buffer":0,"byteLength":120}],"buffers":[{"byteLength":120}]})");
  const absl::StatusOr<TriangleMesh> read = ReadGlb("modes.glb", Glb(json, bin));
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->positions.size(), 15u) << "the fan, then two instances of the strip's vertices";
  EXPECT_TRUE(read->colors.empty()) << "colours of only some vertices are left out";
  // Fan: (1,2,0), (2,3,0), (3,4,0). Strip: (0,1,2), (1,3,2), (2,3,4) per instance; the points
  // primitive adds no vertices (they are the strip's) and no faces.
  const std::vector<std::array<uint32_t, 3>> expected = {{1, 2, 0},    {2, 3, 0},    {3, 4, 0},
                                                         {5, 6, 7},    {6, 8, 7},    {7, 8, 9},
                                                         {10, 11, 12}, {11, 13, 12}, {12, 13, 14}};
  EXPECT_EQ(read->faces, expected);

  const absl::StatusOr<PointCloud> points = ReadPointCloud(TempPath("modes.glb"));
  ASSERT_TRUE(points.ok()) << points.status();
  EXPECT_EQ(points->positions.size(), 15u);
}

TEST(GltfIoTest, PointCloudsKeepTheirNormalsWeightsAndColours) {
  PointCloud cloud = io_test::RandomCloud(300, 7, /*normals=*/true, /*weights=*/true);
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud.colors.push_back({static_cast<uint8_t>(i), static_cast<uint8_t>(255 - i % 256), 7});
  }
  for (const char* name : {"points.glb", "points.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = TempPath(name);
    ASSERT_TRUE(WritePointCloud(cloud, path).ok());
    const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->positions, cloud.positions);
    EXPECT_EQ(read->normals, cloud.normals) << "unit normals come back bitwise";
    EXPECT_EQ(read->weights, cloud.weights);
    EXPECT_EQ(read->colors, cloud.colors);
  }
  const absl::StatusOr<JsonValue> doc = ParseJson(GlbJson(ReadBytes(TempPath("points.glb"))));
  ASSERT_TRUE(doc.ok()) << doc.status();
  const JsonValue& primitive = doc->Find("meshes")->items[0].Find("primitives")->items[0];
  EXPECT_EQ(primitive.Find("mode")->number, 0) << "POINTS";
  const JsonValue* attributes = primitive.Find("attributes");
  ASSERT_NE(attributes->Find("NORMAL"), nullptr);
  ASSERT_NE(attributes->Find("_WEIGHT"), nullptr) << "application-specific semantics begin with _";
  const JsonValue& accessors = *doc->Find("accessors");
  const JsonValue& weight = accessors.items[attributes->Find("_WEIGHT")->number];
  EXPECT_EQ(weight.Find("type")->text, "SCALAR");
  EXPECT_EQ(weight.Find("count")->number, cloud.size());
  const JsonValue& normal = accessors.items[attributes->Find("NORMAL")->number];
  EXPECT_EQ(normal.Find("componentType")->number, 5126) << "float";
  const JsonValue& views = *doc->Find("bufferViews");
  EXPECT_EQ(views.items.size(), 4u) << "positions, colours, normals, weights; no indices";
  for (const JsonValue& view : views.items) EXPECT_EQ(view.Find("target")->number, 34962);

  // glTF wants unit normals: others are made so, zero ones stay zero.
  PointCloud odd = io_test::RandomCloud(2, 8, true, false);
  odd.normals = {Vec3f(0, 3, 4), Vec3f(0, 0, 0)};
  ASSERT_TRUE(WritePointCloud(odd, TempPath("odd.glb")).ok());
  const absl::StatusOr<PointCloud> unit = ReadPointCloud(TempPath("odd.glb"));
  ASSERT_TRUE(unit.ok()) << unit.status();
  EXPECT_EQ(unit->normals, (std::vector<Vec3f>{Vec3f(0, 0.6f, 0.8f), Vec3f(0, 0, 0)}));
  // Meshes carry neither.
  const absl::StatusOr<TriangleMesh> as_mesh = ReadMesh(TempPath("points.glb"));
  ASSERT_TRUE(as_mesh.ok()) << as_mesh.status();
  EXPECT_EQ(as_mesh->positions, cloud.positions);
}

TEST(GltfIoTest, ReadsNormalsTurnedByTheirNodesAndWeightsByOtherNames) {
  // Two points with float normals and 8-bit normalized confidences, drawn by a node that
  // stretches x by 2 and mirrors z.
  std::string bin;
  for (float c : {0.f, 0.f, 0.f, 1.f, 2.f, 3.f}) Put(c, false, &bin);
  const float s = 1 / std::sqrt(2.0f);
  for (float c : {s, s, 0.f, 0.f, 0.f, 1.f}) Put(c, false, &bin);
  for (uint8_t c : {255, 51}) Put(c, false, &bin);
  bin += std::string(2, '\0');
  const auto json = [](const std::string& normal_count, const std::string& second_mesh) {
    return absl::StrCat(
        R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],)",
        R"("nodes":[{"mesh":0,"scale":[2,1,-1]}],)",
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1,"_CONFIDENCE":2},)",
        R"("mode":0})", second_mesh, R"(]}],)",
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":2,"type":"VEC3"},)",
        R"({"bufferView":1,"componentType":5126,"count":)", normal_count, R"(,"type":"VEC3"},)",
        R"({"bufferView":2,"componentType":5121,"normalized":true,"count":2,"type":"SCALAR"}],)",
        R"("bufferViews":[{"buffer":0,"byteLength":24},{"buffer":0,"byteOffset":24,)",
        R"("byteLength":24},{"buffer":0,"byteOffset":48,"byteLength":2}],)",
        R"("buffers":[{"byteLength":52}]})");
  };
  const std::string path = TempPath("turned.glb");
  WriteBytes(path, Glb(json("2", ""), bin));
  const absl::StatusOr<PointCloud> read = ReadPointCloud(path);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->positions, (std::vector<Vec3f>{Vec3f(0, 0, 0), Vec3f(2, 2, -3)}));
  ASSERT_EQ(read->normals.size(), 2u);
  // Normals turn by the inverse transpose: (1, 1, 0) under x stretched by 2 leans toward y.
  EXPECT_NEAR(read->normals[0][0], 1 / std::sqrt(5.0f), 1e-6);
  EXPECT_NEAR(read->normals[0][1], 2 / std::sqrt(5.0f), 1e-6);
  EXPECT_NEAR(read->normals[0][2], 0, 1e-6);
  EXPECT_NEAR(read->normals[1][2], -1, 1e-6) << "mirrored in z, the normal turns with it";
  EXPECT_NEAR(read->weights[0], 1.0, 1e-6);
  EXPECT_NEAR(read->weights[1], 0.2, 1e-6);

  // A second primitive without them: the file's normals and weights are left out.
  WriteBytes(path, Glb(json("2", R"(,{"attributes":{"POSITION":0},"mode":0})"), bin));
  const absl::StatusOr<PointCloud> partial = ReadPointCloud(path);
  ASSERT_TRUE(partial.ok()) << partial.status();
  EXPECT_TRUE(partial->normals.empty());
  EXPECT_TRUE(partial->weights.empty());

  WriteBytes(path, Glb(json("1", ""), bin));
  const absl::StatusOr<PointCloud> short_normals = ReadPointCloud(path);
  EXPECT_EQ(short_normals.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(short_normals.status().message()),
              HasSubstr("meshes[0].primitives[0]: NORMAL has 1 elements for 2 positions"));
  EXPECT_EQ(ReadMesh(path).status().code(), absl::StatusCode::kInvalidArgument)
      << "the file is malformed, whatever is read from it";

  // Another application's "_CONFIDENCE" of three values is not a weight: passed over.
  std::string vec3 = json("2", "");
  const std::string scalar = R"("componentType":5121,"normalized":true,"count":2,"type":"SCALAR")";
  ASSERT_NE(vec3.find(scalar), std::string::npos);
  vec3.replace(vec3.find(scalar), scalar.size(), R"("componentType":5126,"count":2,"type":"VEC3")");
  vec3 = absl::StrReplaceAll(vec3, {{R"("byteOffset":48,"byteLength":2)",
                                     R"("byteOffset":24,"byteLength":24)"}});
  WriteBytes(path, Glb(vec3, bin));
  const absl::StatusOr<PointCloud> foreign = ReadPointCloud(path);
  ASSERT_TRUE(foreign.ok()) << foreign.status();
  EXPECT_TRUE(foreign->weights.empty());
  EXPECT_EQ(foreign->normals.size(), 2u);
}

TEST(GltfIoTest, RefusesMalformedFilesAndSaysWhatIsWrong) {
  const SquareBuffer square;
  const std::string good = SquareJson("");
  const auto replaced = [&](const char* from, const char* to) {
    std::string json = good;
    EXPECT_NE(json.find(from), std::string::npos) << from;
    return absl::StrReplaceAll(json, {{from, to}});
  };
  std::string bad_version = Glb(good, square.bin);
  bad_version[4] = 1;
  struct Case {
    std::string what;
    std::string bytes;
    std::string message;
  } cases[] = {
      {"truncated header", "glTF\x02", "the .glb header is truncated"},
      {"container version", bad_version, "version 1; only 2 is supported"},
      {"truncated file", Glb(good, square.bin).substr(0, 100), "(truncated?)"},
      {"JSON syntax", Glb("{\"asset\":", square.bin), "JSON byte 12: expected a value"},
      {"glTF 1", Glb(replaced("\"2.0\"", "\"1.0\""), square.bin), "only glTF 2 is supported"},
      {"no asset", Glb(R"({"meshes":[]})", ""), "asset.version is missing"},
      {"accessor past its view",
       Glb(replaced(R"("count":6,"type":"SCALAR")", R"("count":7,"type":"SCALAR")"), square.bin),
       "accessors[2] (indices): 7 elements"},
      {"index past the vertices",
       Glb(good, square.bin.substr(0, 64) + std::string("\x00\x01\x09\0\0\0\0\0", 8)),
       "index 9 at 2 is past its 4 vertices"},
      {"view past the buffer", Glb(replaced("\"byteOffset\":64", "\"byteOffset\":68"), square.bin),
       "bufferViews[1] (bytes 68 to 74) reaches past buffers[0]"},
      {"missing accessor", Glb(replaced("\"indices\":2", "\"indices\":5"), square.bin),
       "accessors[5] does not exist (there are 3)"},
      {"wrong index type",
       Glb(replaced("\"componentType\":5121,\"count\":6", "\"componentType\":5126,\"count\":6"),
           square.bin),
       "componentType 5126, which does not fit"},
      {"sparse", Glb(replaced("\"count\":6,", "\"count\":6,\"sparse\":{},"), square.bin),
       "is sparse, which is not supported"},
      {"not whole triangles",
       Glb(replaced(R"("count":6,"type":"SCALAR")", R"("count":5,"type":"SCALAR")"), square.bin),
       "5 indices do not make whole triangles"},
      {"required extension",
       Glb(replaced(R"("asset":)", R"("extensionsRequired":["EXT_meshopt_compression"],"asset":)"),
           square.bin),
       "requires the extension EXT_meshopt_compression"},
      {"node cycle",
       Glb(absl::StrCat(R"({"scenes":[{"nodes":[0]}],"nodes":[{"children":[1]},{"children":[0]}],)",
                        good.substr(1)),
           square.bin),
       "nodes[0] is reached twice"},
      {"non-finite position",
       Glb(absl::StrCat(R"({"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,)",
                        R"("scale":[1e39,1e39,1e39]}],)", good.substr(1)),
           square.bin),
       "is not finite where its node places it"},
      {"base64", Glb(replaced("\"byteLength\":72", "\"byteLength\":72,\"uri\":\"data:x,abc\""), ""),
       "a data URI that is not base64"},
      {"no BIN chunk", Glb(good, ""), "has no uri and is not the BIN chunk"},
      {"corrupt Draco",
       Glb(replaced(R"("indices":2)",
                    R"("indices":2,"extensions":{"KHR_draco_mesh_compression":{"bufferView":0,)"
                    R"("attributes":{"POSITION":0}}})"),
           square.bin),
       "KHR_draco_mesh_compression: not valid Draco data"},
  };
  for (const Case& c : cases) {
    const absl::StatusOr<TriangleMesh> read = ReadGlb("bad.glb", c.bytes);
    ASSERT_FALSE(read.ok()) << c.what;
    EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument) << c.what;
    EXPECT_THAT(std::string(read.status().message()), HasSubstr(c.message)) << c.what;
    EXPECT_THAT(std::string(read.status().message()), HasSubstr("bad.glb")) << c.what;
  }
}

}  // namespace
}  // namespace neuralmesh
