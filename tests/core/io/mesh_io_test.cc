#include "core/io/mesh_io.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using io_test::ExpectSameMesh;
using io_test::Put;
using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;


// Writes `content` to a fresh file called `name` and reads it as a mesh.
absl::StatusOr<TriangleMesh> ReadContent(const std::string& name, const std::string& content) {
  const std::string path = TempPath(name);
  WriteBytes(path, content);
  return ReadMesh(path);
}

// Expects reading `content` from `name` to fail with INVALID_ARGUMENT mentioning `substring`.
void ExpectRejected(const std::string& name, const std::string& content,
                    const std::string& substring, const std::string& what) {
  const absl::StatusOr<TriangleMesh> mesh = ReadContent(name, content);
  ASSERT_FALSE(mesh.ok()) << what << ": the malformed file was accepted";
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument)
      << what << ": wrong status code: " << mesh.status();
  EXPECT_THAT(std::string(mesh.status().message()), HasSubstr(substring))
      << what << ": the message does not explain the problem";
  EXPECT_THAT(std::string(mesh.status().message()), HasSubstr(name))
      << what << ": the message does not name the file";
}

TriangleMesh MakeMesh(std::vector<Vec3f> positions, std::vector<std::array<uint32_t, 3>> faces) {
  TriangleMesh mesh;
  mesh.positions = std::move(positions);
  mesh.faces = std::move(faces);
  return mesh;
}

void ExpectExactly(const TriangleMesh& expected, const absl::StatusOr<TriangleMesh>& actual,
                   const std::string& what) {
  ASSERT_TRUE(actual.ok()) << what << ": " << actual.status();
  EXPECT_EQ(actual->positions, expected.positions) << what << ": positions differ";
  EXPECT_EQ(actual->faces, expected.faces) << what << ": faces differ";
}

// The unit square 0-1-2-3 and an apex 4, as used by the hand-written files below.
const TriangleMesh kSquarePyramid =
    MakeMesh({Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1, 1, 0), Vec3f(0, 1, 0), Vec3f(0.5f, 0.5f, 1)},
             {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}});

class MeshRoundTripTest : public ::testing::TestWithParam<const char*> {};

TEST_P(MeshRoundTripTest, WriteThenReadGivesTheSameMesh) {
  const std::string extension = GetParam();
  const bool lossy = extension == ".drc";
  for (const TriangleMesh& mesh : {testing::Icosphere(2, 1.7), testing::GridPatch(4, 3)}) {
    const std::string path = TempPath("round_trip" + extension);
    const absl::Status written = WriteMesh(mesh, path);
    ASSERT_TRUE(written.ok()) << "writing " << extension << ": " << written;
    const absl::StatusOr<TriangleMesh> read = ReadMesh(path);
    ASSERT_TRUE(read.ok()) << "reading back " << extension << ": " << read.status();
    const float tolerance =
        lossy ? io_test::QuantizationTolerance(io_test::BoundingCubeRange(mesh.positions), 11)
              : 0.0f;
    ExpectSameMesh(mesh, *read, tolerance, "round trip through " + extension);
    if (!lossy && extension != ".stl") {
      EXPECT_EQ(read->positions, mesh.positions) << extension << " must keep vertex order";
      EXPECT_EQ(read->faces, mesh.faces) << extension << " must keep faces as written";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllFormats, MeshRoundTripTest,
                         ::testing::Values(".ply", ".obj", ".off", ".stl", ".drc"),
                         [](const auto& info) { return std::string(info.param + 1); });

TEST(MeshIoTest, ExtensionsAreCaseInsensitive) {
  const TriangleMesh mesh = testing::Icosphere(1);
  for (const char* name : {"UPPER.PLY", "Mixed.Obj", "shape.OFF", "part.Stl", "frame.DRC"}) {
    const std::string path = TempPath(name);
    ASSERT_TRUE(WriteMesh(mesh, path).ok()) << "cannot write " << name;
    EXPECT_TRUE(ReadMesh(path).ok()) << "cannot read " << name;
    EXPECT_TRUE(IsSupportedMeshExtension(path)) << name << " should be supported";
  }
  EXPECT_FALSE(IsSupportedMeshExtension("cloud.xyz")) << ".xyz holds points, not meshes";
  EXPECT_FALSE(IsSupportedMeshExtension("noextension")) << "no extension, no format";
  EXPECT_FALSE(IsSupportedMeshExtension("dir.ply/file")) << "the dot is in a directory name";
}

TEST(MeshIoTest, MissingFileIsNotFound) {
  const absl::StatusOr<TriangleMesh> mesh = ReadMesh(TempPath("does/not/exist.ply"));
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kNotFound) << mesh.status();
  EXPECT_THAT(std::string(mesh.status().message()), HasSubstr("cannot open"))
      << "the message should say the file cannot be opened";
}

TEST(MeshIoTest, DirectoryIsNotReadable) {
  const std::string dir = TempPath("dir_named.obj");
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  const absl::StatusOr<TriangleMesh> from_dir = ReadMesh(dir);
  EXPECT_EQ(from_dir.status().code(), absl::StatusCode::kNotFound)
      << "reading a directory: " << from_dir.status();
}

TEST(MeshIoTest, UnknownExtensionListsTheSupportedOnes) {
  for (const char* name : {"mesh.abc", "cloud.xyz", "noextension"}) {
    const absl::StatusOr<TriangleMesh> mesh = ReadMesh(TempPath(name));
    EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument) << name;
    EXPECT_THAT(std::string(mesh.status().message()), HasSubstr(".ply, .obj, .off, .stl, .drc"))
        << name << ": the message should list the supported extensions";
    const absl::Status written = WriteMesh(testing::Icosphere(0), TempPath(name));
    EXPECT_EQ(written.code(), absl::StatusCode::kInvalidArgument) << name << ": " << written;
  }
}

