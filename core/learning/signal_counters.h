// The signal counters of Section 2.2: each Basic Step adds 1 to the winner's counter and
// multiplies every counter by alpha_sc; Step 2 splits the vertex with the highest counter.
//
// Evaluation is lazy, as in Eq. 4: winners are recorded between two calls of Step 2 and applied
// when Step 2 asks for the most active vertex. Section 3.3's remedy for the otherwise quadratic
// Step 2 is taken one step further: a counter is stored as its logarithm referred to a common
// time origin,
//     key_i = ln c_i(t) - t ln(alpha_sc)   (independent of t between two wins of vertex i),
// so the global multiplication by alpha_sc never touches memory, no counter underflows to zero
// (the paper's c_M problem, Eq. 9), and an indexed max-heap over the keys finds the most active
// vertex in O(log v). A win costs O(log v), amortised over the Basic Steps.
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
  explicit SignalCounters(double alpha_sc);

  // Starts tracking `id` with counter value `value` (>= 0) at step `step`.
  void Add(int id, double value, uint64_t step);
  void Remove(int id);
  bool Contains(int id) const {
    return id >= 0 && id < static_cast<int>(heap_pos_.size()) && heap_pos_[id] >= 0;
  }

  // Records that `id` won the Basic Step numbered `step`; applied lazily (Eq. 4).
  void RecordWin(int id, uint64_t step) { pending_.emplace_back(id, step); }
  // Applies the recorded wins. Wins of ids removed in between are dropped.
  void Flush();

  // The counter of `id` at step `step` (after Flush); 0 for an id not tracked.
  double Value(int id, uint64_t step) const;
  // Overwrites the counter of a tracked id (used when a split divides it, Eq. 5-6).
  void Set(int id, double value, uint64_t step);

  // The tracked id with the highest counter for which `eligible(id)` holds, or -1. Flushes
  // first. Ineligible ids met on the way stay tracked.
  int MostActive(const std::function<bool(int)>& eligible);

  size_t size() const { return heap_.size(); }
  void Clear();

 private:
  double KeyOf(double value, uint64_t step) const;
  void SiftUp(size_t i);
  void SiftDown(size_t i);
  void Update(int id, double key);

  // The keys live in the heap entries, so that sifting reads only the heap (a win's sift
  // touches a few random entries; on a large mesh each is a cache miss).
  struct Entry {
    double key;
    int id;
  };
  // A win's key is nearly always the largest (keys grow with the time of the last win), so
  // its sift runs to the top: a 4-ary heap halves the levels, and the misses, of a binary one.
  static constexpr size_t kArity = 4;
  static size_t FirstChild(size_t i) { return kArity * i + 1; }
  // Writes `entry` at heap index i and records where its id now is.
  void Place(size_t i, const Entry& entry);

  double log_alpha_;
  HugePageVector<int> heap_pos_;  // By id; -1 when not tracked.
  HugePageVector<Entry> heap_;    // Max-heap by key.
  std::vector<std::pair<int, uint64_t>> pending_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_SIGNAL_COUNTERS_H_
