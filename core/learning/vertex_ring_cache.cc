#include "core/learning/vertex_ring_cache.h"

#include <algorithm>

namespace neuralmesh {

VertexRingCache::RingView VertexRingCache::Walk(const Mesh& mesh, int v) {
  if (static_cast<size_t>(v) >= lines_.size()) {
    lines_.resize(std::max<size_t>(static_cast<size_t>(v) + 1, lines_.size() * 3 / 2));
  }
  Line& line = lines_[v];
  // A raw half-edge walk: OpenMesh's circulators cost several times more.
  const Mesh::VertexHandle vh(v);
  const bool boundary = mesh.is_boundary(vh);
  long_ring_.clear();
  WalkNeighbours(mesh, vh, long_ring_);
  const int valence = static_cast<int>(long_ring_.size());
  if (valence > kLongestCachedRing) return {long_ring_.data(), valence, boundary};
  line.valence = static_cast<uint8_t>(valence);
  line.boundary = boundary ? 1 : 0;
  line.epoch = current_epoch_;
  if (valence <= kSlots) {
    std::copy(long_ring_.begin(), long_ring_.end(), line.neighbours);
    return {line.neighbours, valence, boundary};
  }
  // A ring stored again after an Invalidate leaves its old copy in overflow_ until the next
  // InvalidateAll: few rings are long, and connectivity changes only at splits in between.
  line.neighbours[0] = static_cast<int32_t>(overflow_.size());
  overflow_.insert(overflow_.end(), long_ring_.begin(), long_ring_.end());
  return {&overflow_[line.neighbours[0]], valence, boundary};
}

bool VertexRingCache::AppendRing(const Mesh& mesh, int v, std::vector<int>& out) {
  const RingView ring = Ring(mesh, v);
  out.insert(out.end(), ring.neighbours, ring.neighbours + ring.size);
  return ring.boundary;
}

void VertexRingCache::InvalidateAll() {
  overflow_.clear();
  if (++current_epoch_ == 0) {  // Wrapped: no line may look current by accident.
    for (Line& line : lines_) line.epoch = 0;
    current_epoch_ = 1;
  }
}

}  // namespace neuralmesh