TEST(MeshIoTest, EmptyFilesAreRejected) {
  for (const char* name : {"empty.ply", "empty.obj", "empty.off", "empty.stl", "empty.drc"}) {
    ExpectRejected(name, "", "is empty", name);
  }
  ExpectRejected("comments_only.obj", "# nothing here\n\n", "contains no vertices",
                 "OBJ without vertices");
}

TEST(MeshIoTest, PlyVerticesWithoutFacesReadAsAMeshWithoutFaces) {
  const absl::StatusOr<TriangleMesh> mesh =
      ReadContent("points_only.ply",
                  "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n1 2 3\n4 5 6\n");
  ExpectExactly(MakeMesh({Vec3f(1, 2, 3), Vec3f(4, 5, 6)}, {}), mesh, "PLY without faces");
}

// ---------------------------------------------------------------------------------------------
// PLY

TEST(PlyReadTest, AsciiWithPolygonsListPropertiesAndExtraElements) {
  const std::string ply =
      "ply\r\n"  // Windows line endings in the header are fine.
      "format ascii 1.0\n"
      "comment hand written\n"
      "obj_info generated for a test\n"
      "element vertex 5\n"
      "property float x\n"
      "property float y\n"
      "property double z\n"
      "property list uchar int tags\n"
      "property uchar red\n"
      "element face 2\n"
      "property uchar flags\n"
      "property list uchar int vertex_indices\n"
      "property list uchar float texcoord\n"
      "element edge 1\n"
      "property int vertex1\n"
      "property int vertex2\n"
      "end_header\n"
      "0 0 0 2 7 8 255\n"
      "1 0 0 0 1\n"
      "\n"
      "1 1 0 1 5 3\n"
      "0 1 0   0 4\n"
      "0.5 0.5 1 3 1 2 3 9\n"
      "1 4 0 1 2 3 0\n"
      "0 3 0 3 4 6 0 0 1 0 1 1\n"
      "0 1\n";
  ExpectExactly(kSquarePyramid, ReadContent("ascii.ply", ply), "ASCII PLY");
}

std::string BinaryPlyHeader(const char* format) {
  return std::string("ply\nformat ") + format +
         " 1.0\n"
         "element vertex 5\n"
         "property double x\n"
         "property double y\n"
         "property double z\n"
         "property ushort quality\n"
         "element material 1\n"
         "property list uchar uchar name\n"
         "element face 2\n"
         "property list uchar uint vertex_indices\n"
         "property short flags\n"
         "end_header\n";
}

