#include "core/analysis/triangle_tree.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/analysis/closest_point_triangle.h"
#include "core/morton_code.h"

namespace neuralmesh {
namespace {

constexpr uint32_t kLeafSize = 4;
// A median split halves the count at every level, so the depth stays below 32 for 32-bit
// triangle counts and a traversal never holds more than depth + 1 pending nodes.
constexpr int kMaxStack = 64;

Vec3 ToVec3(const Vec3f& v) { return Vec3(v[0], v[1], v[2]); }

struct Box {
  float lo[3] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                 std::numeric_limits<float>::infinity()};
  float hi[3] = {-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                 -std::numeric_limits<float>::infinity()};
  void Extend(const float* p) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], p[i]);
      hi[i] = std::max(hi[i], p[i]);
    }
  }
};

// Distance from x to the interval [lo, hi]; 0 inside. Branch-free (at most one term is
// positive): the comparisons of a traversal are too random to predict.
inline double IntervalDistance(double x, double lo, double hi) {
  return std::max(lo - x, 0.0) + std::max(x - hi, 0.0);
}

// Squared distance from p to the box [lo, hi]; 0 inside.
inline double BoxDistance2(const float* lo, const float* hi, const double* p) {
  const double dx = IntervalDistance(p[0], lo[0], hi[0]);
  const double dy = IntervalDistance(p[1], lo[1], hi[1]);
  const double dz = IntervalDistance(p[2], lo[2], hi[2]);
  return dx * dx + dy * dy + dz * dz;
}

// Squared distance from p to the bounding box of triangle abc: a cheap lower bound that
// spares most exact tests inside a leaf.
inline double TriangleBoxDistance2(const Vec3f& a, const Vec3f& b, const Vec3f& c,
                                   const double* p) {
  float lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    lo[i] = std::min(std::min(a[i], b[i]), c[i]);
    hi[i] = std::max(std::max(a[i], b[i]), c[i]);
  }
  return BoxDistance2(lo, hi, p);
}

