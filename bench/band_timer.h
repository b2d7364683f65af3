// Timing learners in turns: the machine's speed drifts by up to 1.8 times within a second, so
// learners that are compared take turns of 20,000 Basic Steps and the drift meets them alike.
#ifndef NEURALMESH_BENCH_BAND_TIMER_H_
#define NEURALMESH_BENCH_BAND_TIMER_H_

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/learning/learner.h"

namespace neuralmesh {

// Wall time and Basic Steps per band of vertex counts (between two milestones), taken in turns
// of 20,000 Basic Steps so that two learners, or two processes, can alternate and the
// machine's drift, which is large here, hits both alike.
class BandTimer {
 public:
  explicit BandTimer(std::vector<size_t> bands)
      : bands_(std::move(bands)), seconds_(bands_.size()), steps_(bands_.size()) {}
  bool done(const Learner& learner) const { return band_of(learner) >= bands_.size(); }
  // One turn of `learner`; its error when it fails.
  absl::Status Turn(Learner& learner) {
    const size_t band = band_of(learner);
    StopCriteria turn;
    turn.max_basic_steps = kTurnSteps;
    turn.target_vertices = bands_.back();
    const uint64_t before = learner.progress().basic_steps;
    const auto start = std::chrono::steady_clock::now();
    if (absl::StatusOr<StopReason> stop = learner.Run(turn); !stop.ok()) return stop.status();
    seconds_[band] +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    steps_[band] += learner.progress().basic_steps - before;
    return absl::OkStatus();
  }
  const std::vector<size_t>& bands() const { return bands_; }
  double us_per_step(size_t band) const { return 1e6 * seconds_[band] / steps_[band]; }
  double total_seconds() const {
    double total = 0;
    for (double s : seconds_) total += s;
    return total;
  }
  uint64_t total_steps() const {
    uint64_t total = 0;
    for (uint64_t s : steps_) total += s;
    return total;
  }
  uint64_t steps(size_t band) const { return steps_[band]; }

  static constexpr uint64_t kTurnSteps = 20000;

 private:
  size_t band_of(const Learner& learner) const {
    size_t band = 0;
    while (band < bands_.size() && learner.num_vertices() >= bands_[band]) ++band;
    return band;
  }
  std::vector<size_t> bands_;
  std::vector<double> seconds_;
  std::vector<uint64_t> steps_;
};

// Gives each learner a turn in order, skipping those whose timer is done, until all are done.
// The first error of a learner, if one fails.
inline absl::Status TakeTurns(const std::vector<std::unique_ptr<Learner>>& learners,
                              std::vector<BandTimer>& timers) {
  for (bool all_done = false; !all_done;) {
    all_done = true;
    for (size_t i = 0; i < learners.size(); ++i) {
      if (timers[i].done(*learners[i])) continue;
      if (absl::Status status = timers[i].Turn(*learners[i]); !status.ok()) return status;
      all_done = false;
    }
  }
  return absl::OkStatus();
}

}  // namespace neuralmesh

#endif  // NEURALMESH_BENCH_BAND_TIMER_H_
