#include "core/sampling/alias_table.h"

#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"

namespace neuralmesh {

template <typename T>
absl::StatusOr<AliasTable> AliasTable::Build(absl::Span<const T> weights) {
  const size_t n = weights.size();
  if (n == 0) return absl::InvalidArgumentError("the alias table needs at least one weight");
  if (n > std::numeric_limits<uint32_t>::max()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the alias table holds at most 2^32 - 1 weights, not ", n));
  }
  double sum = 0;
  size_t any_positive = 0;
  for (size_t i = 0; i < n; ++i) {
    const double w = weights[i];
    if (!std::isfinite(w) || w < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("weight ", i, " is ", w, "; weights must be finite and non-negative"));
    }
    if (w > 0) any_positive = i;
    sum += w;
  }
  if (!(sum > 0)) return absl::InvalidArgumentError("all weights are zero");
  if (!std::isfinite(sum)) {
    return absl::InvalidArgumentError("the weights sum to more than a double can hold");
  }

  AliasTable table;
  table.prob_.resize(n);
  table.alias_.resize(n);
  std::vector<double> scaled(n);
  std::vector<uint32_t> small;
  std::vector<uint32_t> large;
  for (size_t i = 0; i < n; ++i) {
    // Divided first: n / sum overflows to infinity when the sum is subnormal, and a weight of
    // zero times infinity is NaN, which was filed as large and drawn.
    scaled[i] = static_cast<double>(weights[i]) / sum * static_cast<double>(n);
    (scaled[i] < 1.0 ? small : large).push_back(static_cast<uint32_t>(i));
  }
  while (!small.empty() && !large.empty()) {
    const uint32_t l = small.back();
    small.pop_back();
    const uint32_t g = large.back();
    table.prob_[l] = scaled[l];
    table.alias_[l] = g;
    // Vose's order of operations, (p_g + p_l) - 1, loses less precision than p_g - (1 - p_l).
    scaled[g] = (scaled[g] + scaled[l]) - 1.0;
    if (scaled[g] < 1.0) {
      large.pop_back();
      small.push_back(g);
    }
  }
  for (uint32_t g : large) {
    table.prob_[g] = 1.0;
    table.alias_[g] = g;
  }
  // Only rounding leaves cells in `small` here, all with p close to 1, except that a cell of
  // weight zero must stay undrawable: it sends every draw to a positive entry instead.
  for (uint32_t l : small) {
    const bool positive = weights[l] > 0;
    table.prob_[l] = positive ? 1.0 : 0.0;
    table.alias_[l] = positive ? l : static_cast<uint32_t>(any_positive);
  }
  return table;
}

absl::StatusOr<AliasTable> AliasTable::Create(absl::Span<const double> weights) {
  return Build(weights);
}

absl::StatusOr<AliasTable> AliasTable::Create(absl::Span<const float> weights) {
  return Build(weights);
}

}  // namespace neuralmesh
