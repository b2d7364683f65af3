#include "core/learning/vertex_ring_cache.h"

#include <algorithm>

namespace neuralmesh {

bool VertexRingCache::AppendRing(const Mesh& mesh, int v, std::vector<int>& out) {
  if (static_cast<size_t>(v) >= lines_.size()) {
    lines_.resize(std::max<size_t>(static_cast<size_t>(v) + 1, lines_.size() * 3 / 2));
  }
  Line& line = lines_[v];
  if (line.epoch == current_epoch_) {
    out.insert(out.end(), line.neighbours, line.neighbours + line.valence);
    return line.boundary != 0;
  }
  // A raw half-edge walk: OpenMesh's circulators cost several times more.
  const Mesh::VertexHandle vh(v);
  const bool boundary = mesh.is_boundary(vh);
  const size_t first = out.size();
  const Mesh::HalfedgeHandle start = mesh.halfedge_handle(vh);
  Mesh::HalfedgeHandle h = start;
  do {
    out.push_back(mesh.to_vertex_handle(h).idx());
    h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
  } while (h != start);
  const size_t valence = out.size() - first;
  if (valence <= static_cast<size_t>(kSlots)) {
    std::copy(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(), line.neighbours);
    line.valence = static_cast<uint16_t>(valence);
    line.boundary = boundary ? 1 : 0;
    line.epoch = current_epoch_;
  }
  return boundary;
}

void VertexRingCache::InvalidateAll() {
  if (++current_epoch_ == 0) {  // Wrapped: no line may look current by accident.
    for (Line& line : lines_) line.epoch = 0;
    current_epoch_ = 1;
  }
}

}  // namespace neuralmesh
