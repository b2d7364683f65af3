// Statistical outlier removal on a clean sphere: the whole cloud at once
// (statistical_outliers.h, one thread and every hardware thread), and the same points streamed
// in batches of each size (streaming_outlier_filter.h, one thread, as a server session runs
// it), in random order and swept along x, as a scanner sends a surface region by region.
// Prints the time per point, the share of points dropped and how many of the points held back
// on arrival were accepted later; on clean data the dropped points are the sparsest spots, and
// the streamed filter should drop about as many as the whole-cloud one in either order.
//
//   build/bin/outlier-bench [--points=1000000] [--batches=1000,10000,100000] [--seed=3]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/types/span.h"
#include "bench/bench_flags.h"
#include "bench/count_list.h"
#include "core/analysis/statistical_outliers.h"
#include "core/analysis/streaming_outlier_filter.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/sample_points.h"

ABSL_FLAG(size_t, points, 1000000, "Points sampled uniformly on the unit sphere.");
ABSL_FLAG(std::string, batches, "1000,10000,100000",
          "Batch sizes the points are streamed in, comma-separated.");
ABSL_FLAG(uint64_t, seed, 3, "Seed of the sampling.");

namespace neuralmesh {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

size_t CountTrue(const std::vector<bool>& flags) {
  return static_cast<size_t>(std::count(flags.begin(), flags.end(), true));
}

void PrintRow(const std::string& how, size_t points, double seconds, size_t dropped,
              const std::string& released) {
  std::printf("| %s | %.2f | %.2f | %zu | %.3f%% | %s |\n", how.c_str(), seconds,
              seconds * 1e6 / static_cast<double>(points), dropped,
              100.0 * static_cast<double>(dropped) / static_cast<double>(points), released.c_str());
}

// Streams `positions` through a filter in batches of `batch_size`, ending the stream.
void StreamRow(const std::vector<Vec3f>& positions, size_t batch_size, const std::string& order) {
  const size_t n = positions.size();
  StreamingOutlierFilter filter(OutlierOptions{});
  size_t dropped = 0;
  size_t released = 0;
  const auto start = std::chrono::steady_clock::now();
  for (size_t begin = 0; begin < n; begin += batch_size) {
    const auto batch =
        absl::MakeConstSpan(positions).subspan(begin, std::min(batch_size, n - begin));
    OutlierJudgement judgement = filter.Judge(batch);
    dropped += judgement.dropped.size();
    released += judgement.released.size();
    filter.Add(batch, std::move(judgement));
  }
  dropped += filter.DropHeld().size();
  PrintRow(order + " in batches of " + std::to_string(batch_size), n, SecondsSince(start), dropped,
           std::to_string(released));
}

int Run() {
  const size_t n = absl::GetFlag(FLAGS_points);
  const std::vector<size_t> batch_sizes =
      bench::ParseCountList(absl::GetFlag(FLAGS_batches), "outlier-bench");
  auto sphere = MakeSphere(Vec3(0, 0, 0), 1.0);
  if (!sphere.ok() || n == 0) {
    std::fprintf(stderr, "outlier-bench: --points must be positive\n");
    return 2;
  }
  const PointCloud cloud = SamplePoints(**sphere, n, absl::GetFlag(FLAGS_seed));
  std::printf("%zu points on the unit sphere, 16 neighbours, 3 standard deviations\n\n", n);
  std::printf(
      "| filter | s | us/point | dropped | share | held, then accepted |\n"
      "| --- | ---: | ---: | ---: | ---: | ---: |\n");
  for (const int threads : {1, 0}) {
    OutlierOptions options;
    options.threads = threads;
    const auto start = std::chrono::steady_clock::now();
    const auto outliers = FindStatisticalOutliers(cloud, options);
    const double seconds = SecondsSince(start);
    if (!outliers.ok()) {
      std::fprintf(stderr, "outlier-bench: %s\n", std::string(outliers.status().message()).c_str());
      return 1;
    }
    const unsigned used = threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
    PrintRow("whole cloud, " + std::to_string(used) + (used == 1 ? " thread" : " threads"), n,
             seconds, CountTrue(*outliers), "-");
  }
  std::vector<Vec3f> swept = cloud.positions;
  std::sort(swept.begin(), swept.end(), [](const Vec3f& a, const Vec3f& b) { return a[0] < b[0]; });
  for (const size_t batch_size : batch_sizes) {
    StreamRow(cloud.positions, batch_size, "random order");
    StreamRow(swept, batch_size, "swept along x");
  }
  return 0;
}

}  // namespace
}  // namespace neuralmesh

int main(int argc, char** argv) {
  neuralmesh::ParseBenchFlags(argc, argv,
                              "Statistical outlier removal, whole-cloud and streamed (random and "
                              "swept), on a clean sphere.\n"
                              "  outlier-bench [--points=N] [--batches=N1,N2,...] [--seed=S]");
  return neuralmesh::Run();
}
