// Vertex colours from coloured points (core/analysis/color_source.h) on a sphere whose points
// are coloured by position: indexing the points once, painting meshes of each size, and a
// stream of batches painted after every batch as a server session paints each mesh it
// publishes (GrowingPointColors). Prints the time per point and per vertex, and the worst and
// mean difference of a channel from the colour of each vertex's position.
//
//   build/bin/color-bench [--points=1000000] [--vertices=1000,10000,100000]
//                         [--batch=10000] [--stream_vertices=10000] [--seed=3]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/types/span.h"
#include "bench/bench_flags.h"
#include "bench/count_list.h"
#include "core/analysis/color_source.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/sample_points.h"

ABSL_FLAG(size_t, points, 1000000, "Coloured points sampled uniformly on the unit sphere.");
ABSL_FLAG(std::string, vertices, "1000,10000,100000",
          "Vertex counts of the meshes painted, comma-separated.");
ABSL_FLAG(size_t, batch, 10000, "Points per batch of the stream.");
ABSL_FLAG(size_t, stream_vertices, 10000, "Vertices of the mesh painted after every batch.");
ABSL_FLAG(uint64_t, seed, 3, "Seed of the sampling.");

namespace neuralmesh {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Rgb ColorOfPosition(const Vec3f& p) {
  Rgb color;
  for (int c = 0; c < 3; ++c) color[c] = ChannelFromFraction((p[c] + 1.0) / 2.0);
  return color;
}

// Vertices at points of the sphere other than the coloured ones (the faces do not matter).
TriangleMesh SphereVertices(const ImplicitSurface& sphere, size_t n, uint64_t seed) {
  TriangleMesh mesh;
  mesh.positions = SamplePoints(sphere, n, seed).positions;
  return mesh;
}

// "worst / mean" channel difference from the colours of the vertices' positions.
std::string ColorError(const TriangleMesh& mesh) {
  int worst = 0;
  double sum = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Rgb expected = ColorOfPosition(mesh.positions[v]);
    for (int c = 0; c < 3; ++c) {
      const int error = std::abs(int{mesh.colors[v][c]} - int{expected[c]});
      worst = std::max(worst, error);
      sum += error;
    }
  }
  char text[64];
  std::snprintf(text, sizeof(text), "%d / %.2f", worst,
                sum / (3.0 * static_cast<double>(mesh.positions.size())));
  return text;
}

int Run() {
  const size_t n = absl::GetFlag(FLAGS_points);
  const uint64_t seed = absl::GetFlag(FLAGS_seed);
  const std::vector<size_t> sizes =
      bench::ParseCountList(absl::GetFlag(FLAGS_vertices), "color-bench");
  const std::unique_ptr<ImplicitSurface> sphere = MakeSphere(Vec3(0, 0, 0), 1.0).value();
  PointCloud cloud = SamplePoints(*sphere, n, seed);
  for (const Vec3f& p : cloud.positions) cloud.colors.push_back(ColorOfPosition(p));

  std::printf("%zu coloured points on the unit sphere, 8 neighbours\n\n", n);
  std::printf("| what | s | us per point or vertex | channel error (worst / mean) |\n");
  std::printf("| --- | ---: | ---: | ---: |\n");
  auto start = std::chrono::steady_clock::now();
  const std::unique_ptr<ColorSource> source = MakePointColorSource(cloud).value();
  double seconds = SecondsSince(start);
  std::printf("| index %zu points | %.3f | %.3f | |\n", n, seconds,
              seconds * 1e6 / static_cast<double>(n));
  for (const size_t v : sizes) {
    TriangleMesh mesh = SphereVertices(*sphere, v, seed + 1);
    start = std::chrono::steady_clock::now();
    source->Paint(&mesh);
    seconds = SecondsSince(start);
    std::printf("| paint %zu vertices | %.3f | %.3f | %s |\n", v, seconds,
                seconds * 1e6 / static_cast<double>(v), ColorError(mesh).c_str());
  }

  const size_t batch = std::max<size_t>(1, absl::GetFlag(FLAGS_batch));
  TriangleMesh mesh = SphereVertices(*sphere, absl::GetFlag(FLAGS_stream_vertices), seed + 2);
  GrowingPointColors growing;
  double append_seconds = 0, paint_seconds = 0, slowest = 0;
  size_t paints = 0;
  for (size_t begin = 0; begin < n; begin += batch) {
    const size_t count = std::min(batch, n - begin);
    start = std::chrono::steady_clock::now();
    growing.Append(absl::MakeConstSpan(cloud.positions).subspan(begin, count),
                   absl::MakeConstSpan(cloud.colors).subspan(begin, count));
    append_seconds += SecondsSince(start);
    start = std::chrono::steady_clock::now();
    growing.Paint(&mesh);
    const double paint = SecondsSince(start);
    paint_seconds += paint;
    slowest = std::max(slowest, paint);
    ++paints;
  }
  std::printf("| stream: append %zu points in batches of %zu | %.3f | %.3f | |\n", n, batch,
              append_seconds, append_seconds * 1e6 / static_cast<double>(n));
  std::printf(
      "| stream: paint %zu vertices after each of %zu batches (slowest %.3f s) | %.3f | "
      "%.3f | %s |\n",
      mesh.positions.size(), paints, slowest, paint_seconds,
      paint_seconds * 1e6 / static_cast<double>(paints * mesh.positions.size()),
      ColorError(mesh).c_str());
  return 0;
}

}  // namespace
}  // namespace neuralmesh

int main(int argc, char** argv) {
  neuralmesh::ParseBenchFlags(argc, argv,
                              "Vertex colours from coloured points: indexing, painting, and a "
                              "stream painted after every batch.\n"
                              "  color-bench [--points=N] [--vertices=N1,N2,...] [--batch=N] "
                              "[--stream_vertices=N] [--seed=S]");
  return neuralmesh::Run();
}