std::string BinaryPlyBody(bool big_endian) {
  std::string out;
  for (const Vec3f& p : kSquarePyramid.positions) {
    for (int c = 0; c < 3; ++c) Put<double>(p[c], big_endian, &out);
    Put<uint16_t>(500, big_endian, &out);
  }
  out += '\x03';
  out += "abc";
  Put<uint8_t>(4, big_endian, &out);
  for (uint32_t v : {0u, 1u, 2u, 3u}) Put(v, big_endian, &out);
  Put<int16_t>(-3, big_endian, &out);
  Put<uint8_t>(3, big_endian, &out);
  for (uint32_t v : {0u, 3u, 4u}) Put(v, big_endian, &out);
  Put<int16_t>(7, big_endian, &out);
  return out;
}

TEST(PlyReadTest, BinaryBigEndian) {
  ExpectExactly(kSquarePyramid,
                ReadContent("big.ply", BinaryPlyHeader("binary_big_endian") + BinaryPlyBody(true)),
                "binary big-endian PLY");
}

TEST(PlyReadTest, BinaryLittleEndian) {
  ExpectExactly(
      kSquarePyramid,
      ReadContent("little.ply", BinaryPlyHeader("binary_little_endian") + BinaryPlyBody(false)),
      "binary little-endian PLY");
}

TEST(PlyReadTest, BinaryLittleEndianWithIntegerCoordinates) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty short x\n"
      "property char y\nproperty uint z\nelement face 1\nproperty list int ushort "
      "vertex_index\nend_header\n";
  const int16_t xs[3] = {-2, 300, 0};
  const int8_t ys[3] = {-128, 5, 127};
  const uint32_t zs[3] = {0, 7, 100000};
  for (int i = 0; i < 3; ++i) {
    Put(xs[i], false, &ply);
    Put(ys[i], false, &ply);
    Put(zs[i], false, &ply);
  }
  Put<int32_t>(3, false, &ply);
  for (uint16_t v : {2, 1, 0}) Put(v, false, &ply);
  ExpectExactly(
      MakeMesh({Vec3f(-2, -128, 0), Vec3f(300, 5, 7), Vec3f(0, 127, 100000)}, {{2, 1, 0}}),
      ReadContent("ints.ply", ply), "integer-typed PLY coordinates");
}

