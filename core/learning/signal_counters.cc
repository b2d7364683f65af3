#include "core/learning/signal_counters.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace neuralmesh {

SignalCounters::SignalCounters(double alpha_sc) : log_alpha_(std::log(alpha_sc)) {}

double SignalCounters::KeyOf(double value, uint64_t step) const {
  if (!(value > 0)) return -std::numeric_limits<double>::infinity();
  return std::log(value) - static_cast<double>(step) * log_alpha_;
}

double SignalCounters::Value(int id, uint64_t step) const {
  if (!Contains(id)) return 0;
  const double k = heap_[heap_pos_[id]].key;
  if (k == -std::numeric_limits<double>::infinity()) return 0;
  return std::exp(k + static_cast<double>(step) * log_alpha_);
}

void SignalCounters::Add(int id, double value, uint64_t step) {
  if (id >= static_cast<int>(heap_pos_.size())) heap_pos_.resize(static_cast<size_t>(id) + 1, -1);
  if (heap_pos_[id] >= 0) {
    Set(id, value, step);
    return;
  }
  heap_pos_[id] = static_cast<int>(heap_.size());
  heap_.push_back({KeyOf(value, step), id});
  SiftUp(heap_.size() - 1);
}

void SignalCounters::Remove(int id) {
  if (!Contains(id)) return;
  const size_t i = static_cast<size_t>(heap_pos_[id]);
  const size_t last = heap_.size() - 1;
  heap_pos_[id] = -1;
  if (i != last) {
    Place(i, heap_[last]);
    heap_.pop_back();
    SiftDown(i);
    SiftUp(i);
  } else {
    heap_.pop_back();
  }
}

void SignalCounters::Set(int id, double value, uint64_t step) { Update(id, KeyOf(value, step)); }

void SignalCounters::Update(int id, double key) {
  const size_t i = static_cast<size_t>(heap_pos_[id]);
  const double old = heap_[i].key;
  heap_[i].key = key;
  if (key > old) {
    SiftUp(i);
  } else {
    SiftDown(i);
  }
}

void SignalCounters::Flush() {
  // Below e^-38 (< 2^-54) a counter adds nothing to the 1 of a win: before + 1.0 rounds to
  // exactly 1.0. Such wins, most of them on a large mesh (a vertex wins about once every v
  // Basic Steps, and e^-38 = alpha_sc^740 for the paper's 0.95), skip the exp and the log and
  // still give bitwise the same key.
  constexpr double kNegligibleExponent = -38;
  // On a large mesh each win's entry is a cache miss, and so is its position in the heap
  // before it: both start loading for all the wins first, one level at a time.
  for (const auto& [id, step] : pending_) {
    if (static_cast<size_t>(id) < heap_pos_.size()) __builtin_prefetch(&heap_pos_[id]);
  }
  for (const auto& [id, step] : pending_) {
    if (Contains(id)) __builtin_prefetch(&heap_[heap_pos_[id]]);
  }
  for (const auto& [id, step] : pending_) {
    if (!Contains(id)) continue;
    // c(step) after the win = c(step) before it + 1 (Eq. 4's 1 + sum alpha^-x, one term at a
    // time); the common factor alpha^t stays implicit in the key.
    const double time_term = static_cast<double>(step) * log_alpha_;
    if (heap_[heap_pos_[id]].key + time_term < kNegligibleExponent) {
      Update(id, 0.0 - time_term);  // KeyOf(1.0, step): log(1) is exactly 0.
      continue;
    }
    const double before = Value(id, step);
    Update(id, KeyOf(before + 1.0, step));
  }
  pending_.clear();
}

int SignalCounters::MostActive(const std::function<bool(int)>& eligible) {
  Flush();
  if (heap_.empty()) return -1;
  if (eligible(heap_[0].id)) return heap_[0].id;
  // Best-first walk of the heap: the largest eligible key is found without popping anything.
  std::vector<size_t> frontier = {0};
  int best = -1;
  double best_key = -std::numeric_limits<double>::infinity();
  while (!frontier.empty()) {
    // Take the frontier entry with the largest key.
    size_t pick = 0;
    for (size_t j = 1; j < frontier.size(); ++j) {
      if (heap_[frontier[j]].key > heap_[frontier[pick]].key) pick = j;
    }
    const size_t i = frontier[pick];
    frontier[pick] = frontier.back();
    frontier.pop_back();
    const Entry& entry = heap_[i];
    if (best >= 0 && entry.key <= best_key) break;
    if (eligible(entry.id)) {
      best = entry.id;
      best_key = entry.key;
      break;
    }
    for (size_t c = FirstChild(i); c < FirstChild(i) + kArity && c < heap_.size(); ++c) {
      frontier.push_back(c);
    }
  }
  return best;
}

void SignalCounters::Clear() {
  heap_pos_.clear();
  heap_.clear();
  pending_.clear();
}

void SignalCounters::Place(size_t i, const Entry& entry) {
  heap_[i] = entry;
  heap_pos_[entry.id] = static_cast<int>(i);
}

// Both sifts move the entry through a hole: each level writes one entry and one position
// instead of swapping two.
void SignalCounters::SiftUp(size_t i) {
  const Entry moving = heap_[i];
  while (i > 0) {
    const size_t parent = (i - 1) / kArity;
    if (heap_[parent].key >= moving.key) break;
    Place(i, heap_[parent]);
    i = parent;
  }
  Place(i, moving);
}

void SignalCounters::SiftDown(size_t i) {
  const size_t n = heap_.size();
  const Entry moving = heap_[i];
  while (true) {
    const size_t first = FirstChild(i);
    if (first >= n) break;
    size_t largest = first;
    const size_t end = std::min(first + kArity, n);
    for (size_t c = first + 1; c < end; ++c) {
      if (heap_[c].key > heap_[largest].key) largest = c;
    }
    if (heap_[largest].key <= moving.key) break;
    Place(i, heap_[largest]);
    i = largest;
  }
  Place(i, moving);
}

}  // namespace neuralmesh
