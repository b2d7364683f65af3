#include "core/learning/signal_counters.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/next_float.h"

namespace neuralmesh {

SignalCounters::SignalCounters(double alpha_sc)
    : log_alpha_(std::log(alpha_sc)),
      initial_log_bound_(-std::log1p(-alpha_sc)),
      log_bound_(initial_log_bound_) {}

double SignalCounters::Value(int id, uint64_t step) const {
  if (!Contains(id)) return 0;
  const double k = key_[id];
  if (k == -std::numeric_limits<double>::infinity()) return 0;
  return std::exp(k + static_cast<double>(step) * log_alpha_);
}

void SignalCounters::Add(int id, double value, uint64_t step) {
  if (id >= static_cast<int>(key_.size())) key_.resize(static_cast<size_t>(id) + 1, kUntracked);
  if (!Contains(id)) ++tracked_;
  SetValue(id, value, step);
}

void SignalCounters::Remove(int id) {
  if (!Contains(id)) return;
  key_[id] = kUntracked;  // Its touches stay in the log, where searches skip them.
  --tracked_;
}

void SignalCounters::Set(int id, double value, uint64_t step) {
  if (Contains(id)) SetValue(id, value, step);
}

void SignalCounters::SetValue(int id, double value, uint64_t step) {
  // ln c, for the key and for B; a counter of 0 (or less) has the key -inf.
  const double log_value = value > 0 ? std::log(value) : -std::numeric_limits<double>::infinity();
  log_bound_ = std::max(log_bound_, log_value);
  SetKey(id, log_value - static_cast<double>(step) * log_alpha_, step);
}

// Inline: Flush sets a key for every win, 100 per split.
inline void SignalCounters::SetKey(int id, double key, uint64_t step) {
  key_[id] = key;
  // The largest key a counter of at most B can have at this step, computed as SetValue
  // computes keys, plus a margin for their rounding.
  double bound = log_bound_ - static_cast<double>(step) * log_alpha_;
  bound += 1e-9 * (1 + std::abs(bound));
  if (!log_.empty()) bound = std::max(bound, static_cast<double>(log_.back().bound));
  float rounded = static_cast<float>(bound);
  if (static_cast<double>(rounded) < bound) {
    rounded = NextFloatUp(rounded);
  }
  log_.push_back(LoggedTouch{id, rounded});
  if (log_.size() > 2 * tracked_ + kLogSlack) CompactLog();
}

void SignalCounters::CompactLog() {
  // A bit per id whose touches are dropped: the untracked ids, marked first in one pass over
  // the keys in order (on a large mesh, reading the key of each touch instead was a cache
  // miss per touch, 10% of Step 2's time at 100K vertices), then each id whose last touch is
  // kept.
  const size_t ids = key_.size();
  seen_.assign((ids + 63) / 64, 0);
  for (size_t id = 0; id < ids; ++id) {
    seen_[id / 64] |= uint64_t{key_[id] == kUntracked} << (id % 64);
  }
  // Newest first: the first touch met of an id is its last one.
  size_t kept = log_.size();
  for (size_t i = log_.size(); i-- > 0;) {
    const LoggedTouch touch = log_[i];
    const size_t id = static_cast<size_t>(touch.id);
    const uint64_t bit = uint64_t{1} << (id % 64);
    const bool keep = (seen_[id / 64] & bit) == 0;
    seen_[id / 64] |= bit;
    // Written whether kept or not, without a branch (which half the touches would mispredict):
    // kept > i, so this overwrites only touches already read, or this one.
    log_[kept - 1] = touch;
    kept -= keep ? 1 : 0;
  }
  log_.erase(log_.begin(), log_.begin() + static_cast<std::ptrdiff_t>(kept));
}

void SignalCounters::Flush() {
  // Below e^-38 (< 2^-54) a counter adds nothing to the 1 of a win: before + 1.0 rounds to
  // exactly 1.0. Such wins, most of them on a large mesh (a vertex wins about once every v
  // Basic Steps, and e^-38 = alpha_sc^740 for the paper's 0.95), skip the exp and the log and
  // still give bitwise the same key.
  constexpr double kNegligibleExponent = -38;
  // On a large mesh each win's key is a cache miss: they all start loading first.
  for (const auto& [id, step] : pending_) {
    if (static_cast<size_t>(id) < key_.size()) __builtin_prefetch(&key_[id]);
  }
  for (const auto& [id, step] : pending_) {
    if (!Contains(id)) continue;
    // c(step) after the win = c(step) before it + 1 (Eq. 4's 1 + sum alpha^-x, one term at a
    // time); the common factor alpha^t stays implicit in the key.
    const double time_term = static_cast<double>(step) * log_alpha_;
    if (key_[id] + time_term < kNegligibleExponent) {
      SetKey(id, 0.0 - time_term, step);  // A value of 1: log(1) is exactly 0, and 1 <= B.
      continue;
    }
    // A win keeps the counter at or below B unless it lands in the step of the id's last
    // touch (nothing decayed yet): SetValue raises B then.
    SetValue(id, Value(id, step) + 1.0, step);
  }
  pending_.clear();
}

int SignalCounters::MostActive(const std::function<bool(int)>& eligible) {
  Flush();
  int best = -1;
  double best_key = -std::numeric_limits<double>::infinity();
  for (size_t i = log_.size(); i-- > 0;) {
    const LoggedTouch touch = log_[i];
    if (touch.bound < best_key) break;  // Nobody touched at or before this one beats best.
    const double key = key_[touch.id];
    if (key != kUntracked && key > best_key && eligible(touch.id)) {
      best = touch.id;
      best_key = key;
    }
  }
  if (best >= 0) return best;
  // No eligible counter above 0 (ln 0 = -inf): any eligible one, the last touched first.
  for (size_t i = log_.size(); i-- > 0;) {
    const int id = log_[i].id;
    if (key_[id] != kUntracked && eligible(id)) return id;
  }
  return -1;
}

void SignalCounters::Clear() {
  key_.clear();
  tracked_ = 0;
  log_.clear();
  pending_.clear();
  log_bound_ = initial_log_bound_;
}

}  // namespace neuralmesh