const char kAsciiHeader[] =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST(PlyReadTest, MalformedFilesAreRejectedWithAReason) {
  struct Case {
    const char* what;
    std::string content;
    const char* message;
  };
  std::string truncated = BinaryPlyHeader("binary_little_endian") + BinaryPlyBody(false);
  truncated.resize(truncated.size() - 5);
  std::string bogus_count =
      "ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  bogus_count.append(20, '\0');  // About 150 bytes in all.
  std::string binary_bad_index =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list uchar uint "
      "vertex_indices\nend_header\n";
  for (int c = 0; c < 3; ++c) Put<float>(1, false, &binary_bad_index);
  Put<uint8_t>(3, false, &binary_bad_index);
  for (uint32_t v : {0u, 0u, 9u}) Put(v, false, &binary_bad_index);
  std::string binary_nan =
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  for (float v : {0.0f, NAN, 0.0f}) Put(v, true, &binary_nan);

  const Case cases[] = {
      {"bad magic", "plx\nformat ascii 1.0\nend_header\n", "expected 'ply'"},
      {"bad format", "ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown PLY format"},
      {"no end_header", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
       "no 'end_header'"},
      {"unknown keyword", "ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n",
       "line 3: unexpected header keyword"},
      {"unknown type",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n"
       "end_header\n0\n",
       "line 4: unknown property type 'float128'"},
      {"negative count", "ply\nformat ascii 1.0\nelement vertex -1\nend_header\n",
       "line 3: expected 'element <name> <non-negative count>'"},
      {"missing x",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\n"
       "property float z\nend_header\n1 2\n",
       "no scalar property 'x'"},
      {"truncated binary", truncated, "truncated"},
      {"vertex count beyond the data", bogus_count, "declares 999999999999 'vertex' elements"},
      {"ascii count beyond the data",
       "ply\nformat ascii 1.0\nelement vertex 100000\nproperty float x\nend_header\n1\n",
       "declares 100000 'vertex' elements but only"},
      {"letters for a number", std::string(kAsciiHeader) + "0 0 0\n1 abc 0\n0 1 0\n3 0 1 2\n",
       "line 11: expected a number for property 'y' of vertex 1, found 'abc'"},
      {"too few values", std::string(kAsciiHeader) + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n",
       "line 11: vertex 1 has too few values"},
      {"too many values", std::string(kAsciiHeader) + "0 0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
       "line 10: vertex 0 has 4 values"},
      {"file ends early", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n",
       "the file ends after 2 of the 3 'vertex' elements"},
      {"face index out of range", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
       "line 13: face 0 uses vertex index 7; the file has 3 vertices"},
      {"negative face index", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
       "uses vertex index -1"},
      {"fractional face index", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n",
       "expected an integer"},
      {"two-vertex face", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
       "face 0 has 2 vertices; a face needs at least 3"},
      {"NaN coordinate", std::string(kAsciiHeader) + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
       "line 11: vertex 1 has a non-finite coordinate"},
      {"coordinate beyond float", std::string(kAsciiHeader) + "0 0 1e39\n1 0 0\n0 1 0\n3 0 1 2\n",
       "vertex 0 has a non-finite coordinate"},
      {"binary face index out of range", binary_bad_index, "uses vertex index 9"},
      {"face index out of range in a face element before the vertices, another after",
       "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
       "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "3 0 1 1000\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
       "triangle 0 uses vertex 1000; the file has 3 vertices"},
      {"binary NaN", binary_nan, "non-finite"},
      {"no vertex element",
       "ply\nformat ascii 1.0\nelement face 0\n"
       "property list uchar int vertex_indices\nend_header\n",
       "no 'vertex' element"},
      {"face without indices",
       "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
       "property float y\nproperty float z\nelement face 1\n"
       "property int a\nend_header\n1\n",
       "no 'vertex_indices'"},
  };
  for (const Case& c : cases) ExpectRejected("malformed.ply", c.content, c.message, c.what);
}

// ---------------------------------------------------------------------------------------------
// OBJ

TEST(ObjReadTest, AllFaceReferenceFormsNegativeIndicesAndPolygons) {
  const std::string obj =
      "# a hand-written OBJ\n"
      "mtllib scene.mtl\n"
      "o thing\n"
      "v 0 0 0\n"
      "v 1 0 0\n"
      "v 1 1 0\n"
      "v 0 1 0 1.0\n"  // With the optional w.
      "vt 0 0\nvt 1 0\n"
      "vn 0 0 1\n"
      "g group\nusemtl red\ns 1\n"
      "f 1 2 3\n"
      "f 1/1 3/2 4/1\n"
      "f 1/1/1 2/2/1 3/1/1   # trailing comment\n"
      "f 1//1 3//1 4//1\r\n"
      "v 0.5 0.5 1\n"
      "f -1 -5 -4\n"  // Relative: the apex, vertex 1, vertex 2.
      "f 1 2 3 4 5\n"
      "l 1 2\n";
  ExpectExactly(
      MakeMesh(
          {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1, 1, 0), Vec3f(0, 1, 0), Vec3f(0.5f, 0.5f, 1)},
          {{0, 1, 2}, {0, 2, 3}, {0, 1, 2}, {0, 2, 3}, {4, 0, 1}, {0, 1, 2}, {0, 2, 3}, {0, 3, 4}}),
      ReadContent("forms.obj", obj), "OBJ reference forms");
}

