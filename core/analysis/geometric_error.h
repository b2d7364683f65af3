// Geometric error of a reconstruction against a reference surface, or against the points it was
// learned from: Chamfer (L1), Hausdorff and normal consistency, normalised by the diagonal of
// the reference's bounding box.
//
//   1. Sample each surface area-uniformly (pick a triangle with probability proportional to
//      its area, then a uniform point in it), deterministically from the seed.
//   2. For every sample, find the exact closest point on the other surface with a
//      TriangleTree (no approximation besides the sampling itself).
//   3. accuracy = mean over reconstruction samples of d(p, reference) / diag,
//      completeness = mean over reference samples of d(q, reconstruction) / diag,
//      chamfer_l1 = (accuracy + completeness) / 2,
//      hausdorff = the largest distance either way / diag, also over every vertex of both
//      meshes so that a single spike vertex is caught,
//      normal_consistency = mean over the samples of both sides of |n_p . n_closest|, with
//      the face normals of the sample's triangle and of the closest point's triangle.
// The vertices only enter the Hausdorff maximum: the means stay unbiased estimates of the
// surface integrals whatever the tessellation. A vertex query may stop as soon as it finds
// the other surface within the largest sample distance, which leaves the maximum exact.
// The reference's samples depend only on the seed, so reconstructions compared with one
// reference share them. The two trees are built in parallel. O((s + v) log f) for s samples.
#ifndef NEURALMESH_CORE_ANALYSIS_GEOMETRIC_ERROR_H_
#define NEURALMESH_CORE_ANALYSIS_GEOMETRIC_ERROR_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/mesh.h"
#include "core/point_cloud.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

struct GeometricErrorOptions {
  // More samples than this are refused rather than allocated: the estimates converge long
  // before (the default is 200,000), and each sample costs memory for its point, its normal and
  // its closest point.
  static constexpr size_t kMaxSamples = 20000000;

  size_t samples = 200000;  // Area-uniform samples per surface (besides its vertices).
  uint64_t seed = 1;        // Seeds the sampling; equal seeds give equal results.
  int threads = 0;          // Query threads; 0: one per hardware thread. Results do not
                            // depend on it.

  // INVALID_ARGUMENT when samples is 0 or above kMaxSamples, or threads < 0.
  absl::Status Validate() const;
};

struct GeometricError {
  double chamfer_l1 = 0.0;          // (accuracy + completeness) / 2.
  double hausdorff = 0.0;           // Largest distance in either direction / diagonal.
  double normal_consistency = 0.0;  // Mean |n . n'| over the samples of both sides, in [0, 1].
  double accuracy = 0.0;            // Mean reconstruction -> reference distance / diagonal.
  double completeness = 0.0;        // Mean reference -> reconstruction distance / diagonal.
  double diagonal = 0.0;            // Bounding-box diagonal of the reference.
};

// Compares `reconstruction` with `reference`.
// Returns INVALID_ARGUMENT when either mesh has no vertices or no faces, a face index is out
// of range, a position is not finite, a surface has zero area, the reference's bounding box
// has zero diagonal, or `options` is invalid.
absl::StatusOr<GeometricError> ComputeGeometricError(const TriangleMesh& reconstruction,
                                                     const TriangleMesh& reference,
                                                     const GeometricErrorOptions& options = {});

// Compares `reconstruction` with the points it was learned from, for scans that have no
// reference surface (the points and the mesh in one frame):
//   completeness = mean over every point of its exact distance to the reconstruction / diag,
//   accuracy = mean over the reconstruction's area-uniform samples of the distance to the
//     nearest point / diag (surface where the points have none: a bridged hole, a bulge; the
//     points' spacing sets its floor),
//   chamfer_l1 = (accuracy + completeness) / 2,
//   hausdorff = the largest distance either way / diag, also over every vertex,
//   normal_consistency = mean over both sides of |n . n'|, the points' normals against the
//     closest triangle's and the samples' against their nearest point's, when the points carry
//     normals; NaN otherwise,
// diag being the diagonal of the points' bounding box. O((n + s + v) log) for n points and s
// samples.
// Returns INVALID_ARGUMENT as ComputeGeometricError for the reconstruction, and for no points,
// a non-finite point or points whose bounding box has zero diagonal.
absl::StatusOr<GeometricError> ComputeErrorAgainstPoints(const TriangleMesh& reconstruction,
                                                         const PointCloud& points,
                                                         const GeometricErrorOptions& options = {});

// The exact (unnormalised) distance from each of `points` to the surface of `mesh`, in the
// order of `points`, over `threads` threads (0: one per hardware thread).
// Returns INVALID_ARGUMENT for a mesh without faces, an out-of-range face index, a non-finite
// position, or a non-finite query point.
absl::StatusOr<std::vector<double>> DistancesToMesh(absl::Span<const Vec3> points,
                                                    const TriangleMesh& mesh, int threads = 0);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_GEOMETRIC_ERROR_H_
