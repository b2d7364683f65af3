#include "core/io/draco_codec.h"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/point_cloud_io.h"
#include "core/random.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

using io_test::BoundingCubeRange;
using io_test::ExpectSameCloud;
using io_test::ExpectSameMesh;
using io_test::QuantizationTolerance;
using io_test::TempPath;
using ::testing::HasSubstr;

constexpr char kDracoEncoder[] = "/usr/bin/draco_encoder";
constexpr char kDracoDecoder[] = "/usr/bin/draco_decoder";

void ExpectInvalid(const absl::Status& status, const std::string& substring,
                   const std::string& context) {
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument)
      << context << ": expected INVALID_ARGUMENT, got " << status;
  EXPECT_THAT(std::string(status.message()), HasSubstr(substring))
      << context << ": the message does not say what is wrong";
}

TEST(DracoOptionsTest, DefaultsAreValid) {
  EXPECT_TRUE(DracoOptions().Validate().ok()) << "default options must validate";
}

TEST(DracoOptionsTest, ValidateNamesTheBadField) {
  struct Case {
    const char* field;
    void (*mutate)(DracoOptions&);
  };
  const Case cases[] = {
      {"position_quantization_bits", [](DracoOptions& o) { o.position_quantization_bits = 0; }},
      {"position_quantization_bits", [](DracoOptions& o) { o.position_quantization_bits = 25; }},
      {"normal_quantization_bits", [](DracoOptions& o) { o.normal_quantization_bits = 1; }},
      {"weight_quantization_bits", [](DracoOptions& o) { o.weight_quantization_bits = 25; }},
      {"normal_quantization_bits", [](DracoOptions& o) { o.normal_quantization_bits = 25; }},
      {"encode_speed", [](DracoOptions& o) { o.encode_speed = -1; }},
      {"encode_speed", [](DracoOptions& o) { o.encode_speed = 11; }},
      {"decode_speed", [](DracoOptions& o) { o.decode_speed = 11; }},
      {"quantization_box.range", [](DracoOptions& o) { o.quantization_box = QuantizationBox{}; }},
      {"quantization_box.range",
       [](DracoOptions& o) {
         o.quantization_box = QuantizationBox{Vec3f(0, 0, 0), NAN};
       }},
      {"quantization_box.origin",
       [](DracoOptions& o) {
         o.quantization_box = QuantizationBox{Vec3f(INFINITY, 0, 0), 1};
       }},
  };
  for (const Case& c : cases) {
    DracoOptions options;
    c.mutate(options);
    ExpectInvalid(options.Validate(), c.field, c.field);
    ExpectInvalid(EncodeMesh(testing::Icosphere(1), options).status(), c.field,
                  std::string("EncodeMesh with bad ") + c.field);
  }
}

TEST(DracoCodecTest, EncodeRejectsEmptyAndInvalidInput) {
  ExpectInvalid(EncodeMesh(TriangleMesh{}, {}).status(), "empty", "empty mesh");
  ExpectInvalid(EncodePointCloud(PointCloud{}, {}).status(), "empty", "empty cloud");

  TriangleMesh no_faces = testing::Icosphere(1);
  no_faces.faces.clear();
  ExpectInvalid(EncodeMesh(no_faces, {}).status(), "no faces", "mesh without faces");

  TriangleMesh bad_index = testing::Icosphere(1);
  bad_index.faces[3][1] = 1000;
  ExpectInvalid(EncodeMesh(bad_index, {}).status(), "face 3", "face index out of range");

  TriangleMesh all_degenerate;
  all_degenerate.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
  all_degenerate.faces = {{0, 0, 1}, {1, 1, 1}};
  ExpectInvalid(EncodeMesh(all_degenerate, {}).status(), "degenerate", "only degenerate faces");

  TriangleMesh nan_vertex = testing::Icosphere(1);
  nan_vertex.positions[7][2] = NAN;
  ExpectInvalid(EncodeMesh(nan_vertex, {}).status(), "vertex 7", "NaN coordinate");

  PointCloud bad_weights = io_test::RandomCloud(10, 1, false, true);
  bad_weights.weights.pop_back();
  ExpectInvalid(EncodePointCloud(bad_weights, {}).status(), "weights",
                "weights count differs from point count");
}

TEST(DracoCodecTest, MeshRoundTripIsWithinQuantizationTolerance) {
  for (int bits : {8, 11, 16}) {
    for (int speed : {0, 5, 10}) {
      const TriangleMesh mesh = testing::Icosphere(3, 2.5);
      DracoOptions options;
      options.position_quantization_bits = bits;
      options.encode_speed = speed;
      options.decode_speed = speed;
      const absl::StatusOr<std::string> bytes = EncodeMesh(mesh, options);
      ASSERT_TRUE(bytes.ok()) << "encoding failed at " << bits << " bits: " << bytes.status();
      const absl::StatusOr<TriangleMesh> decoded = DecodeMesh(*bytes);
      ASSERT_TRUE(decoded.ok()) << "decoding failed: " << decoded.status();
      ExpectSameMesh(
          mesh, *decoded, QuantizationTolerance(BoundingCubeRange(mesh.positions), bits),
          "Icosphere(3) at " + std::to_string(bits) + " bits, speed " + std::to_string(speed));
    }
  }
}