// The faces of `mesh` without repeats, in index order: of the faces with the same corner
// positions in the same cyclic order, the first. A box is nearer to a point off the plane of
// its triangle than the triangle is, so copies of a triangle never prune each other and a
// query used to test every copy: a reference of 5,000 copies of one face took 85 s to
// evaluate. Copies give the same distances, and the first gives the same face as before.
// (A copy of opposite orientation is kept: its normal differs.) O(f log f).
std::vector<uint32_t> DistinctFaces(const TriangleMesh& mesh) {
  using Key = std::array<float, 9>;
  const size_t n = mesh.faces.size();
  std::vector<Key> keys(n);
  for (size_t f = 0; f < n; ++f) {
    std::array<Vec3f, 3> corners;
    for (int i = 0; i < 3; ++i) corners[i] = mesh.positions[mesh.faces[f][i]];
    const auto less = [](const Vec3f& a, const Vec3f& b) {
      return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
    };
    // The cyclic rotation that starts at the smallest corner.
    const int first =
        static_cast<int>(std::min_element(corners.begin(), corners.end(), less) - corners.begin());
    for (int i = 0; i < 3; ++i) {
      const Vec3f& c = corners[(first + i) % 3];
      for (int j = 0; j < 3; ++j) keys[f][3 * i + j] = c[j];
    }
  }
  std::vector<uint32_t> order(n);
  for (size_t f = 0; f < n; ++f) order[f] = static_cast<uint32_t>(f);
  std::sort(order.begin(), order.end(), [&keys](uint32_t a, uint32_t b) {
    return keys[a] != keys[b] ? keys[a] < keys[b] : a < b;
  });
  std::vector<uint32_t> kept;
  kept.reserve(n);
  for (size_t k = 0; k < n; ++k) {
    if (k == 0 || keys[order[k]] != keys[order[k - 1]]) kept.push_back(order[k]);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

}  // namespace

absl::StatusOr<TriangleTree> TriangleTree::Build(const TriangleMesh& mesh) {
  const size_t n = mesh.faces.size();
  if (n == 0) return absl::InvalidArgumentError("TriangleTree: the mesh has no faces");
  if (n > std::numeric_limits<uint32_t>::max()) {
    return absl::InvalidArgumentError(
        absl::StrCat("TriangleTree: ", n, " faces exceed the 32-bit face index"));
  }
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3f& p = mesh.positions[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return absl::InvalidArgumentError(
          absl::StrCat("TriangleTree: position ", i, " is not finite"));
    }
  }
  const size_t num_positions = mesh.positions.size();
  for (size_t f = 0; f < n; ++f) {
    for (uint32_t v : mesh.faces[f]) {
      if (v >= num_positions) {
        return absl::InvalidArgumentError(absl::StrCat(
            "TriangleTree: face ", f, " refers to vertex ", v, " of only ", num_positions));
      }
    }
  }

  // Triangles are reordered in place as compact (centroid, face) items, so every pass of
  // the build reads contiguous memory; node boxes are formed bottom-up from the children.
  struct Item {
    float centroid[3];
    uint32_t face;
  };
  const std::vector<uint32_t> kept = DistinctFaces(mesh);
  const size_t m = kept.size();
  std::vector<Item> items(m);
  for (size_t k = 0; k < m; ++k) {
    Box box;
    for (uint32_t v : mesh.faces[kept[k]]) box.Extend(mesh.positions[v].data());
    for (int i = 0; i < 3; ++i) items[k].centroid[i] = 0.5f * (box.lo[i] + box.hi[i]);
    items[k].face = kept[k];
  }

  TriangleTree tree;
  tree.nodes_.reserve(m);  // Leaves hold at least 2 triangles, so nodes < m.
  tree.triangles_.resize(m);
  // Recursion depth is bounded by log2(n) (median split). Returns the node's index.
  auto build = [&](auto&& self, uint32_t begin, uint32_t end) -> uint32_t {
    const uint32_t index = static_cast<uint32_t>(tree.nodes_.size());
    tree.nodes_.emplace_back();
    Box box;
    if (end - begin <= kLeafSize) {
      for (uint32_t i = begin; i < end; ++i) {
        const auto& f = mesh.faces[items[i].face];
        Triangle& t = tree.triangles_[i];
        t = {mesh.positions[f[0]], mesh.positions[f[1]], mesh.positions[f[2]], items[i].face};
        box.Extend(t.a.data());
        box.Extend(t.b.data());
        box.Extend(t.c.data());
      }
      Node& node = tree.nodes_[index];
      std::copy(box.lo, box.lo + 3, node.lo);
      std::copy(box.hi, box.hi + 3, node.hi);
      node.first_or_second = begin;
      node.count = end - begin;
      return index;
    }
    Box centroids;
    for (uint32_t i = begin; i < end; ++i) centroids.Extend(items[i].centroid);
    int axis = 0;
    for (int i = 1; i < 3; ++i) {
      if (centroids.hi[i] - centroids.lo[i] > centroids.hi[axis] - centroids.lo[axis]) axis = i;
    }
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(
        items.begin() + begin, items.begin() + mid, items.begin() + end,
        [axis](const Item& x, const Item& y) { return x.centroid[axis] < y.centroid[axis]; });
    const uint32_t left = self(self, begin, mid);
    const uint32_t right = self(self, mid, end);
    for (uint32_t child : {left, right}) {
      box.Extend(tree.nodes_[child].lo);
      box.Extend(tree.nodes_[child].hi);
    }
    Node& node = tree.nodes_[index];
    std::copy(box.lo, box.lo + 3, node.lo);
    std::copy(box.hi, box.hi + 3, node.hi);
    node.first_or_second = right;
    node.count = 0;
    return index;
  };
  build(build, 0, static_cast<uint32_t>(m));

  const Node& root = tree.nodes_[0];
  tree.bounds_.Extend(Vec3(root.lo[0], root.lo[1], root.lo[2]));
  tree.bounds_.Extend(Vec3(root.hi[0], root.hi[1], root.hi[2]));
  return tree;
}

