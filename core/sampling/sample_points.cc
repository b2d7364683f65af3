#include "core/sampling/sample_points.h"

#include "core/random.h"

namespace neuralmesh {

PointCloud SamplePoints(const Sampler& sampler, size_t n, uint64_t seed) {
  PointCloud cloud;
  if (sampler.empty()) return cloud;
  Random rng(seed);
  cloud.positions.reserve(n);
  for (size_t i = 0; i < n; ++i) cloud.positions.emplace_back(sampler.Sample(rng));
  return cloud;
}

}  // namespace neuralmesh
