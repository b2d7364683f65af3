// VertexOctree benchmark: the learner's access pattern on N points of a torus surface. Each
// iteration is one Basic Step's worth of octree work: Nearest for a fresh random point of the
// surface, then Move of 7 random points by a tiny random offset (about 1% of the mean
// spacing). Prints CPU ns per iteration (query + moves) and per query alone, the median over
// --repeats runs; it is not a test.
//
//   build/bin/octree-bench [--sizes=1000,20000,100000] [--iterations=200000] [--repeats=5]
//                          [--bucket_size=0] [--seed=1]
//
// Queries, ids and offsets are drawn before the clock starts, so the numbers are the octree's
// alone. The first run of each size checks some answers against brute force.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "bench/bench_flags.h"
#include "bench/count_list.h"
#include "core/bounding_box.h"
#include "core/learning/vertex_octree.h"
#include "core/random.h"
#include "core/sampling/implicit_surfaces.h"

ABSL_FLAG(std::string, sizes, "1000,20000,100000", "Point counts.");
ABSL_FLAG(int, iterations, 200000, "Iterations (one query and 7 moves each) per run.");
ABSL_FLAG(int, repeats, 5, "Runs per size; the median is printed.");
ABSL_FLAG(int, bucket_size, 0, "Leaf capacity; 0 uses VertexOctree's default.");
ABSL_FLAG(uint64_t, seed, 1, "Seed of the points and of the operations.");

namespace neuralmesh {
namespace {

constexpr int kMovesPerStep = 7;

// CPU time of this thread: the machine is shared, and wall time would count the time other
// processes hold the core.
double ThreadCpuNs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e9 * static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The operations of one run, drawn in advance.
struct Workload {
  BoundingBox bounds;
  std::vector<Vec3> points;   // Initial positions.
  std::vector<Vec3> queries;  // One per iteration.
  std::vector<int> moved;     // kMovesPerStep per iteration.
  std::vector<Vec3> offsets;  // Likewise.
};

Workload MakeWorkload(const ImplicitSurface& surface, size_t n, int iterations, uint64_t seed) {
  Workload w;
  w.bounds = surface.Bounds();
  Random rng(seed);
  w.points.reserve(n);
  for (size_t i = 0; i < n; ++i) w.points.push_back(surface.Sample(rng));
  const double spacing = std::sqrt(surface.Area() / static_cast<double>(n));
  const double step = 0.01 * spacing;
  for (int it = 0; it < iterations; ++it) {
    w.queries.push_back(surface.Sample(rng));
    for (int k = 0; k < kMovesPerStep; ++k) {
      w.moved.push_back(static_cast<int>(rng.NextIndex(n)));
      w.offsets.push_back(
          Vec3(rng.NextDouble() - 0.5, rng.NextDouble() - 0.5, rng.NextDouble() - 0.5) *
          (2 * step));
    }
  }
  return w;
}

struct RunResult {
  double ns_per_step = 0;   // Query + moves.
  double ns_per_query = 0;  // Query alone.
  int depth = 0;
};

RunResult RunOnce(const Workload& w, int bucket_size, bool verify) {
  std::vector<Vec3> pos = w.points;
  VertexOctree tree = bucket_size > 0 ? VertexOctree(w.bounds, &pos, bucket_size)
                                      : VertexOctree(w.bounds, &pos);
  for (size_t i = 0; i < pos.size(); ++i) tree.Insert(static_cast<int>(i));
  const size_t iterations = w.queries.size();
  RunResult r;
  // Query + moves, as in the learner.
  double start = ThreadCpuNs();
  for (size_t it = 0; it < iterations; ++it) {
    tree.Nearest(w.queries[it]);
    for (int k = 0; k < kMovesPerStep; ++k) {
      const size_t j = it * kMovesPerStep + k;
      const int id = w.moved[j];
      pos[id] += w.offsets[j];
      tree.Move(id);
    }
  }
  r.ns_per_step = (ThreadCpuNs() - start) / iterations;
  // Queries alone (the points stay where the moves left them).
  start = ThreadCpuNs();
  for (size_t it = 0; it < iterations; ++it) tree.Nearest(w.queries[it]);
  r.ns_per_query = (ThreadCpuNs() - start) / iterations;
  r.depth = tree.Depth();
  if (verify) {
    for (size_t it = 0; it < iterations; it += 997) {
      const Vec3& q = w.queries[it];
      double best = std::numeric_limits<double>::infinity();
      for (const Vec3& p : pos) best = std::min(best, (p - q).sqrnorm());
      const int got = tree.Nearest(q);
      if (got < 0 || (pos[got] - q).sqrnorm() > best * (1 + 1e-12)) {
        std::fprintf(stderr, "octree-bench: wrong answer for query %zu\n", it);
        std::exit(1);
      }
    }
  }
  return r;
}

int Run() {
  const std::vector<size_t> sizes =
      bench::ParseCountList(absl::GetFlag(FLAGS_sizes), "octree-bench");
  const int iterations = std::max(1, absl::GetFlag(FLAGS_iterations));
  const int repeats = std::max(1, absl::GetFlag(FLAGS_repeats));
  const int bucket_size = absl::GetFlag(FLAGS_bucket_size);
  const uint64_t seed = absl::GetFlag(FLAGS_seed);
  // The learner benchmark's surface: a torus with R = 1, r = 0.35.
  auto torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.35).value();

  std::printf(
      "VertexOctree on a torus (R = 1, r = 0.35): a step is 1 Nearest + %d Moves of ~1%% of the "
      "spacing; CPU ns, median of %d runs of %d steps\n\n",
      kMovesPerStep, repeats, iterations);
  std::printf("%8s %12s %12s %6s\n", "points", "ns/step", "ns/query", "depth");
  for (size_t n : sizes) {
    const Workload w = MakeWorkload(*torus, n, iterations, seed);
    std::vector<double> step_ns, query_ns;
    int depth = 0;
    for (int rep = 0; rep < repeats; ++rep) {
      const RunResult r = RunOnce(w, bucket_size, rep == 0);
      step_ns.push_back(r.ns_per_step);
      query_ns.push_back(r.ns_per_query);
      depth = r.depth;
    }
    std::printf("%8zu %12.1f %12.1f %6d\n", n, Median(step_ns), Median(query_ns), depth);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace
}  // namespace neuralmesh

int main(int argc, char** argv) {
  neuralmesh::ParseBenchFlags(
      argc, argv,
      "Times the vertex octree's nearest-vertex queries and moves at several sizes; "
      "see bench/octree_bench.cc");
  return neuralmesh::Run();
}
