// The plane that fits a target space best in the least-squares sense (principal component
// analysis of samples drawn from it), and how far the data reaches within it. The disc start
// of the learner (initial_mesh.h) is built in it.
#ifndef NEURALMESH_CORE_LEARNING_BEST_FIT_PLANE_H_
#define NEURALMESH_CORE_LEARNING_BEST_FIT_PLANE_H_

#include "core/mesh.h"
#include "core/random.h"
#include "core/sampling/sampler.h"

namespace neuralmesh {

struct BestFitPlane {
  Vec3 center;  // The samples' mean: the plane passes through it.
  // An orthonormal, right-handed frame: u along the samples' largest spread, v along the
  // second largest, normal = u x v along the smallest (the plane's normal).
  Vec3 u;
  Vec3 v;
  Vec3 normal;
  // The largest distance from `center` of a sample projected into the plane. 0 when every
  // sample projects onto the centre.
  double radius = 0;
};

// Fits a plane to `samples` points drawn from `target` (which must not be empty) with `rng`.
// Deterministic for a given rng state and data. Degenerate data still give an orthonormal
// frame: points on a line give u along it and some v and normal perpendicular to it; a single
// point gives the coordinate axes and radius 0. O(samples).
BestFitPlane FitPlane(const Sampler& target, Random& rng, int samples);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_BEST_FIT_PLANE_H_
