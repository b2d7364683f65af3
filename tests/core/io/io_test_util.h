// Helpers for the file I/O and Draco tests: temporary files, and geometry comparisons that do
// not depend on vertex or face order (Draco reorders both).
#ifndef NEURALMESH_TESTS_CORE_IO_IO_TEST_UTIL_H_
#define NEURALMESH_TESTS_CORE_IO_IO_TEST_UTIL_H_

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "core/io/internal/binary.h"
#include "core/io/point_cloud_io.h"
#include "core/point_cloud.h"
#include "core/random.h"
#include "core/triangle_mesh.h"
#include "gtest/gtest.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh::io_test {

// Appends `value` in the given byte order, for hand-built binary files.
template <typename T>
void Put(T value, bool big_endian, std::string* out) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const bool host_big = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;
  if (big_endian != host_big) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

// What a shell command printed on its standard output, and its exit status; for the independent
// readers of tests/tools (the tests run from the repository's root).
struct CommandResult {
  int status = -1;
  std::string output;
};

inline CommandResult RunCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[65536];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) result.output.append(buffer, n);
  result.status = pclose(pipe);
  return result;
}

// The little-endian T at `offset` of a binary file's bytes.
template <typename T>
T Field(const std::string& bytes, size_t offset) {
  return io_internal::LoadScalar<T>(bytes.data() + offset, /*big_endian=*/false);
}

// A path in this test process's temporary directory (tests/testing/temp_dir.h), prefixed with
// the running test's name.
inline std::string TempPath(const std::string& name) {
  const std::string dir = neuralmesh::testing::ProcessTempDir() + "/";
  std::string prefix;
  if (const auto* test = ::testing::UnitTest::GetInstance()->current_test_info()) {
    prefix += std::string(test->test_suite_name()) + "." + test->name() + "_";
  }
  std::replace(prefix.begin(), prefix.end(), '/', '_');
  return dir + prefix + name;
}

// Writes raw bytes (text or binary) to `path`, failing the test if that is impossible.
inline void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  ASSERT_TRUE(out.good()) << "cannot create test file " << path;
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << "cannot write test file " << path;
}

// Writes `bytes` to a temporary file `name` and reads it back as a point cloud.
inline absl::StatusOr<PointCloud> ReadCloudFrom(const std::string& name, const std::string& bytes,
                                                PointsLeftOut* left_out = nullptr) {
  const std::string path = TempPath(name);
  WriteBytes(path, bytes);
  return ReadPointCloud(path, left_out);
}

inline std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Half a quantization step of a cube with edge `range` at `bits` bits, plus float slack: the
// largest per-coordinate error of a Draco round trip.
inline float QuantizationTolerance(float range, int bits) {
  return range / static_cast<float>((1u << bits) - 1) * 0.5f * 1.001f + 1e-6f;
}

