// Draws a point cloud from any target space P (Section 2.1): n independent samples, for tests
// and demos that need an input cloud with known ground truth (an implicit surface, a mesh).
#ifndef NEURALMESH_CORE_SAMPLING_SAMPLE_POINTS_H_
#define NEURALMESH_CORE_SAMPLING_SAMPLE_POINTS_H_

#include <cstddef>
#include <cstdint>

#include "core/point_cloud.h"
#include "core/sampling/sampler.h"

namespace neuralmesh {

// `n` samples of `sampler` drawn with a Random seeded by `seed`, in draw order, positions only
// (no weights, no normals): the same seed gives the same cloud. An empty sampler gives an
// empty cloud. O(n) sampler calls.
PointCloud SamplePoints(const Sampler& sampler, size_t n, uint64_t seed);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_SAMPLE_POINTS_H_
