// Merges vertices at identical positions, for the formats that store triangles with their own
// corners (STL) or split vertices at seams of other attributes (glTF).
#ifndef NEURALMESH_CORE_IO_INTERNAL_VERTEX_MERGER_H_
#define NEURALMESH_CORE_IO_INTERNAL_VERTEX_MERGER_H_

#include <array>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/mesh.h"

namespace neuralmesh::io_internal {

// Gives each distinct position one index, appending the new ones to `positions`. Keys are bit
// patterns, with -0 folded onto +0. `Point` is Vec3f, or Point3d (position_collector.h) for
// positions not yet narrowed to floats.
template <typename Point>
class VertexMergerOf {
 public:
  explicit VertexMergerOf(std::vector<Point>* positions) : positions_(positions) {}

  uint32_t Add(const Point& p) {
    Key key;
    for (int c = 0; c < 3; ++c) {
      const Scalar value = p[c] == 0 ? Scalar{0} : p[c];
      std::memcpy(&key[c], &value, sizeof(Scalar));
    }
    const auto [it, inserted] = index_.emplace(key, static_cast<uint32_t>(positions_->size()));
    if (inserted) positions_->push_back(p);
    return it->second;
  }

 private:
  using Scalar = std::remove_cv_t<std::remove_reference_t<decltype(std::declval<Point&>()[0])>>;
  using Bits = std::conditional_t<sizeof(Scalar) == 8, uint64_t, uint32_t>;
  using Key = std::array<Bits, 3>;
  struct KeyHash {
    size_t operator()(const Key& k) const {
      uint64_t h = k[0];
      h = h * 0x9E3779B97F4A7C15ull ^ k[1];
      h = h * 0x9E3779B97F4A7C15ull ^ k[2];
      return static_cast<size_t>(h ^ (h >> 29));
    }
  };
  std::vector<Point>* positions_;
  std::unordered_map<Key, uint32_t, KeyHash> index_;
};

using VertexMerger = VertexMergerOf<Vec3f>;

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_VERTEX_MERGER_H_