// The largest side of the bounding box of `points`: the cube Draco quantizes against.
inline float BoundingCubeRange(const std::vector<Vec3f>& points) {
  Vec3f lo = points.front(), hi = points.front();
  for (const Vec3f& p : points) {
    lo.minimize(p);
    hi.maximize(p);
  }
  return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

// For each point of `actual`, the index of the point of `expected` within `tolerance` (max
// norm), or -1 when there is none. Expected points must be farther apart than 2 * tolerance.
inline std::vector<int> MatchPoints(const std::vector<Vec3f>& expected,
                                    const std::vector<Vec3f>& actual, float tolerance) {
  std::vector<int> by_x(expected.size());
  for (size_t i = 0; i < expected.size(); ++i) by_x[i] = static_cast<int>(i);
  std::sort(by_x.begin(), by_x.end(),
            [&](int a, int b) { return expected[a][0] < expected[b][0]; });
  std::vector<int> match(actual.size(), -1);
  for (size_t i = 0; i < actual.size(); ++i) {
    const Vec3f& p = actual[i];
    auto it = std::lower_bound(by_x.begin(), by_x.end(), p[0] - tolerance,
                               [&](int e, float x) { return expected[e][0] < x; });
    for (; it != by_x.end() && expected[*it][0] <= p[0] + tolerance; ++it) {
      const Vec3f d = expected[*it] - p;
      if (std::abs(d[0]) <= tolerance && std::abs(d[1]) <= tolerance &&
          std::abs(d[2]) <= tolerance) {
        match[i] = *it;
        break;
      }
    }
  }
  return match;
}

// A face as a rotation-normalized triple (smallest index first), so that orientation counts
// but the starting corner does not.
inline std::array<int, 3> CanonicalFace(int a, int b, int c) {
  if (b < a && b < c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

// Expects `actual` to be `expected` up to vertex and face order, with positions within
// `tolerance` per coordinate: every actual vertex matches an expected one, every expected vertex
// is matched, and the oriented faces, mapped to expected vertices, are the same multiset.
inline void ExpectSameMesh(const TriangleMesh& expected, const TriangleMesh& actual,
                           float tolerance, const std::string& context) {
  SCOPED_TRACE(context);
  const std::vector<int> match = MatchPoints(expected.positions, actual.positions, tolerance);
  std::vector<bool> hit(expected.positions.size(), false);
  int unmatched = 0;
  for (size_t i = 0; i < match.size(); ++i) {
    if (match[i] < 0) {
      if (++unmatched <= 3) {
        ADD_FAILURE() << "decoded vertex " << i << " (" << actual.positions[i] << ") is not within "
                      << tolerance << " of any input vertex";
      }
    } else {
      hit[match[i]] = true;
    }
  }
  EXPECT_EQ(unmatched, 0) << "vertices with no input counterpart";
  EXPECT_EQ(std::count(hit.begin(), hit.end(), false), 0)
      << "input vertices missing from the result";
  if (unmatched > 0) return;
  std::map<std::array<int, 3>, int> faces;
  for (const auto& f : expected.faces) ++faces[CanonicalFace(f[0], f[1], f[2])];
  for (const auto& f : actual.faces) {
    --faces[CanonicalFace(match[f[0]], match[f[1]], match[f[2]])];
  }
  int differing = 0;
  for (const auto& [face, count] : faces) {
    if (count != 0 && ++differing <= 3) {
      ADD_FAILURE() << "face (" << face[0] << ", " << face[1] << ", " << face[2] << ") occurs "
                    << (count > 0 ? "fewer" : "more") << " times in the result than in the "
                    << "input (difference " << count << ")";
    }
  }
  EXPECT_EQ(differing, 0) << "oriented face sets differ";
}

// Expects `actual` to be `expected` up to point order: positions within `tolerance`, normals
// within `normal_tolerance`, weights within `weight_tolerance`.
inline void ExpectSameCloud(const PointCloud& expected, const PointCloud& actual, float tolerance,
                            float normal_tolerance, float weight_tolerance,
                            const std::string& context) {
  SCOPED_TRACE(context);
  ASSERT_EQ(actual.size(), expected.size()) << "point count changed";
  ASSERT_EQ(actual.normals.size(), expected.normals.size()) << "normals lost or invented";
  ASSERT_EQ(actual.weights.size(), expected.weights.size()) << "weights lost or invented";
  const std::vector<int> match = MatchPoints(expected.positions, actual.positions, tolerance);
  std::vector<bool> hit(expected.size(), false);
  int failures = 0;
  for (size_t i = 0; i < match.size() && failures < 5; ++i) {
    if (match[i] < 0) {
      ADD_FAILURE() << "point " << i << " (" << actual.positions[i] << ") is not within "
                    << tolerance << " of any input point";
      ++failures;
      continue;
    }
    EXPECT_FALSE(hit[match[i]]) << "two points matched input point " << match[i];
    hit[match[i]] = true;
    if (!expected.normals.empty()) {
      const Vec3f d = actual.normals[i] - expected.normals[match[i]];
      if (d.max_abs() > normal_tolerance) {
        ADD_FAILURE() << "normal of point " << i << " is " << actual.normals[i] << ", expected "
                      << expected.normals[match[i]];
        ++failures;
      }
    }
    if (!expected.weights.empty() &&
        std::abs(actual.weights[i] - expected.weights[match[i]]) > weight_tolerance) {
      ADD_FAILURE() << "weight of point " << i << " is " << actual.weights[i] << ", expected "
                    << expected.weights[match[i]];
      ++failures;
    }
  }
  EXPECT_EQ(failures, 0) << "points differ";
}

// Uniform random points in [-1, 1]^3 with unit normals and weights in [0.5, 2), from `seed`.
inline PointCloud RandomCloud(int n, uint64_t seed, bool normals, bool weights) {
  Random random(seed);
  auto uniform = [&] { return static_cast<float>(2 * random.NextDouble() - 1); };
  PointCloud cloud;
  for (int i = 0; i < n; ++i) {
    cloud.positions.emplace_back(uniform(), uniform(), uniform());
    if (normals) {
      Vec3f v(uniform(), uniform(), uniform() + 2.5f);
      cloud.normals.push_back(v.normalized());
    }
    if (weights) cloud.weights.push_back(0.5f + 1.5f * static_cast<float>(random.NextDouble()));
  }
  return cloud;
}

}  // namespace neuralmesh::io_test

#endif  // NEURALMESH_TESTS_CORE_IO_IO_TEST_UTIL_H_
