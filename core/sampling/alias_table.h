// Vose's alias method: draws an index with probability proportional to a weight in O(1),
// after an O(n) build. Used by the weighted samplers (per-point confidence and triangle
// choice, Section 4.1 of the paper).
//
//   build:  p_i = n w_i / sum(w); split the p_i into "small" (< 1) and "large" (>= 1);
//           repeatedly pair a small l with a large g: cell l keeps p_l of itself and
//           aliases the rest to g; g loses 1 - p_l and is re-filed as small or large.
//   draw:   i = uniform cell in [0, n); keep i with probability prob_i, else alias_i.
//
// M. D. Vose, "A linear algorithm for generating random numbers with a given distribution",
// IEEE Trans. Software Engineering 17(9), 1991.
#ifndef NEURALMESH_CORE_SAMPLING_ALIAS_TABLE_H_
#define NEURALMESH_CORE_SAMPLING_ALIAS_TABLE_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/random.h"

namespace neuralmesh {

class AliasTable {
 public:
  // Builds the table for `weights` in O(n). An entry of weight zero is never drawn.
  // Returns INVALID_ARGUMENT when `weights` is empty, has more than 2^32 - 1 entries, holds a
  // negative or non-finite weight, sums to zero, or sums to more than a double can hold.
  static absl::StatusOr<AliasTable> Create(absl::Span<const double> weights);
  static absl::StatusOr<AliasTable> Create(absl::Span<const float> weights);

  // Draws index i with probability weights[i] / sum(weights). O(1): one NextIndex and one
  // NextDouble from `rng`, nothing else: always two NextU64, so that the state after one draw
  // tells the next one.
  size_t Draw(Random& rng) const {
    const uint64_t cell = rng.NextIndex(prob_.size());
    return rng.NextDouble() < prob_[cell] ? cell : alias_[cell];
  }

  // Starts loading the cell that Draw(rng) reads (a cache miss on a large table).
  void PrefetchDraw(const Random& rng) const {
    Random peek = rng;
    const uint64_t cell = peek.NextIndex(prob_.size());
    __builtin_prefetch(&prob_[cell]);
    __builtin_prefetch(&alias_[cell]);
  }

  // The number of weights, including those of weight zero.
  size_t size() const { return prob_.size(); }

 private:
  AliasTable() = default;
  template <typename T>
  static absl::StatusOr<AliasTable> Build(absl::Span<const T> weights);

  std::vector<double> prob_;     // Probability of keeping the cell's own index.
  std::vector<uint32_t> alias_;  // The index drawn otherwise.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_ALIAS_TABLE_H_
