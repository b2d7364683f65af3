#include "tests/testing/shapes.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <utility>

#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/sample_points.h"
#include "gtest/gtest.h"

namespace neuralmesh::testing {
namespace {

// The two triangles (a, b, c) and (a, c, d) of the quad with corners a, b, c, d in order.
void AddQuad(TriangleMesh& m, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  m.faces.push_back({a, b, c});
  m.faces.push_back({a, c, d});
}

}  // namespace

TriangleMesh Icosphere(int levels, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh m;
  const double raw[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                             {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                             {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (const auto& p : raw) m.positions.push_back(Vec3f(p[0], p[1], p[2]).normalized());
  m.faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
             {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoint;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      const uint32_t index = static_cast<uint32_t>(m.positions.size());
      m.positions.push_back(((m.positions[a] + m.positions[b]) * 0.5f).normalized());
      midpoint.emplace(key, index);
      return index;
    };
    std::vector<std::array<uint32_t, 3>> faces;
    for (const auto& f : m.faces) {
      const uint32_t ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      faces.push_back({f[0], ab, ca});
      faces.push_back({f[1], bc, ab});
      faces.push_back({f[2], ca, bc});
      faces.push_back({ab, bc, ca});
    }
    m.faces = std::move(faces);
  }
  for (Vec3f& p : m.positions) p *= static_cast<float>(radius);
  return m;
}

PointCloud UnitSpherePointsAndAStray(size_t n, uint64_t seed, const Vec3f& stray) {
  PointCloud cloud = SamplePoints(*MakeSphere(Vec3(0, 0, 0), 1.0).value(), n, seed);
  cloud.positions.push_back(stray);
  return cloud;
}

Rgb ColorOfPosition(const Vec3f& p) {
  Rgb color;
  for (int c = 0; c < 3; ++c) color[c] = ChannelFromFraction((p[c] + 1.0) / 2.0);
  return color;
}

TriangleMesh ColoredIcosphere(int levels) {
  TriangleMesh mesh = Icosphere(levels);
  for (const Vec3f& p : mesh.positions) mesh.colors.push_back(ColorOfPosition(p));
  return mesh;
}

PointCloud ColoredUnitSpherePoints(size_t n, uint64_t seed) {
  PointCloud cloud = SamplePoints(*MakeSphere(Vec3(0, 0, 0), 1.0).value(), n, seed);
  for (const Vec3f& p : cloud.positions) cloud.colors.push_back(ColorOfPosition(p));
  return cloud;
}

int ColorError(const Rgb& color, const Vec3f& p) {
  const Rgb expected = ColorOfPosition(p);
  int error = 0;
  for (int c = 0; c < 3; ++c) error = std::max(error, std::abs(int{color[c]} - int{expected[c]}));
  return error;
}

int WorstColorErrorOnTheUnitSphere(const TriangleMesh& mesh) {
  if (mesh.colors.empty()) return -1;
  EXPECT_EQ(mesh.colors.size(), mesh.positions.size());
  int worst = 0;
  for (size_t v = 0; v < mesh.colors.size(); ++v) {
    worst = std::max(worst, ColorError(mesh.colors[v], mesh.positions[v].normalized()));
  }
  return worst;
}

TriangleMesh GridPatch(int nx, int ny) {
  TriangleMesh m;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      m.positions.emplace_back(static_cast<float>(i) / nx, static_cast<float>(j) / ny, 0.f);
    }
  }
  auto id = [&](int i, int j) { return static_cast<uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) AddQuad(m, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
  }
  return m;
}

TriangleMesh TorusGrid(int along, int around, double major, double minor) {
  TriangleMesh m;
  for (int i = 0; i < along; ++i) {
    const double u = 2 * M_PI * i / along;
    for (int j = 0; j < around; ++j) {
      const double v = 2 * M_PI * j / around;
      const double r = major + minor * std::cos(v);
      m.positions.emplace_back(static_cast<float>(r * std::cos(u)),
                               static_cast<float>(r * std::sin(u)),
                               static_cast<float>(minor * std::sin(v)));
    }
  }
  auto id = [&](int i, int j) {
    return static_cast<uint32_t>((i % along) * around + (j % around));
  };
  for (int i = 0; i < along; ++i) {
    for (int j = 0; j < around; ++j) {
      AddQuad(m, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
    }
  }
  return m;
}

TriangleMesh TorusWithBridgedHoles(int along, int around, double major, double minor) {
  const TriangleMesh torus = TorusGrid(along, around, major, minor);
  TriangleMesh m;
  m.positions = torus.positions;
  // TorusGrid adds the two faces of the quad (ring 0, angle j) as faces 2j and 2j + 1.
  for (size_t f = 0; f < torus.faces.size(); ++f) {
    if (f < 2 * static_cast<size_t>(around) && f >= 4) continue;  // The cut, but quads 0, 1.
    m.faces.push_back(torus.faces[f]);
  }
  auto ring0 = [](int j) { return static_cast<uint32_t>(j); };
  auto ring1 = [around](int j) { return static_cast<uint32_t>(around + j % around); };
  // Ring 0's side of the cut carries half-edges j -> j + 1 and ring 1's j + 1 -> j, so the band
  // runs along them reversed.
  m.faces.push_back({ring0(3), ring0(2), ring1(around - 1)});
  m.faces.push_back({ring0(3), ring1(around - 1), ring1(0)});
  return m;
}

std::vector<size_t> BoundaryLoopSizes(const Mesh& mesh) {
  std::vector<size_t> sizes;
  std::vector<bool> seen(mesh.n_halfedges(), false);
  for (auto start : mesh.halfedges()) {
    if (seen[start.idx()] || !mesh.is_boundary(start)) continue;
    size_t n = 0;
    auto h = start;
    do {  // Bounded, so that a broken mesh fails the test instead of hanging it.
      seen[h.idx()] = true;
      ++n;
      h = mesh.next_halfedge_handle(h);
    } while (h != start && n <= mesh.n_halfedges());
    sizes.push_back(n);
  }
  std::sort(sizes.begin(), sizes.end());
  return sizes;
}

Mesh MustToMesh(const TriangleMesh& triangles) {
  auto mesh = ToMesh(triangles);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  return mesh.ok() ? std::move(mesh).value() : Mesh();
}

}  // namespace neuralmesh::testing
