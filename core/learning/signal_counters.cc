#include "core/learning/signal_counters.h"

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
  if (i != last) {
    Swap(i, last);
    heap_.pop_back();
    heap_pos_[id] = -1;
    SiftDown(i);
    SiftUp(i);
  } else {
    heap_.pop_back();
    heap_pos_[id] = -1;
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
  for (const auto& [id, step] : pending_) {
    if (!Contains(id)) continue;
    // c(step) after the win = c(step) before it + 1 (Eq. 4's 1 + sum alpha^-x, one term at a
    // time); the common factor alpha^t stays implicit in the key.
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
    for (size_t c = 2 * i + 1; c <= 2 * i + 2 && c < heap_.size(); ++c) frontier.push_back(c);
  }
  return best;
}

void SignalCounters::Clear() {
  heap_pos_.clear();
  heap_.clear();
  pending_.clear();
}

void SignalCounters::Swap(size_t a, size_t b) {
  std::swap(heap_[a], heap_[b]);
  heap_pos_[heap_[a].id] = static_cast<int>(a);
  heap_pos_[heap_[b].id] = static_cast<int>(b);
}

void SignalCounters::SiftUp(size_t i) {
  while (i > 0) {
    const size_t parent = (i - 1) / 2;
    if (heap_[parent].key >= heap_[i].key) break;
    Swap(i, parent);
    i = parent;
  }
}

void SignalCounters::SiftDown(size_t i) {
  const size_t n = heap_.size();
  while (true) {
    size_t largest = i;
    const size_t l = 2 * i + 1, r = 2 * i + 2;
    if (l < n && heap_[l].key > heap_[largest].key) largest = l;
    if (r < n && heap_[r].key > heap_[largest].key) largest = r;
    if (largest == i) break;
    Swap(i, largest);
    i = largest;
  }
}

}  // namespace neuralmesh
