// Learning that no longer grows the mesh: Step 2's splits and Step 3's collapses in balance
// below the target, which more Basic Steps do not change (too few points for the target, points
// that all coincide, a thin shape sampled sparsely). The server and the CLI stop such a run with
// a clear error instead of learning forever.
#ifndef NEURALMESH_CORE_LEARNING_GROWTH_WATCH_H_
#define NEURALMESH_CORE_LEARNING_GROWTH_WATCH_H_

#include <cstddef>
#include <cstdint>

#include "absl/status/status.h"

namespace neuralmesh {

class GrowthWatch {
 public:
  // Split intervals (C_vs Basic Steps each) without a new largest vertex count after which
  // learning counts as stalled; normal growth makes one every few splits.
  static constexpr uint64_t kStallSplits = 2000;

  // For a learner that splits every `c_vs` (> 0) Basic Steps, or less often
  // (LongestSplitInterval in learner_options.h), starting now with `vertices` vertices after
  // `basic_steps` steps.
  GrowthWatch(int c_vs, size_t vertices, uint64_t basic_steps);

  // Records the learner's state; FAILED_PRECONDITION saying so once the mesh has not grown past
  // its largest vertex count for kStallSplits * C_vs Basic Steps, OK until then.
  absl::Status Check(size_t vertices, uint64_t basic_steps);

 private:
  uint64_t patience_;
  size_t max_vertices_;
  uint64_t steps_at_max_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_GROWTH_WATCH_H_
