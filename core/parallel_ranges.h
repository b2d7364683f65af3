// Work over [0, n) split into one contiguous range per thread, for loops whose iterations are
// independent and write only their own slots (so results do not depend on the thread count).
#ifndef NEURALMESH_CORE_PARALLEL_RANGES_H_
#define NEURALMESH_CORE_PARALLEL_RANGES_H_

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace neuralmesh {

// Runs work(begin, end) on consecutive ranges covering [0, n), one per thread, the calling
// thread taking the first, and returns when all are done. `threads` is 0 for one per hardware
// thread; no thread gets fewer than `min_per_thread` iterations (one thread at least).
template <typename Work>
void ForEachRange(size_t n, int threads, size_t min_per_thread, const Work& work) {
  size_t count = threads > 0 ? static_cast<size_t>(threads)
                             : std::max(1u, std::thread::hardware_concurrency());
  count = std::min(count, std::max<size_t>(1, n / std::max<size_t>(1, min_per_thread)));
  std::vector<std::thread> workers;
  for (size_t t = 1; t < count; ++t) {
    workers.emplace_back([&work, n, t, count] { work(n * t / count, n * (t + 1) / count); });
  }
  work(size_t{0}, n / count);
  for (std::thread& worker : workers) worker.join();
}

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_PARALLEL_RANGES_H_