TEST(DracoCodecTest, OpenMeshWithBoundaryRoundTrips) {
  const TriangleMesh grid = testing::GridPatch(7, 5);
  const absl::StatusOr<std::string> bytes = EncodeMesh(grid, {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::StatusOr<TriangleMesh> decoded = DecodeMesh(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  ExpectSameMesh(grid, *decoded, QuantizationTolerance(1.0f, 11), "GridPatch(7, 5)");
}

TEST(DracoCodecTest, EdgebreakerDropsUnusedVerticesAndDegenerateFacesAndSplitsBowties) {
  const TriangleMesh sphere = testing::Icosphere(1);
  TriangleMesh messy = sphere;
  messy.positions.emplace_back(5.0f, 5.0f, 5.0f);  // Used by no face.
  messy.faces.push_back({0, 0, 1});                // Degenerate.
  const absl::StatusOr<std::string> bytes = EncodeMesh(messy, {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::StatusOr<TriangleMesh> decoded = DecodeMesh(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  ExpectSameMesh(sphere, *decoded, QuantizationTolerance(BoundingCubeRange(messy.positions), 11),
                 "the sphere without its unused vertex and degenerate face");

  // Two triangles touching at vertex 0 only: Draco gives each fan its own copy of vertex 0.
  TriangleMesh bowtie;
  bowtie.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(-1, 0, 0),
                      Vec3f(0, -1, 0)};
  bowtie.faces = {{0, 1, 2}, {0, 3, 4}};
  const absl::StatusOr<TriangleMesh> split = DecodeMesh(*EncodeMesh(bowtie, {}));
  ASSERT_TRUE(split.ok()) << split.status();
  EXPECT_EQ(split->positions.size(), 6u) << "the non-manifold vertex should be duplicated";
  ExpectSameMesh(bowtie, *split, QuantizationTolerance(2.0f, 11), "bowtie geometry");
}

TEST(DracoCodecTest, IcosphereLevel5NeedsAtMost8BytesPerVertexAt11Bits) {
  const TriangleMesh mesh = testing::Icosphere(5);
  DracoOptions options;
  options.position_quantization_bits = 11;
  const absl::StatusOr<std::string> bytes = EncodeMesh(mesh, options);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const double per_vertex = static_cast<double>(bytes->size()) / mesh.positions.size();
  std::cout << "Draco Icosphere(5): " << mesh.positions.size() << " vertices, " << mesh.faces.size()
            << " faces, " << bytes->size() << " bytes = " << per_vertex
            << " bytes/vertex at 11 bits, speed 5\n";
  ::testing::Test::RecordProperty("bytes_per_vertex", std::to_string(per_vertex));
  EXPECT_LE(per_vertex, 8.0) << "the product budget is 8 bytes per vertex";
}

// Small meshes like a session's first levels of detail (6 to 42 vertices, closed and open),
// each with the quantization box a session would give it: its bounding cube enlarged 2x.
std::vector<TriangleMesh> SmallMeshes() {
  std::vector<TriangleMesh> meshes;
  for (int seed = 1; seed <= 4; ++seed) {
    TriangleMesh bumpy = testing::Icosphere(0);
    for (size_t v = 0; v < bumpy.positions.size(); ++v) {
      bumpy.positions[v] *= 1.0f + 0.15f * std::sin(static_cast<float>(seed * 7 + v * 3));
    }
    meshes.push_back(bumpy);
  }
  for (const auto& [nx, ny] : {std::pair{1, 2}, {2, 2}, {3, 3}, {3, 4}, {4, 5}, {5, 6}}) {
    meshes.push_back(testing::GridPatch(nx, ny));
  }
  TriangleMesh octahedron;
  octahedron.positions = {Vec3f(1, 0, 0),  Vec3f(-1, 0, 0), Vec3f(0, 1, 0),
                          Vec3f(0, -1, 0), Vec3f(0, 0, 1),  Vec3f(0, 0, -1)};
  octahedron.faces = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                      {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  meshes.push_back(octahedron);
  return meshes;
}

DracoOptions SessionOptions(const TriangleMesh& mesh) {
  const float range = BoundingCubeRange(mesh.positions);
  Vec3f low = mesh.positions.front(), high = low;
  for (const Vec3f& p : mesh.positions) {
    low.minimize(p);
    high.maximize(p);
  }
  const Vec3f centre = (low + high) / 2;
  DracoOptions options;
  options.quantization_box = QuantizationBox{centre - Vec3f(range, range, range), 2 * range};
  return options;
}

TEST(DracoCodecTest, SmallMeshesKeepTheShortestOfSeveralEncodings) {
  int shorter = 0;
  const std::vector<TriangleMesh> meshes = SmallMeshes();
  for (size_t i = 0; i < meshes.size(); ++i) {
    const std::string context = "small mesh " + std::to_string(i) + " (" +
                                std::to_string(meshes[i].positions.size()) + " vertices)";
    DracoOptions exact = SessionOptions(meshes[i]);
    exact.shrink_small_meshes = false;
    const absl::StatusOr<std::string> given = EncodeMesh(meshes[i], exact);
    const absl::StatusOr<std::string> shortest = EncodeMesh(meshes[i], SessionOptions(meshes[i]));
    ASSERT_TRUE(given.ok() && shortest.ok())
        << context << ": " << given.status() << " / " << shortest.status();
    EXPECT_LE(shortest->size(), given->size())
        << context << ": the shortest stream is longer than the one with the given settings";
    shorter += shortest->size() < given->size() ? 1 : 0;
    const absl::StatusOr<TriangleMesh> from_given = DecodeMesh(*given);
    const absl::StatusOr<TriangleMesh> from_shortest = DecodeMesh(*shortest);
    ASSERT_TRUE(from_given.ok() && from_shortest.ok()) << context << ": decoding failed";
    ExpectSameMesh(*from_given, *from_shortest, 0.0f,
                   context + ": every encoding decodes to the same grid points and faces");
  }
  EXPECT_GT(shorter, 0) << "no small mesh got a shorter stream than with the given settings, "
                           "so the other encodings were not tried (or never help)";
}

// DracoExactBox at every scale: the box contains the one asked for and is one Draco keeps
// exactly, so asking again changes nothing.
TEST(DracoCodecTest, ExactBoxesContainTheBoxAndAreKeptAsTheyAre) {
  Random random(17);
  for (int i = 0; i < 2000; ++i) {
    const double scale = std::pow(10.0, -9 + 17 * random.NextDouble());
    QuantizationBox box;
    for (int c = 0; c < 3; ++c) {
      box.origin[c] = static_cast<float>(scale * (4 * random.NextDouble() - 2));
    }
    box.range = static_cast<float>(scale * (0.01 + random.NextDouble()));
    const QuantizationBox exact = DracoExactBox(box);
    const std::string context = "box " + std::to_string(i) + " at scale " + std::to_string(scale);
    for (int c = 0; c < 3; ++c) {
      ASSERT_LE(exact.origin[c], box.origin[c]) << context;
      ASSERT_GE(double{exact.origin[c]} + exact.range, double{box.origin[c]} + box.range)
          << context;
    }
    const QuantizationBox again = DracoExactBox(exact);
    ASSERT_EQ(again.origin, exact.origin) << context;
    ASSERT_EQ(again.range, exact.range) << context;
    const QuantizationBox read = BoxAsDracoReadsIt(exact);
    ASSERT_EQ(read.origin, exact.origin) << context << ": Draco would read it differently";
    ASSERT_EQ(read.range, exact.range) << context << ": Draco would read it differently";
  }
}

// What Draco makes of a box it is given: six decimals (the grid the server's fuzzed boxes
// decode on, fuzz/corpus/draco_encoder_fuzzer/crash-box-read-with-six-decimals).
TEST(DracoCodecTest, BoxAsDracoReadsItRoundsToSixDecimals) {
  QuantizationBox box;
  box.origin = Vec3f(-1.2888323e-05f, 1e-7f, 2.5f);
  box.range = 1.35020528e-05f;
  const QuantizationBox read = BoxAsDracoReadsIt(box);
  EXPECT_EQ(read.origin, Vec3f(-1.3e-05f, 0.0f, 2.5f));
  EXPECT_EQ(read.range, 1.4e-05f);
}

// Draco receives a fixed box as text with six decimals, so a box of edge 3e-9 reached it as
// edge 0: it then crashed (fuzz/draco_encoder_fuzzer.cc found a 4-vertex mesh) or decoded every
// point to 0. Such a box must be rejected with a message that says so, and DracoExactBox must
// give a box that contains it and encodes at every scale.
TEST(DracoCodecTest, FixedBoxesAreTakenAsDracoReadsThem) {
  for (const double extent : {3e-9, 1e-6, 1e-3, 0.7, 1e3, 3e7}) {
    const std::string context = "extent " + std::to_string(extent);
    TriangleMesh mesh = testing::GridPatch(6, 6);  // [0, 1]^2 at z = 0.
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      Vec3f& p = mesh.positions[i];
      p = Vec3f(static_cast<float>(extent * (p[0] + 0.1234567)),
                static_cast<float>(extent * (p[1] - 2.345678)),
                static_cast<float>(extent * 0.3 * std::sin(static_cast<double>(i))));
    }
    const QuantizationBox box{
        Vec3f(static_cast<float>(extent * 0.07), static_cast<float>(extent * -2.4),
              static_cast<float>(extent * -0.35)),
        static_cast<float>(extent * 1.1)};
    const QuantizationBox exact = DracoExactBox(box);
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(exact.origin[c], box.origin[c]) << context;
      EXPECT_GE(double{exact.origin[c]} + exact.range, double{box.origin[c]} + box.range)
          << context;
    }
    if (extent >= 1e-3) {
      EXPECT_LE(exact.range, box.range * 1.01) << context << ": the exact box grew too much";
    }
    DracoOptions options;
    options.position_quantization_bits = 14;
    options.quantization_box = exact;
    const absl::StatusOr<std::string> bytes = EncodeMesh(mesh, options);
    ASSERT_TRUE(bytes.ok()) << context << ": " << bytes.status();
    const absl::StatusOr<TriangleMesh> decoded = DecodeMesh(*bytes);
    ASSERT_TRUE(decoded.ok()) << context << ": " << decoded.status();
    // QuantizationTolerance's absolute slack is too coarse at these scales: half a step, and
    // float rounding relative to the box.
    const double tolerance =
        exact.range / ((1 << 14) - 1) * 0.5 * 1.001 +
        4 * std::numeric_limits<float>::epsilon() *
            (std::abs(exact.origin[0]) + std::abs(exact.origin[1]) + exact.range);
    ASSERT_EQ(decoded->positions.size(), mesh.positions.size()) << context;
    EXPECT_EQ(decoded->faces.size(), mesh.faces.size()) << context;
    for (const Vec3f& p : decoded->positions) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Vec3f& q : mesh.positions) {
        double d = 0;
        for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(double{p[c]} - double{q[c]}));
        nearest = std::min(nearest, d);
      }
      EXPECT_LE(nearest, tolerance) << context << ": decoded vertex far from every input";
    }
    if (extent < 1e-6) {
      options.quantization_box = box;
      ExpectInvalid(EncodeMesh(mesh, options).status(), "six decimals", context);
    }
  }

  // The fuzzer's mesh, in the server's box: 1.1 times its extent of 3e-29.
  TriangleMesh tiny;
  tiny.positions = {Vec3f(1.3132476e-38f, 0.0f, 2.8398993e-29f),
                    Vec3f(2.8411367e-29f, 2.8411367e-29f, 2.8411367e-29f),
                    Vec3f(2.8411367e-29f, 4.2336235e-37f, 2.8411367e-29f),
                    Vec3f(6.0669049e-39f, 6.1350416e-39f, 6.1328892e-39f)};
  tiny.faces = {{2, 0, 3}, {1, 2, 3}};
  DracoOptions options;
  options.position_quantization_bits = 14;
  options.quantization_box =
      QuantizationBox{Vec3f(-1.42057e-30f, -1.42057e-30f, -1.42057e-30f), 3.12525e-29f};
  ExpectInvalid(EncodeMesh(tiny, options).status(), "six decimals", "the fuzzer's mesh");
  options.quantization_box = DracoExactBox(*options.quantization_box);
  const absl::StatusOr<std::string> bytes = EncodeMesh(tiny, options);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::StatusOr<TriangleMesh> decoded = DecodeMesh(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_EQ(decoded->faces.size(), 2u) << "the fuzzer's mesh in its exact box";
}

TEST(DracoCodecTest, MeshesOf64VerticesOrMoreUseTheGivenSettingsOnly) {
  const TriangleMesh mesh = testing::Icosphere(2);  // 162 vertices.
  DracoOptions exact = SessionOptions(mesh);
  exact.shrink_small_meshes = false;
  const absl::StatusOr<std::string> given = EncodeMesh(mesh, exact);
  const absl::StatusOr<std::string> chosen = EncodeMesh(mesh, SessionOptions(mesh));
  ASSERT_TRUE(given.ok() && chosen.ok()) << given.status() << " / " << chosen.status();
  EXPECT_EQ(*chosen, *given) << "a larger mesh must be encoded once, as configured";
}

TEST(DracoCodecTest, PointCloudRoundTripKeepsNormalsAndWeights) {
  const PointCloud cloud = io_test::RandomCloud(2000, 7, true, true);
  for (int speed : {0, 5, 10}) {  // Kd-tree below 10, sequential at 10.
    DracoOptions options;
    options.encode_speed = speed;
    options.decode_speed = speed;
    const absl::StatusOr<std::string> bytes = EncodePointCloud(cloud, options);
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    const absl::StatusOr<PointCloud> decoded = DecodePointCloud(*bytes);
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    ExpectSameCloud(cloud, *decoded, QuantizationTolerance(BoundingCubeRange(cloud.positions), 11),
                    /*normal_tolerance=*/0.01f, /*weight_tolerance=*/1.5f / 65535 + 1e-5f,
                    "speed " + std::to_string(speed));
    if (speed == 10) {
      const float tolerance = QuantizationTolerance(BoundingCubeRange(cloud.positions), 11);
      for (size_t i = 0; i < cloud.size(); ++i) {
        ASSERT_LE((decoded->positions[i] - cloud.positions[i]).max_abs(), tolerance)
            << "the sequential coder (speed 10) should keep point " << i << " in place";
      }
    }
  }
}

TEST(DracoCodecTest, PointCloudWithoutOptionalAttributesDecodesWithout) {
  const PointCloud cloud = io_test::RandomCloud(300, 3, false, false);
  const absl::StatusOr<std::string> bytes = EncodePointCloud(cloud, {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::StatusOr<PointCloud> decoded = DecodePointCloud(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  ExpectSameCloud(cloud, *decoded, QuantizationTolerance(2.0f, 11), 0, 0, "positions only");
}

TEST(DracoCodecTest, DecodePointCloudRefusesMoreDeclaredPointsThanAllowed) {
  const PointCloud cloud = io_test::RandomCloud(300, 3, false, false);
  const absl::StatusOr<std::string> bytes = EncodePointCloud(cloud, {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::Status refused = DecodePointCloud(*bytes, 299).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kResourceExhausted) << refused;
  EXPECT_THAT(std::string(refused.message()), HasSubstr("declares 300 points; at most 299"));
  EXPECT_TRUE(DecodePointCloud(*bytes, 300).ok());

  const TriangleMesh mesh = testing::Icosphere(2);  // 162 vertices, 320 faces.
  const absl::StatusOr<std::string> mesh_bytes = EncodeMesh(mesh, {});
  ASSERT_TRUE(mesh_bytes.ok()) << mesh_bytes.status();
  EXPECT_EQ(DecodePointCloud(*mesh_bytes, 161).status().code(),
            absl::StatusCode::kResourceExhausted)
      << "a mesh's vertices count as points";
  EXPECT_TRUE(DecodePointCloud(*mesh_bytes, 162).ok()) << "and its faces against twice that";
}

TEST(DracoCodecTest, DecodePointCloudAcceptsAMesh) {
  const TriangleMesh mesh = testing::Icosphere(2);
  const absl::StatusOr<std::string> bytes = EncodeMesh(mesh, {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::StatusOr<PointCloud> cloud = DecodePointCloud(*bytes);
  ASSERT_TRUE(cloud.ok()) << "a Draco mesh must decode as a point cloud: " << cloud.status();
  PointCloud expected;
  expected.positions = mesh.positions;
  ExpectSameCloud(expected, *cloud, QuantizationTolerance(2.0f, 11), 0, 0, "mesh vertices");
}

TEST(DracoCodecTest, DecodeMeshRejectsAPointCloud) {
  const absl::StatusOr<std::string> bytes =
      EncodePointCloud(io_test::RandomCloud(50, 2, false, false), {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  ExpectInvalid(DecodeMesh(*bytes).status(), "point cloud", "DecodeMesh on a point cloud");
}

// A copy of `mesh` with every vertex above z = 0.3 pushed outwards, so the two meshes differ
// (and have different bounding boxes) but share all other vertices exactly.
TriangleMesh Bulged(const TriangleMesh& mesh) {
  TriangleMesh bulged = mesh;
  for (Vec3f& p : bulged.positions) {
    if (p[2] > 0.3f) p *= 1.37f;
  }
  return bulged;
}

TEST(DracoCodecTest, FixedQuantizationBoxPutsSuccessiveMeshesOnOneGrid) {
  const TriangleMesh a = testing::Icosphere(3);
  const TriangleMesh b = Bulged(a);
  DracoOptions options;
  options.position_quantization_bits = 12;
  options.quantization_box = QuantizationBox{Vec3f(-1.5f, -1.5f, -1.5f), 3.0f};
  const absl::StatusOr<std::string> bytes_a = EncodeMesh(a, options);
  const absl::StatusOr<std::string> bytes_b = EncodeMesh(b, options);
  ASSERT_TRUE(bytes_a.ok() && bytes_b.ok()) << bytes_a.status() << " / " << bytes_b.status();
  const absl::StatusOr<TriangleMesh> decoded_a = DecodeMesh(*bytes_a);
  const absl::StatusOr<TriangleMesh> decoded_b = DecodeMesh(*bytes_b);
  ASSERT_TRUE(decoded_a.ok() && decoded_b.ok()) << "decoding failed";

  const float tolerance = QuantizationTolerance(3.0f, 12);
  ExpectSameMesh(a, *decoded_a, tolerance, "mesh A in the fixed box");
  ExpectSameMesh(b, *decoded_b, tolerance, "mesh B in the fixed box");
  const std::vector<int> match_a =
      io_test::MatchPoints(a.positions, decoded_a->positions, tolerance);
  const std::vector<int> match_b =
      io_test::MatchPoints(b.positions, decoded_b->positions, tolerance);
  std::vector<int> where_a(a.positions.size(), -1), where_b(b.positions.size(), -1);
  for (size_t i = 0; i < match_a.size(); ++i)
    if (match_a[i] >= 0) where_a[match_a[i]] = i;
  for (size_t i = 0; i < match_b.size(); ++i)
    if (match_b[i] >= 0) where_b[match_b[i]] = i;

  const double step = 3.0 / ((1 << 12) - 1);
  int shared = 0;
  for (size_t v = 0; v < a.positions.size(); ++v) {
    if (a.positions[v] != b.positions[v]) continue;  // Moved by the bulge.
    ASSERT_GE(where_a[v], 0) << "vertex " << v << " missing from decoded A";
    ASSERT_GE(where_b[v], 0) << "vertex " << v << " missing from decoded B";
    const Vec3f& pa = decoded_a->positions[where_a[v]];
    const Vec3f& pb = decoded_b->positions[where_b[v]];
    EXPECT_EQ(std::memcmp(pa.data(), pb.data(), sizeof(Vec3f)), 0)
        << "input vertex " << v << " at " << a.positions[v] << " decoded to " << pa
        << " in mesh A but " << pb << " in mesh B: the meshes do not share one grid";
    for (int c = 0; c < 3; ++c) {
      const double cell = (pa[c] - (-1.5)) / step;
      EXPECT_NEAR(cell, std::round(cell), 1e-3)
          << "decoded coordinate " << pa[c] << " is not on the box's grid";
    }
    ++shared;
  }
  EXPECT_GT(shared, 100) << "the test meshes should share many vertices";

  // Without the box each mesh is quantized in its own bounding box, so shared vertices drift.
  const absl::StatusOr<TriangleMesh> own_a = DecodeMesh(*EncodeMesh(a, {}));
  const absl::StatusOr<TriangleMesh> own_b = DecodeMesh(*EncodeMesh(b, {}));
  ASSERT_TRUE(own_a.ok() && own_b.ok());
  std::vector<Vec3f> sorted_a, sorted_b;
  for (const Vec3f& p : own_a->positions)
    if (p[2] < 0.2f) sorted_a.push_back(p);
  for (const Vec3f& p : own_b->positions)
    if (p[2] < 0.2f) sorted_b.push_back(p);
  auto less = [](const Vec3f& x, const Vec3f& y) {
    return std::lexicographical_compare(x.data(), x.data() + 3, y.data(), y.data() + 3);
  };
  std::sort(sorted_a.begin(), sorted_a.end(), less);
  std::sort(sorted_b.begin(), sorted_b.end(), less);
  EXPECT_NE(sorted_a, sorted_b)
      << "without a fixed box the per-mesh grids were expected to differ (this checks that "
         "the test above exercises the box)";
}

TEST(DracoCodecTest, FixedQuantizationBoxAppliesToPointClouds) {
  const PointCloud cloud = io_test::RandomCloud(500, 11, true, false);
  DracoOptions options;
  options.quantization_box = QuantizationBox{Vec3f(-4, -4, -4), 8};
  const absl::StatusOr<std::string> bytes = EncodePointCloud(cloud, options);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::StatusOr<PointCloud> decoded = DecodePointCloud(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  const double step = 8.0 / ((1 << 11) - 1);
  for (const Vec3f& p : decoded->positions) {
    for (int c = 0; c < 3; ++c) {
      const double cell = (p[c] + 4.0) / step;
      ASSERT_NEAR(cell, std::round(cell), 1e-3) << "point " << p << " is off the box's grid";
    }
  }
  ExpectSameCloud(cloud, *decoded, QuantizationTolerance(8, 11), 0.01f, 0, "cloud in box");
}

TEST(DracoCodecTest, PositionsOutsideTheFixedBoxAreRejected) {
  DracoOptions options;
  options.quantization_box = QuantizationBox{Vec3f(0, 0, 0), 1};
  ExpectInvalid(EncodeMesh(testing::Icosphere(1), options).status(), "outside the quantization box",
                "sphere around the origin in the positive unit cube");
  ExpectInvalid(EncodePointCloud(io_test::RandomCloud(20, 5, false, false), options).status(),
                "outside the quantization box", "cloud in [-1, 1]^3 in the positive unit cube");
  // A box whose far corner is exactly the farthest point is fine.
  options.quantization_box = QuantizationBox{Vec3f(0, 0, 0), 1};
  EXPECT_TRUE(EncodeMesh(testing::GridPatch(3, 3), options).ok())
      << "GridPatch spans exactly [0, 1]^2 and must fit the unit box";
}

// Draco multiplies by (2^bits - 1) / range in float; below about 2^bits / 3.4e38 that
// overflows and its encoder crashed (found by fuzz/draco_fuzzer.cc re-encoding a decoded mesh
// of extent 1e-42). Such ranges must be rejected, and the smallest ones that work must work.
TEST(DracoCodecTest, RangesTooSmallToQuantizeAreRejectedNotCrashed) {
  for (const auto& [bits, too_small, enough] :
       {std::tuple{11, 1e-36f, 1e-35f}, {20, 1e-33f, 1e-31f}, {24, 1e-32f, 1e-30f}}) {
    const std::string context = std::to_string(bits) + " bits";
    DracoOptions options;
    options.position_quantization_bits = bits;
    TriangleMesh mesh = testing::Icosphere(1);
    for (Vec3f& p : mesh.positions) p *= too_small;
    ExpectInvalid(EncodeMesh(mesh, options).status(), "too little for", context);
    PointCloud cloud;
    cloud.positions = mesh.positions;
    ExpectInvalid(EncodePointCloud(cloud, options).status(), "too little for", context);
    options.quantization_box =
        QuantizationBox{Vec3f(-too_small, -too_small, -too_small), 2 * too_small};
    ExpectInvalid(EncodeMesh(mesh, options).status(), "its range is", context);

    options.quantization_box.reset();
    for (Vec3f& p : mesh.positions) p *= enough / too_small;
    const absl::StatusOr<std::string> bytes = EncodeMesh(mesh, options);
    ASSERT_TRUE(bytes.ok()) << context << ": " << bytes.status();
    const absl::StatusOr<TriangleMesh> decoded = DecodeMesh(*bytes);
    ASSERT_TRUE(decoded.ok()) << context << ": " << decoded.status();
    // At this scale the grid's steps are denormal floats, too coarse for ExpectSameMesh's
    // distance arithmetic; what must hold is that no two vertices collapse into one (as they
    // all did when Draco's scale overflowed).
    EXPECT_EQ(decoded->positions.size(), mesh.positions.size()) << context << ": vertices merged";
    EXPECT_EQ(decoded->faces.size(), mesh.faces.size()) << context << ": faces lost";
  }
  PointCloud weighted = io_test::RandomCloud(20, 3, false, true);
  for (size_t i = 0; i < weighted.size(); ++i) weighted.weights[i] = 1e-40f * (1 + i % 2);
  ExpectInvalid(EncodePointCloud(weighted, DracoOptions{}).status(), "weights", "weights 1e-40");
}

// Draco decodes q * range / (2^bits - 1) + origin in float: a mesh spanning nearly the whole
// float range (found by fuzz/draco_fuzzer.cc re-encoding a decoded mesh) encoded, then decoded
// to infinities. It must be rejected instead.
TEST(DracoCodecTest, RangesReachingPastTheLargestFloatAreRejected) {
  TriangleMesh mesh;
  mesh.positions = {Vec3f(9.4e-38f, 9.4e-38f, 2.3e-38f), Vec3f(0, -1.7e38f, -1.7e38f),
                    Vec3f(-3.4028e38f, 3.2e-42f, 1.77e28f), Vec3f(1.7e25f, 4.3e27f, 7.2e28f)};
  mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  ExpectInvalid(EncodeMesh(mesh, {}).status(), "past the largest float", "mesh");
  PointCloud cloud;
  cloud.positions = mesh.positions;
  ExpectInvalid(EncodePointCloud(cloud, {}).status(), "past the largest float", "cloud");
  for (Vec3f& p : mesh.positions) p *= 0.5f;  // Half the span is fine.
  const absl::StatusOr<std::string> bytes = EncodeMesh(mesh, {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::StatusOr<TriangleMesh> decoded = DecodeMesh(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
}

// The largest bit count allowed (kMaxQuantizationBits) must work at the speeds that pick
// different predictors and coders, on small meshes (which also try the encodings without
// prediction) and on a large one. (Each encoding at 24 bits takes about 0.1 s.)
TEST(DracoCodecTest, MeshesEncodeAtTheMaximumBits) {
  const std::vector<TriangleMesh> small = SmallMeshes();
  const std::vector<TriangleMesh> meshes = {small.front(), small[small.size() / 2], small.back(),
                                            testing::Icosphere(3)};
  for (const int speed : {0, 1, 5, 10}) {
    DracoOptions options;
    options.position_quantization_bits = kMaxQuantizationBits;
    options.encode_speed = speed;
    options.decode_speed = speed;
    for (const TriangleMesh& mesh : meshes) {
      const std::string context =
          std::to_string(mesh.positions.size()) + " vertices, speed " + std::to_string(speed);
      const absl::StatusOr<std::string> bytes = EncodeMesh(mesh, options);
      ASSERT_TRUE(bytes.ok()) << context << ": " << bytes.status();
      const absl::StatusOr<TriangleMesh> decoded = DecodeMesh(*bytes);
      ASSERT_TRUE(decoded.ok()) << context << ": " << decoded.status();
      ExpectSameMesh(mesh, *decoded,
                     QuantizationTolerance(BoundingCubeRange(mesh.positions), kMaxQuantizationBits),
                     context);
    }
  }
}

// Found by fuzz/draco_fuzzer.cc: a 71-byte mesh whose position attribute is declared as
// booleans, one of them stored as 42. Reading that as a bool was undefined; such data is not
// a mesh anyone can mean, and must be rejected with a message naming the problem.
TEST(DracoCodecTest, PositionsOfBooleansAreRejected) {
  const std::string bytes(
      "\x44\x52\x41\x43\x4f\x02\x02\x01\x01\x00\x00\x00\x04\x04\x00\x03\x00\x00\x01\x2f\x01\x01"
      "\x10\x01\xff\x00\x00\x01\x00\x0b\x03\x00\x00\x00\x00\x00\x00\x00\x2a\x00\x3f\x00\xff\xff"
      "\xff\xff\xff\xff\x08\x01\x01\x63\x74\x6f\x6e\x5f\x73\x63\x68\x65\x6d\x65\xff\xff\x6e\x2c"
      "\x50\x6f\x64\x69\x00",
      71);
  ExpectInvalid(DecodeMesh(bytes).status(), "position attribute has data type", "mesh");
  ExpectInvalid(DecodePointCloud(bytes).status(), "position attribute has data type", "cloud");
}

// Draco reserves memory by the counts at the start of a mesh stream before reading anything
// else: a 140-byte stream found by fuzz/point_batch_fuzzer.cc declared 889 million faces and
// made it ask for 3.5 GB. Counts far beyond what the bytes can hold must be rejected first.
TEST(DracoCodecTest, MeshStreamsDeclaringFarTooManyFacesAreRejected) {
  const absl::StatusOr<std::string> valid = EncodeMesh(testing::Icosphere(1), {});
  ASSERT_TRUE(valid.ok()) << valid.status();
  // Draco 2.2 Edgebreaker: an 11-byte header, the traversal type, then varints for the
  // vertex and face counts.
  size_t at = 12;
  auto skip_varint = [&] {
    while (static_cast<uint8_t>((*valid)[at]) & 0x80) ++at;
    ++at;
  };
  skip_varint();
  const size_t faces_at = at;
  skip_varint();
  auto with_faces = [&](uint32_t faces) {
    std::string varint;
    do {
      varint.push_back(static_cast<char>((faces & 0x7f) | (faces > 0x7f ? 0x80 : 0)));
      faces >>= 7;
    } while (faces > 0);
    return valid->substr(0, faces_at) + varint + valid->substr(at);
  };
  const absl::StatusOr<TriangleMesh> as_is = DecodeMesh(with_faces(80));
  ASSERT_TRUE(as_is.ok()) << "the face count was not where the test expects it: " << as_is.status();
  EXPECT_EQ(as_is->faces.size(), 80u);
  ExpectInvalid(DecodeMesh(with_faces(889'000'000)).status(), "declares 889000000 faces",
                "889 million faces");
  ExpectInvalid(DecodePointCloud(with_faces(889'000'000)).status(), "declares 889000000 faces",
                "889 million faces, read as points");
}

// Draco normalises normals in float, and one of length 3e38 (found by the encoder fuzzer)
// overflowed there and decoded to NaN. Normals of any length encode as their directions.
TEST(DracoCodecTest, NormalsOfAnyLengthEncodeAsDirections) {
  PointCloud cloud;
  cloud.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 0, 1)};
  cloud.normals = {Vec3f(3.4e38f, 3.4e38f, 3.4e38f), Vec3f(1e-30f, 0, 0), Vec3f(0, -2.5f, 0),
                   Vec3f(1.3e36f, 3.4e38f, 1e-39f)};
  const absl::StatusOr<std::string> bytes = EncodePointCloud(cloud, {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const absl::StatusOr<PointCloud> decoded = DecodePointCloud(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  ASSERT_EQ(decoded->normals.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    // Draco may reorder points; match each by its position.
    size_t k = 0;
    while (k < 4 && (decoded->positions[k] - cloud.positions[i]).norm() > 1e-3f) ++k;
    ASSERT_LT(k, 4u) << "point " << i << " is missing";
    const Vec3 expected = Vec3(cloud.normals[i][0], cloud.normals[i][1], cloud.normals[i][2]);
    const Vec3 got(decoded->normals[k][0], decoded->normals[k][1], decoded->normals[k][2]);
    EXPECT_NEAR(got.norm(), 1.0, 1e-3) << "normal " << i;
    EXPECT_GT(got.normalized() | expected.normalized(), 0.999) << "normal " << i;
  }
}

// Draco 1.5 still decodes streams of older bitstream versions through legacy paths that read
// counts of their own and never check them: a 102-byte kd-tree point cloud of version 2.1,
// found by fuzz/draco_fuzzer.cc, made it fill 21 GB. Only the versions current encoders write
// are accepted.
TEST(DracoCodecTest, OldBitstreamVersionsAreRejected) {
  const absl::StatusOr<std::string> cloud =
      EncodePointCloud(io_test::RandomCloud(50, 4, false, false), {});
  const absl::StatusOr<std::string> mesh = EncodeMesh(testing::Icosphere(1), {});
  ASSERT_TRUE(cloud.ok() && mesh.ok());
  // Bytes 5 and 6 hold the major and minor version.
  EXPECT_EQ((*cloud)[5], 2);
  EXPECT_EQ((*cloud)[6], 3) << "Draco 1.5 writes point clouds as version 2.3";
  EXPECT_EQ((*mesh)[6], 2) << "and meshes as version 2.2";
  std::string old_cloud = *cloud;
  old_cloud[6] = 1;
  ExpectInvalid(DecodePointCloud(old_cloud).status(), "bitstream version 2.1", "cloud of 2.1");
  std::string old_mesh = *mesh;
  old_mesh[6] = 1;
  ExpectInvalid(DecodeMesh(old_mesh).status(), "bitstream version 2.1", "mesh of 2.1");
  ExpectInvalid(DecodePointCloud(old_mesh).status(), "bitstream version 2.1", "mesh of 2.1");
}

TEST(DracoCodecTest, CorruptAndTruncatedDataIsRejectedWithoutCrashing) {
  ExpectInvalid(DecodeMesh("").status(), "empty", "empty buffer");
  ExpectInvalid(DecodePointCloud("").status(), "empty", "empty buffer");
  ExpectInvalid(DecodeMesh("not a draco file at all").status(), "Draco", "text buffer");

  const absl::StatusOr<std::string> mesh_bytes = EncodeMesh(testing::Icosphere(2), {});
  const absl::StatusOr<std::string> cloud_bytes =
      EncodePointCloud(io_test::RandomCloud(200, 9, true, true), {});
  ASSERT_TRUE(mesh_bytes.ok() && cloud_bytes.ok());

  int truncations_accepted = 0;
  for (const std::string* valid : {&*mesh_bytes, &*cloud_bytes}) {
    for (size_t length = 0; length < valid->size(); ++length) {
      const std::string_view prefix(valid->data(), length);
      const absl::Status mesh_status = DecodeMesh(prefix).status();
      const absl::Status cloud_status = DecodePointCloud(prefix).status();
      // Draco may not need the last few bytes; what matters is a clean status, never a crash.
      if (mesh_status.ok() || cloud_status.ok()) ++truncations_accepted;
      if (!mesh_status.ok()) {
        ASSERT_EQ(mesh_status.code(), absl::StatusCode::kInvalidArgument)
            << "truncation to " << length << " bytes: " << mesh_status;
      }
      if (!cloud_status.ok()) {
        ASSERT_EQ(cloud_status.code(), absl::StatusCode::kInvalidArgument)
            << "truncation to " << length << " bytes: " << cloud_status;
      }
    }
  }
  EXPECT_LE(truncations_accepted, 8) << "most truncations must be detected";

  Random random(2024);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string bytes;
    if (trial % 2 == 0) {
      // Random bytes behind a valid header, so the decoder gets past the magic number.
      bytes = (trial % 4 == 0 ? *mesh_bytes : *cloud_bytes).substr(0, 11);
      const size_t tail = random.NextIndex(400);
      for (size_t i = 0; i < tail; ++i) bytes.push_back(static_cast<char>(random.NextU64()));
    } else {
      // A valid buffer with a few bytes flipped.
      bytes = trial % 4 == 1 ? *mesh_bytes : *cloud_bytes;
      for (int flips = 1 + static_cast<int>(random.NextIndex(4)); flips > 0; --flips) {
        bytes[random.NextIndex(bytes.size())] ^= static_cast<char>(1 + random.NextIndex(255));
      }
    }
    const absl::Status mesh_status = DecodeMesh(bytes).status();
    const absl::Status cloud_status = DecodePointCloud(bytes).status();
    if (!mesh_status.ok()) {
      ASSERT_EQ(mesh_status.code(), absl::StatusCode::kInvalidArgument)
          << "trial " << trial << ": " << mesh_status;
    }
    if (!cloud_status.ok()) {
      ASSERT_EQ(cloud_status.code(), absl::StatusCode::kInvalidArgument)
          << "trial " << trial << ": " << cloud_status;
    }
  }
}

TEST(DracoCodecTest, HugePointCountsInTinyBuffersAreRejectedBeforeAllocating) {
  PointCloud cloud = io_test::RandomCloud(50, 21, true, true);
  for (int speed : {5, 10}) {
    DracoOptions options;
    options.encode_speed = speed;
    const absl::StatusOr<std::string> bytes = EncodePointCloud(cloud, options);
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    // The point count is the int32 after the 11-byte header. Left unchecked, Draco would try
    // to fill gigabytes for this buffer of a few hundred bytes.
    for (const uint32_t count : {0x7f7f7f7fu, 0xffffffffu, 0x10000000u}) {
      std::string corrupt = *bytes;
      std::memcpy(&corrupt[11], &count, sizeof(count));
      const absl::Status status = DecodePointCloud(corrupt).status();
      ExpectInvalid(status, "points in only", "point count " + std::to_string(count));
    }
  }
  // Draco stores many identical points in a few bytes; such legitimate streams still decode.
  PointCloud identical;
  identical.positions.assign(200000, Vec3f(1, 2, 3));
  const absl::StatusOr<std::string> tiny = EncodePointCloud(identical, {});
  ASSERT_TRUE(tiny.ok()) << tiny.status();
  const absl::StatusOr<PointCloud> decoded = DecodePointCloud(*tiny);
  ASSERT_TRUE(decoded.ok()) << "200000 identical points in " << tiny->size()
                            << " bytes must decode: " << decoded.status();
  EXPECT_EQ(decoded->size(), 200000u) << "points lost";
}

bool HaveTool(const char* path) { return access(path, X_OK) == 0; }

int RunTool(const std::string& command) {
  const std::string log = TempPath("draco_tool.log");
  return std::system((command + " > " + log + " 2>&1").c_str());
}

TEST(DracoInteropTest, ReferenceDecoderReadsOurMesh) {
  if (!HaveTool(kDracoDecoder)) GTEST_SKIP() << kDracoDecoder << " is not installed";
  const TriangleMesh mesh = testing::Icosphere(3);
  const absl::StatusOr<std::string> bytes = EncodeMesh(mesh, {});
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const std::string in = TempPath("ours.drc"), out = TempPath("ours_by_reference.ply");
  io_test::WriteBytes(in, *bytes);
  ASSERT_EQ(RunTool(std::string(kDracoDecoder) + " -i " + in + " -o " + out), 0)
      << "draco_decoder failed on our output: " << io_test::ReadBytes(TempPath("draco_tool.log"));
  const absl::StatusOr<TriangleMesh> reference = ReadMesh(out);
  ASSERT_TRUE(reference.ok()) << reference.status();
  const absl::StatusOr<TriangleMesh> ours = DecodeMesh(*bytes);
  ASSERT_TRUE(ours.ok()) << ours.status();
  ExpectSameMesh(*ours, *reference, 0.0f, "reference decoder vs. our decoder, exactly");
  ExpectSameMesh(mesh, *reference, QuantizationTolerance(2.0f, 11), "reference vs. input");
}

TEST(DracoInteropTest, ReferenceDecoderReadsTheShortestEncodingsOfSmallMeshes) {
  if (!HaveTool(kDracoDecoder)) GTEST_SKIP() << kDracoDecoder << " is not installed";
  int other_than_given = 0;
  const std::vector<TriangleMesh> meshes = SmallMeshes();
  for (size_t i = 0; i < meshes.size(); ++i) {
    const std::string context = "small mesh " + std::to_string(i);
    DracoOptions exact = SessionOptions(meshes[i]);
    exact.shrink_small_meshes = false;
    const absl::StatusOr<std::string> bytes = EncodeMesh(meshes[i], SessionOptions(meshes[i]));
    ASSERT_TRUE(bytes.ok()) << context << ": " << bytes.status();
    other_than_given += *bytes != *EncodeMesh(meshes[i], exact) ? 1 : 0;
    const std::string in = TempPath("small.drc"), out = TempPath("small_by_reference.ply");
    io_test::WriteBytes(in, *bytes);
    ASSERT_EQ(RunTool(std::string(kDracoDecoder) + " -i " + in + " -o " + out), 0)
        << context << ": draco_decoder failed: " << io_test::ReadBytes(TempPath("draco_tool.log"));
    const absl::StatusOr<TriangleMesh> reference = ReadMesh(out);
    ASSERT_TRUE(reference.ok()) << context << ": " << reference.status();
    const absl::StatusOr<TriangleMesh> ours = DecodeMesh(*bytes);
    ASSERT_TRUE(ours.ok()) << context << ": " << ours.status();
    ExpectSameMesh(*ours, *reference, 0.0f, context + ": reference decoder vs. ours, exactly");
  }
  EXPECT_GT(other_than_given, 0) << "no stream used other settings than the given ones, so "
                                    "this test did not exercise them";
}

TEST(DracoInteropTest, ReferenceDecoderReadsOurPointCloud) {
  if (!HaveTool(kDracoDecoder)) GTEST_SKIP() << kDracoDecoder << " is not installed";
  const PointCloud cloud = io_test::RandomCloud(400, 13, true, false);
  const std::string in = TempPath("ours_cloud.drc"), out = TempPath("ours_cloud_by_ref.ply");
  ASSERT_TRUE(WritePointCloud(cloud, in).ok());
  ASSERT_EQ(RunTool(std::string(kDracoDecoder) + " -i " + in + " -o " + out), 0)
      << "draco_decoder failed: " << io_test::ReadBytes(TempPath("draco_tool.log"));
  const absl::StatusOr<PointCloud> reference = ReadPointCloud(out);
  ASSERT_TRUE(reference.ok()) << reference.status();
  ExpectSameCloud(cloud, *reference, QuantizationTolerance(2.0f, 11), 0.01f, 0,
                  "reference decoder output");
}

TEST(DracoInteropTest, WeDecodeReferenceEncoderOutput) {
  if (!HaveTool(kDracoEncoder)) GTEST_SKIP() << kDracoEncoder << " is not installed";
  const TriangleMesh mesh = testing::Icosphere(3, 4.0);
  for (const char* source : {"for_reference.ply", "for_reference.obj"}) {
    const std::string in = TempPath(source), out = TempPath("by_reference.drc");
    ASSERT_TRUE(WriteMesh(mesh, in).ok()) << "cannot write " << in;
    ASSERT_EQ(RunTool(std::string(kDracoEncoder) + " -i " + in + " -o " + out + " -qp 14"), 0)
        << "draco_encoder failed on " << source << ": "
        << io_test::ReadBytes(TempPath("draco_tool.log"));
    const absl::StatusOr<TriangleMesh> decoded = ReadMesh(out);
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    ExpectSameMesh(mesh, *decoded, QuantizationTolerance(8.0f, 14),
                   std::string("draco_encoder output from ") + source);
  }
}

TEST(DracoInteropTest, WeDecodeReferenceEncoderPointCloud) {
  if (!HaveTool(kDracoEncoder)) GTEST_SKIP() << kDracoEncoder << " is not installed";
  const PointCloud cloud = io_test::RandomCloud(300, 17, true, false);
  const std::string in = TempPath("cloud_for_reference.ply"), out = TempPath("cloud_by_ref.drc");
  ASSERT_TRUE(WritePointCloud(cloud, in).ok());
  ASSERT_EQ(RunTool(std::string(kDracoEncoder) + " -point_cloud -i " + in + " -o " + out), 0)
      << "draco_encoder failed: " << io_test::ReadBytes(TempPath("draco_tool.log"));
  const absl::StatusOr<PointCloud> decoded = ReadPointCloud(out);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  ExpectSameCloud(cloud, *decoded, QuantizationTolerance(2.0f, 11), 0.05f, 0,
                  "draco_encoder point cloud (8-bit normals)");
}

}  // namespace
}  // namespace neuralmesh
