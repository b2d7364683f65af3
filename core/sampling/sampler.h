// The target space P of the paper (Section 2.1): anything that returns one random point of the
// surface to reconstruct per call. Every sampler answers in O(1), independent of the size of
// its data, which is what makes the learner's speed independent of the input size.
#ifndef NEURALMESH_CORE_SAMPLING_SAMPLER_H_
#define NEURALMESH_CORE_SAMPLING_SAMPLER_H_

#include "absl/status/status.h"
#include "core/bounding_box.h"
#include "core/mesh.h"
#include "core/random.h"

namespace neuralmesh {

class Sampler {
 public:
  virtual ~Sampler() = default;

  // Draws one point s of P using `rng`. Only called when !empty(). Deterministic for a given
  // rng state and data. May be called from one thread while data is appended from another
  // (see GrowingPointCloud).
  virtual Vec3 Sample(Random& rng) const = 0;

  // A hint, for samplers that read a large array: starts loading what Sample would read if
  // called now with `rng`, which it leaves unchanged. The learner calls it one Basic Step
  // ahead, so that the draw does not wait for main memory. By default nothing.
  virtual void PrefetchSample(const Random& rng) const { (void)rng; }

  // Whether there is nothing to sample yet.
  virtual bool empty() const = 0;

  // The bounding box of the data seen so far (the initial tetrahedron is built around it).
  virtual BoundingBox Bounds() const = 0;

  // OK while the points drawn so far are the target space's; an error saying why once they
  // may not be (a file read where it lies that shrank: OffCoreSampler). Cheap enough to call
  // every thousand Basic Steps. By default OK.
  virtual absl::Status CheckSource() const { return absl::OkStatus(); }
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_SAMPLER_H_
