// LAZ (core/io/internal/laz.h): compressing and decompressing a LAS file whose records look
// like an airborne scan (tests/testing/las_scan.h: flight lines, first and last returns, GPS
// times, colours; formats 6-8 in LASzip's layers, from one or several scanner channels).
// Prints the sizes, the LAZ file's share of the LAS file's, and the best time of --repeats runs
// each way, in records per second and MB of LAS per second; checks that the records come back
// byte for byte.
//
//   build/bin/laz-bench [--records=2000000] [--format=3] [--scanner_channels=1]
//                       [--chunk_size=50000] [--threads=1] [--repeats=3]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "absl/flags/flag.h"
#include "bench/bench_flags.h"
#include "core/io/internal/laz.h"
#include "tests/testing/las_scan.h"

ABSL_FLAG(size_t, records, 2000000, "Point records of the scan.");
ABSL_FLAG(int, format, 3, "LAS point format, 0 to 3 or 6 to 8.");
ABSL_FLAG(int, scanner_channels, 1, "Formats 6-8: scanner channels taking turns, 1 to 4.");
ABSL_FLAG(uint32_t, chunk_size, 50000, "Records per LAZ chunk.");
ABSL_FLAG(int, repeats, 3, "Runs of each direction; the fastest is printed.");
ABSL_FLAG(int, threads, 1, "Threads coding chunks; 0 for one per hardware thread.");

namespace neuralmesh {
namespace {

template <typename Function>
double BestSeconds(int repeats, Function function) {
  double best = 1e30;
  for (int i = 0; i < repeats; ++i) {
    const auto start = std::chrono::steady_clock::now();
    function();
    best = std::min(
        best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

int Run() {
  testing::LasScan scan;
  scan.format = absl::GetFlag(FLAGS_format);
  scan.records = absl::GetFlag(FLAGS_records);
  scan.scanner_channels = absl::GetFlag(FLAGS_scanner_channels);
  if (scan.format < 0 || scan.format > 8 || scan.format == 4 || scan.format == 5) {
    std::fprintf(stderr, "--format must be 0 to 3 or 6 to 8\n");
    return 1;
  }
  if (scan.scanner_channels < 1 || scan.scanner_channels > 4) {
    std::fprintf(stderr, "--scanner_channels must be 1 to 4\n");
    return 1;
  }
  const std::string las = testing::ScanLasFile(scan);
  const int repeats = std::max(1, absl::GetFlag(FLAGS_repeats));
  absl::StatusOr<std::string> laz;
  const double compress = BestSeconds(repeats, [&] {
    io_internal::LazWriteOptions options;
    options.chunk_size = absl::GetFlag(FLAGS_chunk_size);
    options.threads = absl::GetFlag(FLAGS_threads);
    laz = io_internal::CompressLas(las, options);
  });
  if (!laz.ok()) {
    std::fprintf(stderr, "compressing failed: %s\n", laz.status().ToString().c_str());
    return 1;
  }
  absl::StatusOr<std::string> back;
  const double decompress = BestSeconds(
      repeats, [&] { back = io_internal::DecompressLaz(*laz, {absl::GetFlag(FLAGS_threads)}); });
  if (!back.ok() || *back != las) {
    std::fprintf(stderr, "the records did not come back: %s\n",
                 back.ok() ? "different bytes" : back.status().ToString().c_str());
    return 1;
  }
  const double mb = las.size() / 1e6;
  std::printf("%zu records of format %d: LAS %.1f MB, LAZ %.1f MB (%.3f of it)\n", scan.records,
              scan.format, mb, laz->size() / 1e6, static_cast<double>(laz->size()) / las.size());
  std::printf("compress:   %.3f s, %.2f M records/s, %.0f MB/s of LAS\n", compress,
              scan.records / compress / 1e6, mb / compress);
  std::printf("decompress: %.3f s, %.2f M records/s, %.0f MB/s of LAS\n", decompress,
              scan.records / decompress / 1e6, mb / decompress);
  return 0;
}

}  // namespace
}  // namespace neuralmesh

int main(int argc, char** argv) {
  neuralmesh::ParseBenchFlags(argc, argv,
                              "Times LAZ compression and decompression of a scan-like LAS "
                              "file.\nUsage: laz-bench [flags]");
  return neuralmesh::Run();
}
