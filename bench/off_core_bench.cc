// Off-core sampling (core/sampling/off_core_sampler.h, `neuralmesh reconstruct --off_core`)
// against reading the file whole: a LAS file (or with --format=ply a binary PLY file of
// doubles) of --points points of a torus (radius 10 m and 4 m, in UTM coordinates) is written,
// then learned to --vertices vertices both ways, with the
// paper's parameters on one thread. Prints for each way the time until learning starts (the
// file opened, or read and its sampler built), until the first coarse mesh (1,000 vertices)
// and until the last, and the memory the process holds then: anonymous (its own allocations:
// the points read whole) and file-backed (the pages of the mapped file that were touched).
// The file is in the page cache when both start (it has just been written), or with --cold
// dropped from it before each (posix_fadvise DONTNEED), as a file read from the disk.
//
//   build/bin/off-core-bench [--points=20000000] [--vertices=20000] [--format=las|ply]
//                            [--cold] [--file=PATH] [--keep] [--write_only]
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "absl/flags/flag.h"
#include "bench/bench_flags.h"
#include "core/io/point_cloud_io.h"
#include "core/learning/learner.h"
#include "core/random.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/off_core_sampler.h"
#include "core/sampling/point_cloud_sampler.h"

ABSL_FLAG(size_t, points, 20000000, "Points of the LAS file.");
ABSL_FLAG(size_t, vertices, 20000, "Vertices to learn each way.");
ABSL_FLAG(std::string, format, "las", "The file's format: las or ply.");
ABSL_FLAG(std::string, file, "", "Where the file is written; /tmp/off-core-bench.FORMAT if empty.");
ABSL_FLAG(bool, keep, false, "Keep the LAS file afterwards.");
ABSL_FLAG(bool, cold, false, "Drop the file from the page cache before each way.");
ABSL_FLAG(bool, write_only, false,
          "Write the file and stop (scripts/upload-bench.sh uploads it to a server).");

namespace neuralmesh {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Drops the file at `path` from the page cache, when --cold says so.
void MaybeDropFromPageCache(const std::string& path) {
  if (!absl::GetFlag(FLAGS_cold)) return;
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fdatasync(fd);
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
  ::close(fd);
}

// A field of /proc/self/status in MB ("RssAnon", "RssFile"), or -1.
double StatusMegabytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1)) / 1024;
  }
  return -1;
}

// Learns `target` to 1,000 and then `vertices` vertices, and prints a row: `opened` is the
// time it took to get `target` ready.
bool LearnAndPrint(const char* way, const Sampler& target, double opened, size_t vertices,
                   Clock::time_point start) {
  absl::StatusOr<std::unique_ptr<Learner>> learner = Learner::Create(LearnerOptions{}, &target);
  if (!learner.ok()) {
    std::fprintf(stderr, "%s\n", learner.status().ToString().c_str());
    return false;
  }
  double coarse = 0;
  for (size_t target_vertices : {size_t{1000}, vertices}) {
    StopCriteria stop;
    stop.target_vertices = target_vertices;
    absl::StatusOr<StopReason> reason = (*learner)->Run(stop);
    if (!reason.ok()) {
      std::fprintf(stderr, "%s\n", reason.status().ToString().c_str());
      return false;
    }
    if (target_vertices == 1000) coarse = SecondsSince(start);
  }
  std::printf("%-12s %10.2f %12.2f %12.2f %14.0f %14.0f\n", way, opened, coarse,
              SecondsSince(start), StatusMegabytes("RssAnon"), StatusMegabytes("RssFile"));
  return true;
}

int Run() {
  const size_t n = absl::GetFlag(FLAGS_points);
  const size_t vertices = absl::GetFlag(FLAGS_vertices);
  const std::string format = absl::GetFlag(FLAGS_format);
  const std::string path = absl::GetFlag(FLAGS_file).empty() ? "/tmp/off-core-bench." + format
                                                             : absl::GetFlag(FLAGS_file);
  if (n < 1000 || vertices <= 1000 || (format != "las" && format != "ply")) {
    std::fprintf(stderr,
                 "--points must be at least 1000, --vertices above 1000, --format las or ply\n");
    return 1;
  }
  {
    std::unique_ptr<ImplicitSurface> torus = MakeTorus(Vec3(0, 0, 0), 10, 4).value();
    PointCloud cloud;
    cloud.origin = {500000, 4100000, 0};
    cloud.positions.reserve(n);
    Random rng(1);
    for (size_t i = 0; i < n; ++i) {
      const Vec3 p = torus->Sample(rng) + Vec3(123, 456, 80);
      cloud.positions.emplace_back(p[0], p[1], p[2]);
    }
    const absl::Status written = WritePointCloud(cloud, path);
    if (!written.ok()) {
      std::fprintf(stderr, "%s\n", written.ToString().c_str());
      return 1;
    }
  }
  if (absl::GetFlag(FLAGS_write_only)) {
    std::printf("%zu points of a torus in %s (%.0f MB)\n", n, path.c_str(),
                static_cast<double>(std::filesystem::file_size(path)) / 1e6);
    return 0;
  }
  std::printf(
      "%zu points of a torus in %s (%.0f MB), learned to %zu vertices; memory held "
      "at the end, RssAnon %.0f MB before either\n\n",
      n, path.c_str(), static_cast<double>(std::filesystem::file_size(path)) / 1e6, vertices,
      StatusMegabytes("RssAnon"));
  std::printf("%-12s %10s %12s %12s %14s %14s\n", "way", "ready s", "1K vertices s", "last s",
              "anonymous MB", "file MB");

  bool ok = true;
  {
    MaybeDropFromPageCache(path);
    const Clock::time_point start = Clock::now();
    absl::StatusOr<std::unique_ptr<OffCoreSampler>> sampler = OffCoreSampler::Open(path);
    if (!sampler.ok()) {
      std::fprintf(stderr, "%s\n", sampler.status().ToString().c_str());
      return 1;
    }
    ok = LearnAndPrint("off-core", **sampler, SecondsSince(start), vertices, start);
  }
  if (ok) {
    MaybeDropFromPageCache(path);
    const Clock::time_point start = Clock::now();
    absl::StatusOr<PointCloud> cloud = ReadPointCloud(path);
    if (!cloud.ok()) {
      std::fprintf(stderr, "%s\n", cloud.status().ToString().c_str());
      return 1;
    }
    absl::StatusOr<std::unique_ptr<Sampler>> sampler =
        UniformPointCloudSampler::Create(std::make_shared<const PointCloud>(*std::move(cloud)));
    if (!sampler.ok()) {
      std::fprintf(stderr, "%s\n", sampler.status().ToString().c_str());
      return 1;
    }
    ok = LearnAndPrint("read whole", **sampler, SecondsSince(start), vertices, start);
  }
  if (!absl::GetFlag(FLAGS_keep)) std::remove(path.c_str());
  return ok ? 0 : 1;
}

}  // namespace
}  // namespace neuralmesh

int main(int argc, char** argv) {
  neuralmesh::ParseBenchFlags(
      argc, argv,
      "Off-core sampling of a LAS or PLY file against reading it whole.\n"
      "  build/bin/off-core-bench [--points=20000000] [--vertices=20000] [--format=las|ply]\n"
      "                           [--cold] [--file=PATH] [--keep] [--write_only]");
  return neuralmesh::Run();
}