TEST(ObjReadTest, MalformedFilesAreRejectedWithAReason) {
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\n";
  const struct {
    const char* what;
    std::string content;
    const char* message;
  } cases[] = {
      {"letters in a vertex", "v 0 0 0\nv 1 zero 0\n",
       "line 2: expected a number for coordinate y of a vertex, found 'zero'"},
      {"two coordinates", "v 0 0\n", "line 1: expected 'v x y z', found 2 coordinates"},
      {"NaN vertex", "v 0 0 0\nv nan 0 0\n", "line 2: vertex has a non-finite coordinate"},
      {"infinite vertex", "v 0 0 inf\n", "line 1: vertex has a non-finite coordinate"},
      {"index 0", square + "f 0 1 2\n", "line 4: face index 0 is invalid"},
      {"index beyond the vertices", square + "f 1 2 3\nf 1 2 9\n",
       "line 5: face uses vertex 9 but the file has 3 vertices"},
      {"relative index before the first vertex", square + "f -1 -2 -4\n",
       "line 4: relative face index -4 points before the first vertex"},
      {"two-vertex face", square + "f 1 2\n", "line 4: a face needs at least 3 vertices"},
      {"letters in a face", square + "f 1 b 3\n", "line 4: expected a vertex index"},
      {"bad texture index", square + "f 1/x 2 3\n", "line 4: malformed face reference '1/x'"},
      {"too many slashes", square + "f 1/1/1/1 2 3\n", "expected v, v/vt, v/vt/vn or v//vn"},
  };
  for (const auto& c : cases) ExpectRejected("malformed.obj", c.content, c.message, c.what);
}

// ---------------------------------------------------------------------------------------------
// OFF

TEST(OffReadTest, VariantsCommentsAndPolygons) {
  const TriangleMesh expected = kSquarePyramid;
  const std::string body = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 1 2 3\n3 0 3 4\n";
  ExpectExactly(expected, ReadContent("plain.off", "OFF\n5 2 0\n" + body), "OFF");
  ExpectExactly(expected, ReadContent("inline_counts.off", "# comment\nOFF 5 2 8\n\n" + body),
                "counts on the keyword line");
  ExpectExactly(expected,
                ReadContent("colors.off",
                            "COFF\n5 2 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n"
                            "1 1 0 0 0 255 255\n0 1 0 1 1 1 1\n0.5 0.5 1 9 9 9 9\n"
                            "4 0 1 2 3 255 0 0\n3 0 3 4\n"),
                "COFF with vertex and face colors");
  ExpectExactly(expected,
                ReadContent("normals.off",
                            "NOFF\n5 2 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n"
                            "0 1 0 0 0 1\n0.5 0.5 1 0 0 1\n4 0 1 2 3\n3 0 3 4\n"),
                "NOFF");
}

TEST(OffReadTest, MalformedFilesAreRejectedWithAReason) {
  const std::string vertices = "0 0 0\n1 0 0\n1 1 0\n";
  const struct {
    const char* what;
    std::string content;
    const char* message;
  } cases[] = {
      {"bad keyword", "OFX\n3 1 0\n" + vertices + "3 0 1 2\n", "expected the keyword OFF"},
      {"4D OFF", "4OFF\n3 1 0\n", "unsupported OFF variant '4OFF'"},
      {"binary OFF", "OFF BINARY\n", "binary OFF is not supported"},
      {"letters in the counts", "OFF\nthree 1 0\n", "line 2: expected a non-negative vertex count"},
      {"missing counts", "OFF\n", "expected the counts"},
      {"count beyond the data", "OFF\n99999999 1 0\n0 0 0\n", "declares 99999999 vertices"},
      {"too few vertices", "OFF\n4 1 0\n" + vertices, "the file ends after 3 of the 4 vertices"},
      {"too few faces", "OFF\n3 2 0\n" + vertices + "3 0 1 2\n",
       "the file ends after 1 of the 2 faces"},
      {"letters in a vertex", "OFF\n3 1 0\n0 0 0\n1 x 0\n1 1 0\n3 0 1 2\n",
       "line 4: expected a finite number in vertex 1, found 'x'"},
      {"NaN vertex", "OFF\n3 1 0\n0 0 0\n1 nan 0\n1 1 0\n3 0 1 2\n",
       "line 4: expected a finite number in vertex 1, found 'nan'"},
      {"short vertex line", "OFF\n3 1 0\n0 0 0\n1 0\n1 1 0\n3 0 1 2\n",
       "line 4: expected 'x y z' for vertex 1, found 2 values"},
      {"index out of range", "OFF\n3 1 0\n" + vertices + "3 0 1 3\n",
       "line 6: face 0 uses vertex 3; valid indices are 0 to 2"},
      {"two-vertex face", "OFF\n3 1 0\n" + vertices + "2 0 1\n",
       "line 6: expected a vertex count of at least 3 for face 0"},
      {"face lists too few indices", "OFF\n3 1 0\n" + vertices + "4 0 1 2\n",
       "face 0 declares 4 vertices but lists 3"},
  };
  for (const auto& c : cases) ExpectRejected("malformed.off", c.content, c.message, c.what);
}

