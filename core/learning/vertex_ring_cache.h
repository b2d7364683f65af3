// The neighbours of each vertex in rotation order, copied out of the half-edge structure into
// one cache line per vertex.
//
// The Basic Step's smoothing (tangential_smoothing.h) reads the rings of the winner and of its
// neighbours: seven rings per step. Walking them through OpenMesh's half-edges is a chain of
// dependent loads (opposite, next, to-vertex) per neighbour, and was the largest single cost
// of the learner. Connectivity changes only every C_vs Basic Steps (a split) or in the rare
// Steps 3-5, so the rings are cached and invalidated by whoever changes the connectivity:
// Invalidate(v) for the vertices whose ring changed, InvalidateAll() after bulk changes
// (collapses, removals, merges, garbage collection). A stale ring is rebuilt on its next use.
#ifndef NEURALMESH_CORE_LEARNING_VERTEX_RING_CACHE_H_
#define NEURALMESH_CORE_LEARNING_VERTEX_RING_CACHE_H_

#include <cstdint>
#include <vector>

#include "core/huge_page_allocator.h"
#include "core/mesh.h"

namespace neuralmesh {

class VertexRingCache {
 public:
  // Appends the neighbours of `v` (a live vertex with at least one edge) to `out` in
  // rotation order; a boundary vertex's list starts at the end of its outgoing boundary
  // half-edge and ends at the start of its incoming one. Returns whether `v` is on the
  // boundary. Amortised O(valence) with one cache line read when the ring is cached.
  bool AppendRing(const Mesh& mesh, int v, std::vector<int>& out);

  // The same ring without a copy: `neighbours` points into the cache (or, for a ring too long
  // to cache, into scratch storage) and stays valid until the next call of Ring or
  // AppendRing, or the next invalidation.
  struct RingView {
    const int32_t* neighbours;
    int size;
    bool boundary;
  };
  RingView Ring(const Mesh& mesh, int v) {
    const RingView cached = CachedRing(v);
    return cached.neighbours != nullptr ? cached : Walk(mesh, v);
  }
  // The cached ring of `v` without walking the half-edges when it is not cached: then
  // `neighbours` is null and `size` 0. Valid as Ring's views are.
  RingView CachedRing(int v) const {
    if (static_cast<size_t>(v) < lines_.size()) {
      const Line& line = lines_[v];
      if (line.epoch == current_epoch_) return {line.neighbours, line.valence, line.boundary != 0};
    }
    return {nullptr, 0, false};
  }
  // A hint: starts loading the cached ring of `v`, for a caller about to read several rings.
  void Prefetch(int v) const {
    if (static_cast<size_t>(v) < lines_.size()) __builtin_prefetch(&lines_[v]);
  }

  // Marks the ring of `v` stale. Call it for every vertex whose set or order of neighbours
  // changed, or whose boundary status did.
  void Invalidate(int v) {
    if (static_cast<size_t>(v) < lines_.size()) lines_[v].epoch = 0;
  }
  // Marks every ring stale, in O(1).
  void InvalidateAll();

 private:
  // Reads the ring of `v` from the half-edges and caches it if it fits.
  RingView Walk(const Mesh& mesh, int v);

  // Rings of up to kSlots neighbours are cached; a vertex of higher valence (rare: the
  // learner keeps valences near 6) is walked every time.
  static constexpr int kSlots = 14;
  struct alignas(64) Line {
    uint32_t epoch = 0;  // Valid when equal to current_epoch_; 0 is never current.
    uint16_t valence = 0;
    uint16_t boundary = 0;
    int32_t neighbours[kSlots];
  };
  static_assert(sizeof(Line) == 64, "one cache line per vertex");

  HugePageVector<Line> lines_;         // Indexed by vertex index.
  std::vector<int32_t> long_ring_;  // The last ring too long for a line.
  uint32_t current_epoch_ = 1;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_VERTEX_RING_CACHE_H_
