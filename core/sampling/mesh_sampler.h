// Samples a triangle mesh (Section 4.1 of the paper): first a triangle, drawn from an alias
// table, then a uniform point in it. The triangle weights decide the remeshing the learner
// produces:
//
//   kArea:       w_t = A_t                        uniform area remeshing
//   kCurvature:  w_t = A_t (epsilon + D |H|_t)    curvature-adaptive remeshing
//
// A_t is the triangle's area, D the diagonal of the mesh's bounding box (so the weights do not
// change when the mesh is scaled) and |H|_t the mean over the triangle's corners of the
// vertex estimate
//
//   |H|_v = (1 / (4 A_v)) sum over edges e at v of |e| |theta_e|,   A_v = sum(A_t at v) / 3,
//
// with theta_e the dihedral angle of e (the angle between the normals of its two triangles,
// orientation made consistent across e). This is the edge-based discrete mean curvature
// (|e| theta_e / 2 per edge, split between its ends; Cohen-Steiner and Morvan, "Restricted
// Delaunay triangulations and normal cycle", SoCG 2003) with absolute dihedral angles: it
// equals |H| on convex or concave regions (1/r on a sphere of radius r, 1/(2r) on a cylinder)
// and, unlike |H|, does not cancel on saddles, which need fine sampling just as much. Edges on
// a boundary, shared by more than two triangles, or next to a zero-area triangle count as
// flat.
//
// The point in the triangle (a, b, c) is a + s (1 - u)(b - a) + s u (c - a) with s = sqrt(r1),
// u = r2 for two uniform numbers r1, r2 (Turk, "Generating random points in triangles",
// Graphics Gems, 1990).
#ifndef NEURALMESH_CORE_SAMPLING_MESH_SAMPLER_H_
#define NEURALMESH_CORE_SAMPLING_MESH_SAMPLER_H_

#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/bounding_box.h"
#include "core/random.h"
#include "core/sampling/alias_table.h"
#include "core/sampling/sampler.h"
#include "core/triangle_mesh.h"

namespace neuralmesh {

enum class MeshSamplingMode {
  kArea,       // Uniform area remeshing (Section 4.1): a triangle is drawn in proportion to
               // its area, so the density on the surface is uniform.
  kCurvature,  // Curvature-adaptive remeshing (Section 4.1): area times a curvature factor.
};

struct MeshSamplerOptions {
  MeshSamplingMode mode = MeshSamplingMode::kArea;
  // kCurvature only: the density of flat regions relative to regions where D |H| = 1 (with D
  // the bounding-box diagonal). With the default 1, a sphere is sampled 1 + 2 sqrt(3) = 4.5
  // times as densely as a plane of the same mesh. Must be finite and > 0.
  double curvature_epsilon = 1.0;

  // Returns INVALID_ARGUMENT naming the first field out of range.
  absl::Status Validate() const;
};

// The weight w_t of every triangle of `mesh` under `options`, as the table above defines it.
// Returns INVALID_ARGUMENT for invalid options, an empty mesh (no vertex or no face), a face
// index out of range, or a non-finite position. O(v + f).
absl::StatusOr<std::vector<double>> ComputeTriangleWeights(const TriangleMesh& mesh,
                                                           const MeshSamplerOptions& options);

// Samples the surface of a TriangleMesh, shared (never copied) through the pointer.
class MeshSampler final : public Sampler {
 public:
  // Returns INVALID_ARGUMENT when `mesh` is null, for the cases of ComputeTriangleWeights, when
  // every triangle has zero area (zero weight), or when there are 2^32 or more faces.
  // O(v + f) build, 12 bytes per face beyond the mesh.
  static absl::StatusOr<std::unique_ptr<Sampler>> Create(std::shared_ptr<const TriangleMesh> mesh,
                                                         const MeshSamplerOptions& options = {});

  Vec3 Sample(Random& rng) const override;  // O(1): an alias draw and two NextDouble.
  // A draw reads a table cell, the face it names, then the face's corners, one cache miss after
  // the other on a large mesh: loaded over three calls, one Basic Step apart.
  void PrefetchSample(const Random& rng) const override;
  bool empty() const override { return false; }
  BoundingBox Bounds() const override { return bounds_; }  // Of the vertices used by faces.
  const TriangleMesh& mesh() const { return *mesh_; }

 private:
  MeshSampler(std::shared_ptr<const TriangleMesh> mesh, AliasTable table,
              const BoundingBox& bounds);

  std::shared_ptr<const TriangleMesh> mesh_;
  AliasTable table_;
  BoundingBox bounds_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_MESH_SAMPLER_H_