// ---------------------------------------------------------------------------------------------
// STL

// Two triangles sharing the edge (1,0,0)-(0,1,0): 4 distinct positions.
constexpr float kStlTriangles[2][3][3] = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                          {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
const TriangleMesh kStlMesh = MakeMesh(
    {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(1, 1, 0)}, {{0, 1, 2}, {1, 3, 2}});

std::string BinaryStl(const std::string& header_text, int count_adjust = 0) {
  std::string out = header_text;
  out.resize(80, ' ');
  Put<uint32_t>(2 + count_adjust, false, &out);
  for (const auto& triangle : kStlTriangles) {
    for (int c = 0; c < 3; ++c) Put<float>(c == 2 ? 1.0f : 0.0f, false, &out);
    for (const auto& vertex : triangle) {
      for (float coordinate : vertex) Put(coordinate, false, &out);
    }
    Put<uint16_t>(0, false, &out);
  }
  return out;
}

TEST(StlReadTest, AsciiMergesSharedVertices) {
  const std::string stl =
      "solid two triangles\n"
      "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n"
      "      vertex 0 1 0\n    endloop\n  endfacet\n"
      "endsolid two triangles\n"
      "solid second\n"
      "  facet normal 0 0 1\n    outer loop\n      vertex 1 0 0\n      vertex 1 1 0\n"
      "      vertex -0 1 0\n    endloop\n  endfacet\n"
      "endsolid\n";
  ExpectExactly(kStlMesh, ReadContent("ascii.stl", stl), "ASCII STL (two solids, -0 == 0)");
}

TEST(StlReadTest, BinaryMergesSharedVerticesEvenWithASolidHeader) {
  ExpectExactly(kStlMesh, ReadContent("binary.stl", BinaryStl("binary header")), "binary STL");
  ExpectExactly(kStlMesh, ReadContent("solid_header.stl", BinaryStl("solid but binary")),
                "binary STL whose header starts with 'solid'");
}

TEST(StlReadTest, MalformedFilesAreRejectedWithAReason) {
  std::string nan_stl = BinaryStl("binary");
  const float nan = NAN;
  std::memcpy(&nan_stl[84 + 50 + 12 + 4], &nan, sizeof(float));
  const std::string facet_start = "solid s\nfacet normal 0 0 1\nouter loop\n";
  const struct {
    const char* what;
    std::string content;
    const char* message;
  } cases[] = {
      {"binary count too large", BinaryStl("binary", 5),
       "declares 7 triangles, which take 434 bytes, but the file has 184"},
      {"binary truncated", BinaryStl("binary").substr(0, 150), "declares 2 triangles"},
      {"tiny file", "abc", "too few for a binary STL"},
      {"binary NaN", nan_stl, "byte 134: triangle 1 has a non-finite coordinate"},
      {"four vertices in a facet",
       facet_start + "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 0\nendloop\n",
       "line 7: a facet has 4 vertices; STL facets are triangles"},
      {"two vertices in a facet", facet_start + "vertex 0 0 0\nvertex 1 0 0\nendloop\n",
       "line 6: a facet has 2 vertices"},
      {"letters in a vertex", facet_start + "vertex 0 zero 0\n",
       "line 4: expected a number for coordinate y, found 'zero'"},
      {"NaN in ASCII", facet_start + "vertex 0 nan 0\n", "line 4: vertex has a non-finite"},
      {"missing endsolid",
       facet_start + "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n",
       "the file ends inside a solid"},
      {"missing outer loop", "solid s\nfacet normal 0 0 1\nvertex 0 0 0\n",
       "line 3: expected 'outer loop', found 'vertex'"},
  };
  for (const auto& c : cases) ExpectRejected("malformed.stl", c.content, c.message, c.what);
}

// ---------------------------------------------------------------------------------------------
// Draco files and write errors

TEST(MeshIoTest, CorruptDracoFilesAreRejected) {
  ExpectRejected("corrupt.drc", "DRACO\x02\x02\x01\x01garbage garbage", "Draco", "garbage");
  const std::string cloud_path = TempPath("cloud_not_mesh.drc");
  PointCloud cloud;
  cloud.positions = {Vec3f(0, 0, 0), Vec3f(1, 2, 3)};
  const absl::StatusOr<std::string> cloud_bytes = EncodePointCloud(cloud, {});
  ASSERT_TRUE(cloud_bytes.ok()) << cloud_bytes.status();
  ExpectRejected("cloud_not_mesh.drc", *cloud_bytes, "point cloud", "a Draco point cloud");
}

TEST(MeshIoTest, WriteRejectsInvalidMeshesAndReportsIoFailures) {
  const TriangleMesh good = testing::Icosphere(1);
  const TriangleMesh empty;
  const absl::Status missing_dir = WriteMesh(good, TempPath("no_such_dir/x.ply"));
  EXPECT_EQ(missing_dir.code(), absl::StatusCode::kNotFound) << missing_dir;
  EXPECT_THAT(std::string(missing_dir.message()), HasSubstr("cannot write"))
      << "the message should say what failed";

  const std::string dir = TempPath("is_a_dir.obj");
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  EXPECT_FALSE(WriteMesh(good, dir).ok()) << "writing over a directory must fail";

  TriangleMesh bad_index = good;
  bad_index.faces[2][0] = 99;
  TriangleMesh nan_vertex = good;
  nan_vertex.positions[4][1] = NAN;
  TriangleMesh no_faces = good;
  no_faces.faces.clear();
  DracoOptions bad_options;
  bad_options.encode_speed = 42;
  DracoOptions small_box;
  small_box.quantization_box = QuantizationBox{Vec3f(0, 0, 0), 0.5f};
  const struct {
    const char* what;
    const TriangleMesh& mesh;
    const char* name;
    DracoOptions options;
    const char* message;
  } cases[] = {
      {"empty mesh", empty, "empty.ply", {}, "the mesh is empty"},
      {"face index out of range", bad_index, "bad.obj", {}, "face 2 uses vertex 99"},
      {"NaN vertex", nan_vertex, "nan.off", {}, "vertex 4 has a non-finite coordinate"},
      {"STL without faces", no_faces, "no_faces.stl", {}, "no faces"},
      {"Draco without faces", no_faces, "no_faces.drc", {}, "no faces"},
      {"bad Draco options", good, "options.drc", bad_options, "encode_speed"},
      {"outside the Draco box", good, "box.drc", small_box, "outside the quantization box"},
  };
  for (const auto& c : cases) {
    const absl::Status status = WriteMesh(c.mesh, TempPath(c.name), {c.options});
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << c.what << ": " << status;
    EXPECT_THAT(std::string(status.message()), HasSubstr(c.message)) << c.what;
  }
  EXPECT_TRUE(WriteMesh(no_faces, TempPath("no_faces.ply")).ok())
      << "PLY, OBJ and OFF can store vertices without faces";
}

// Every prefix of a valid file is read without crashing, and fails, if it does, with
// INVALID_ARGUMENT.
TEST(MeshIoTest, TruncatedFilesFailCleanly) {
  const TriangleMesh mesh = testing::Icosphere(1);
  for (const char* extension : {".ply", ".obj", ".off", ".stl", ".drc"}) {
    const std::string path = TempPath(std::string("whole") + extension);
    ASSERT_TRUE(WriteMesh(mesh, path).ok());
    const std::string bytes = io_test::ReadBytes(path);
    const size_t step = std::max<size_t>(1, bytes.size() / 300);
    for (size_t length = 0; length < bytes.size(); length += step) {
      const absl::StatusOr<TriangleMesh> read =
          ReadContent(std::string("prefix") + extension, bytes.substr(0, length));
      if (!read.ok()) {
        ASSERT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument)
            << extension << " cut to " << length << " bytes: " << read.status();
      }
    }
  }
}

}  // namespace
}  // namespace neuralmesh