TriangleTree::ClosestPointResult TriangleTree::ClosestPointOrWithin(const Vec3& p,
                                                                    double radius) const {
  ClosestPointResult result{std::numeric_limits<double>::infinity(), p, 0};
  double best_d2 = std::numeric_limits<double>::infinity();
  const double stop_d2 = radius > 0.0 ? radius * radius : 0.0;
  struct Entry {
    uint32_t node;
    double d2;
  };
  Entry stack[kMaxStack];
  int top = 0;
  const double q[3] = {p[0], p[1], p[2]};
  stack[top++] = {0, BoxDistance2(nodes_[0].lo, nodes_[0].hi, q)};
  while (top > 0) {
    const Entry entry = stack[--top];
    // Written as !(a < b) so a NaN query prunes everything.
    if (!(entry.d2 < best_d2)) continue;
    const Node& node = nodes_[entry.node];
    if (node.count > 0) {
      for (uint32_t i = node.first_or_second; i < node.first_or_second + node.count; ++i) {
        const Triangle& t = triangles_[i];
        if (!(TriangleBoxDistance2(t.a, t.b, t.c, q) < best_d2)) continue;
        const Vec3 x = ClosestPointOnTriangle(p, ToVec3(t.a), ToVec3(t.b), ToVec3(t.c)).point;
        const double d2 = (p - x).sqrnorm();
        if (d2 < best_d2) {
          best_d2 = d2;
          result.point = x;
          result.face = t.face;
        }
      }
      if (best_d2 <= stop_d2) break;
      continue;
    }
    const Node& left = nodes_[entry.node + 1];
    const Node& right = nodes_[node.first_or_second];
    Entry near{entry.node + 1, BoxDistance2(left.lo, left.hi, q)};
    Entry far{node.first_or_second, BoxDistance2(right.lo, right.hi, q)};
    if (far.d2 < near.d2) std::swap(near, far);
    if (far.d2 < best_d2) stack[top++] = far;
    if (near.d2 < best_d2) stack[top++] = near;
  }
  if (best_d2 < std::numeric_limits<double>::infinity()) result.distance = std::sqrt(best_d2);
  return result;
}

std::vector<TriangleTree::ClosestPointResult> TriangleTree::ClosestPoints(
    absl::Span<const Vec3> points, const BatchOptions& options) const {
  std::vector<ClosestPointResult> results(points.size());
  // Queries run in Z-order: consecutive queries then walk the same part of the tree, which
  // stays in cache. In random order almost every node and leaf visited is a cache miss, and
  // batches of random samples are several times slower. The order does not change results.
  std::vector<std::pair<uint64_t, size_t>> order(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    order[i] = {MortonCode(points[i], bounds_.min, bounds_.max), i};
  }
  std::sort(order.begin(), order.end());

  constexpr size_t kBlock = 1024;
  size_t workers = options.threads > 0 ? static_cast<size_t>(options.threads)
                                       : std::max(1u, std::thread::hardware_concurrency());
  workers = std::min(workers, (points.size() + kBlock - 1) / kBlock);
  // Blocks are handed out dynamically because query cost varies across space; each result
  // slot is written by exactly one thread, so the output does not depend on the schedule.
  std::atomic<size_t> next_block{0};
  auto work = [&] {
    while (true) {
      const size_t begin = next_block.fetch_add(kBlock, std::memory_order_relaxed);
      if (begin >= points.size()) return;
      const size_t end = std::min(points.size(), begin + kBlock);
      for (size_t i = begin; i < end; ++i) {
        const size_t index = order[i].second;
        results[index] = ClosestPointOrWithin(points[index], options.radius);
      }
    }
  };
  std::vector<std::thread> pool;
  for (size_t i = 1; i < workers; ++i) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  return results;
}

}  // namespace neuralmesh
