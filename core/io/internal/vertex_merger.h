// Merges vertices at identical positions, for the formats that store triangles with their own
// corners (STL) or split vertices at seams of other attributes (glTF).
#ifndef NEURALMESH_CORE_IO_INTERNAL_VERTEX_MERGER_H_
#define NEURALMESH_CORE_IO_INTERNAL_VERTEX_MERGER_H_

#include <array>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <vector>

#include "core/mesh.h"

namespace neuralmesh::io_internal {

// Gives each distinct position one index, appending the new ones to `positions`. Keys are bit
// patterns, with -0 folded onto +0.
class VertexMerger {
 public:
  explicit VertexMerger(std::vector<Vec3f>* positions) : positions_(positions) {}

  uint32_t Add(const Vec3f& p) {
    std::array<uint32_t, 3> key;
    for (int c = 0; c < 3; ++c) {
      const float value = p[c] == 0.0f ? 0.0f : p[c];
      std::memcpy(&key[c], &value, sizeof(float));
    }
    const auto [it, inserted] = index_.emplace(key, static_cast<uint32_t>(positions_->size()));
    if (inserted) positions_->push_back(p);
    return it->second;
  }

 private:
  struct KeyHash {
    size_t operator()(const std::array<uint32_t, 3>& k) const {
      uint64_t h = k[0];
      h = h * 0x9E3779B97F4A7C15ull ^ k[1];
      h = h * 0x9E3779B97F4A7C15ull ^ k[2];
      return static_cast<size_t>(h ^ (h >> 29));
    }
  };
  std::vector<Vec3f>* positions_;
  std::unordered_map<std::array<uint32_t, 3>, uint32_t, KeyHash> index_;
};

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_VERTEX_MERGER_H_
