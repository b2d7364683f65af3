// The latency of one dependent load from a block of memory of a given size, read in random
// order (a pointer chase through a random cycle of cache lines). Printed by learner-bench next
// to its table: once a mesh outgrows the caches, a Basic Step waits on chains of such loads
// (octree leaf, winner's ring, its neighbours' rings, their positions), so this figure, more
// than the learner's code, sets how much a step at 100,000 vertices costs over one at 1,000.
#ifndef NEURALMESH_BENCH_MEMORY_LATENCY_H_
#define NEURALMESH_BENCH_MEMORY_LATENCY_H_

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

namespace neuralmesh::bench {

// Nanoseconds per load, over `loads` loads, from `bytes` of memory (at least two cache lines).
inline double DependentLoadNanoseconds(size_t bytes, size_t loads = 10'000'000) {
  constexpr size_t kLineWords = 64 / sizeof(size_t);
  const size_t lines = std::max<size_t>(2, bytes / 64);
  std::vector<size_t> order(lines);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin() + 1, order.end(), std::mt19937_64(1));
  // Word 0 of each line holds the index of the next line's word 0, in the shuffled order.
  std::vector<size_t> chase(lines * kLineWords);
  for (size_t i = 0; i < lines; ++i) {
    chase[order[i] * kLineWords] = order[(i + 1) % lines] * kLineWords;
  }
  size_t at = 0;
  for (size_t i = 0; i < lines; ++i) at = chase[at];  // Warm up: one round through.
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < loads; ++i) at = chase[at];
  const double ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  // Keeps the chase from being optimised away: `at` is a valid index, so this never fires.
  if (at >= chase.size()) return -1;
  return ns / static_cast<double>(loads);
}

}  // namespace neuralmesh::bench

#endif  // NEURALMESH_BENCH_MEMORY_LATENCY_H_
