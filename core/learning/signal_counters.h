// The signal counters of Section 2.2: each Basic Step adds 1 to the winner's counter and
// multiplies every counter by alpha_sc; Step 2 splits the vertex with the highest counter.
//
// Evaluation is lazy, as in Eq. 4: winners are recorded between two calls of Step 2 and applied
// when Step 2 asks for the most active vertex. Section 3.3's remedy for the otherwise quadratic
// Step 2 is taken one step further: a counter is stored as its logarithm referred to a common
// time origin,
//     key_i = ln c_i(t) - t ln(alpha_sc)   (independent of t between two touches of vertex i),
// so the global multiplication by alpha_sc never touches memory and no counter underflows to
// zero (the paper's c_M problem, Eq. 9).
//
// Finding the most active vertex without ordering all of them: a counter never exceeds
// B = max(1 / (1 - alpha_sc), every value given to Add or Set, every value a win left) (a win
// a step or more after the last touch turns c <= B into alpha_sc c + 1 <= B), so a vertex last
// touched (won, Add, Set) at step t has
//     key <= ln B - t ln(alpha_sc),
// a bound that grows with t. The touches are kept in order in a log, each with that bound (a
// running maximum, so that it never decreases along the log); the search walks the log from the
// newest touch back and stops at the first touch whose bound is below the best eligible key
// found: no vertex touched at or before it can beat that key. With the paper's alpha_sc = 0.95
// the walk ends about ln(20) / -ln(0.95) = 58 steps' touches before the winner it returns,
// whatever the mesh size; it goes further only past vertices that are not eligible. A win
// costs O(1) (one entry by id, one appended to the log). The log keeps only the last touch of
// each vertex once it grows past twice their number, so it stays O(v) in size for O(1)
// amortised time per touch.
//
// (An indexed max-heap over the keys did this in O(log v) per win; on a large mesh each win's
// sift to the top of the heap was several cache misses.)
#ifndef NEURALMESH_CORE_LEARNING_SIGNAL_COUNTERS_H_
#define NEURALMESH_CORE_LEARNING_SIGNAL_COUNTERS_H_

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "core/huge_page_allocator.h"

namespace neuralmesh {

class SignalCounters {
 public:
  // alpha_sc in (0, 1).
  explicit SignalCounters(double alpha_sc);

  // Starts tracking `id` with counter value `value` (>= 0) at step `step`; sets the value of
  // an id already tracked.
  void Add(int id, double value, uint64_t step);
  void Remove(int id);
  bool Contains(int id) const {
    return id >= 0 && id < static_cast<int>(key_.size()) && key_[id] != kUntracked;
  }

  // Records that `id` won the Basic Step numbered `step`; applied lazily (Eq. 4). Its key
  // starts loading now: on a large mesh it is a cache miss, and the Basic Steps until the next
  // Flush touch too little to evict it (0.98 of the time per Basic Step from 50K to 100K
  // vertices, against Flush's own prefetch alone).
  void RecordWin(int id, uint64_t step) {
    if (static_cast<size_t>(id) < key_.size()) __builtin_prefetch(&key_[id], 1);
    pending_.emplace_back(id, step);
  }
  // Applies the recorded wins. Wins of ids removed in between are dropped.
  void Flush();

  // The counter of `id` at step `step` (after Flush); 0 for an id not tracked.
  double Value(int id, uint64_t step) const;
  // Overwrites the counter of a tracked id (used when a split divides it, Eq. 5-6).
  void Set(int id, double value, uint64_t step);

  // The tracked id with the highest counter for which `eligible(id)` holds, or -1 (ties: any).
  // Flushes first. `eligible` is asked only of ids whose counter beats the best one so far,
  // so the id returned is the last one it accepted.
  int MostActive(const std::function<bool(int)>& eligible);

  size_t size() const { return tracked_; }
  // Entries in the touch log; for tests (at most about 2 size() + kLogSlack).
  size_t log_size() const { return log_.size(); }
  void Clear();

 private:
  // A key no counter has (ln 0 is -inf); NaN would do as well but is harder to compare.
  static constexpr double kUntracked = 1e308;
  static constexpr size_t kLogSlack = 4096;

  struct LoggedTouch {
    int32_t id;
    // >= the key of every vertex whose last touch is this one or an earlier one (rounded up
    // to a float: the bound only decides how far a search walks back).
    float bound;
  };

  // Sets the counter of a tracked `id` touched at `step`, raising B to it if needed.
  void SetValue(int id, double value, uint64_t step);
  // Sets the key of a tracked `id` touched at `step` and logs the touch (log_bound_ must
  // already bound its counter).
  void SetKey(int id, double key, uint64_t step);
  // Keeps only the last touch of each tracked id (in order).
  void CompactLog();

  double log_alpha_;
  double initial_log_bound_;    // ln(1 / (1 - alpha_sc)).
  double log_bound_;            // ln B, see above.
  HugePageVector<double> key_;  // By id; kUntracked when not tracked.
  size_t tracked_ = 0;
  std::vector<LoggedTouch> log_;
  std::vector<std::pair<int, uint64_t>> pending_;
  std::vector<uint64_t> seen_;  // For CompactLog: a bit per id.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_SIGNAL_COUNTERS_H_
