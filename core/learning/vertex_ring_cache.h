// The neighbours of each vertex in rotation order, copied out of the half-edge structure into
// half a cache line per vertex.
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

// Appends the neighbours of `v` (a live vertex with at least one edge) to `out` in rotation
// order, walking its half-edges: the order of VertexRingCache's rings (for a boundary vertex,
// from the end of its outgoing boundary half-edge, which OpenMesh keeps as the vertex's own).
template <typename Out>
void WalkNeighbours(const Mesh& mesh, Mesh::VertexHandle v, Out& out) {
  const Mesh::HalfedgeHandle start = mesh.halfedge_handle(v);
  Mesh::HalfedgeHandle h = start;
  do {
    out.push_back(mesh.to_vertex_handle(h).idx());
    h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
  } while (h != start);
}

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
      if (line.epoch == current_epoch_) {
        const int32_t* neighbours =
            line.valence <= kSlots ? line.neighbours : &overflow_[line.neighbours[0]];
        return {neighbours, line.valence, line.boundary != 0};
      }
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

  // A line holds rings of up to kSlots neighbours: 99% of the vertices of a learned mesh
  // (valences 4 to 7). A longer ring (up to 255) is kept in overflow_, the line holding its
  // offset there; overflow_ is emptied with InvalidateAll. Two lines share a cache line, so
  // the cache of a 100K-vertex mesh takes 3.2 MB, half of what one line per vertex would.
  static constexpr int kSlots = 7;
  static constexpr int kLongestCachedRing = 255;
  struct alignas(32) Line {
    uint16_t epoch = 0;  // Valid when equal to current_epoch_; 0 is never current.
    uint8_t valence = 0;
    uint8_t boundary = 0;
    int32_t neighbours[kSlots];  // Or, for a longer ring, neighbours[0]: its offset in overflow_.
  };
  static_assert(sizeof(Line) == 32, "two lines per cache line");

  HugePageVector<Line> lines_;      // Indexed by vertex index.
  std::vector<int32_t> overflow_;   // The cached rings longer than kSlots.
  std::vector<int32_t> long_ring_;  // The last ring too long to cache.
  uint16_t current_epoch_ = 1;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_VERTEX_RING_CACHE_H_
