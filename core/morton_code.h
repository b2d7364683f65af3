// Morton (Z-order) codes: positions quantised to 2^21 cells per axis of a box, their bits
// interleaved (x in bit 0, y in bit 1, z in bit 2, ...), so that sorting by code puts points
// that are close in space close together. Used to order the triangle tree's build
// (core/analysis/triangle_tree.h) and the learner's vertices (morton_vertex_order.h).
#ifndef NEURALMESH_CORE_MORTON_CODE_H_
#define NEURALMESH_CORE_MORTON_CODE_H_

#include <cstdint>

#include "core/mesh.h"

namespace neuralmesh {

// The Morton code of `p` in the grid of 2^21 cells per axis over [min, max] (per axis;
// coordinates outside are clamped, NaN counts as the minimum, a flat axis as cell 0).
uint64_t MortonCode(const Vec3& p, const Vec3& min, const Vec3& max);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_MORTON_CODE_H_
