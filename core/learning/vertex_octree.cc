#include "core/learning/vertex_octree.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace neuralmesh {
namespace {

constexpr int kMaxDepth = 40;

double Sq(double x) { return x * x; }

}  // namespace

VertexOctree::VertexOctree(const BoundingBox& initial_box, int bucket_size)
    : bucket_size_(std::max(2, bucket_size)) {
  Vec3 center(0, 0, 0);
  double half = 1;
  if (!initial_box.empty()) {
    center = initial_box.center();
    const Vec3 extent = initial_box.max - initial_box.min;
    half = std::max({extent[0], extent[1], extent[2]}) * 0.5 * 1.01;
    if (!(half > 0) || !std::isfinite(half)) half = 1;
  }
  root_ = NewNode(center, half, -1);
}

int VertexOctree::NewNode(const Vec3& center, double half, int parent) {
  int n;
  if (!free_nodes_.empty()) {
    n = free_nodes_.back();
    free_nodes_.pop_back();
    nodes_[n] = Node();
  } else {
    n = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
  }
  Node& node = nodes_[n];
  node.center = center;
  node.half = half;
  node.parent = parent;
  return n;
}

void VertexOctree::FreeNode(int n) {
  nodes_[n].items.clear();
  nodes_[n].items.shrink_to_fit();
  free_nodes_.push_back(n);
}

bool VertexOctree::InCube(const Node& node, const Vec3& p) const {
  return std::abs(p[0] - node.center[0]) <= node.half &&
         std::abs(p[1] - node.center[1]) <= node.half &&
         std::abs(p[2] - node.center[2]) <= node.half;
}

int VertexOctree::Octant(const Node& node, const Vec3& p) const {
  return (p[0] >= node.center[0] ? 1 : 0) | (p[1] >= node.center[1] ? 2 : 0) |
         (p[2] >= node.center[2] ? 4 : 0);
}

void VertexOctree::GrowRootToward(const Vec3& p) {
  // The new root doubles the old one; the old root becomes the child on the far side of p.
  const Node old = nodes_[root_];
  Vec3 center;
  int octant = 0;
  for (int i = 0; i < 3; ++i) {
    const bool up = p[i] >= old.center[i];
    center[i] = old.center[i] + (up ? old.half : -old.half);
    if (!up) octant |= (1 << i);
  }
  const int old_root = root_;
  root_ = NewNode(center, old.half * 2, -1);
  Node& root = nodes_[root_];
  root.leaf = false;
  root.count = nodes_[old_root].count;
  root.children[octant] = old_root;
  nodes_[old_root].parent = root_;
}

void VertexOctree::Insert(int id, const Vec3& p) {
  if (id >= static_cast<int>(leaf_of_.size())) {
    const size_t n = static_cast<size_t>(id) + 1;
    leaf_of_.resize(n, -1);
    slot_.resize(n, -1);
    position_.resize(n);
  }
  if (leaf_of_[id] >= 0) Remove(id);
  position_[id] = p;
  for (int guard = 0; !InCube(nodes_[root_], p) && guard < 2048; ++guard) GrowRootToward(p);
  InsertIntoTree(id);
  ++size_;
}

int VertexOctree::ChildToward(int n, const Vec3& p) {
  const int o = Octant(nodes_[n], p);
  int child = nodes_[n].children[o];
  if (child < 0) {
    const double h = nodes_[n].half * 0.5;
    const Vec3& center = nodes_[n].center;
    const Vec3 c(center[0] + ((o & 1) ? h : -h), center[1] + ((o & 2) ? h : -h),
                 center[2] + ((o & 4) ? h : -h));
    child = NewNode(c, h, n);
    nodes_[n].children[o] = child;
  }
  return child;
}

void VertexOctree::InsertIntoTree(int id) {
  const Vec3& p = position_[id];
  int n = root_;
  int depth = 0;
  while (true) {
    Node& node = nodes_[n];
    ++node.count;
    if (node.leaf) break;
    n = ChildToward(n, p);  // May reallocate nodes_: `node` is not used after this.
    ++depth;
  }
  Node& leaf = nodes_[n];
  leaf_of_[id] = n;
  slot_[id] = static_cast<int>(leaf.items.size());
  leaf.items.push_back(id);
  if (static_cast<int>(leaf.items.size()) > bucket_size_ && depth < kMaxDepth) SplitLeaf(n);
}

void VertexOctree::SplitLeaf(int n) {
  std::vector<int> items;
  items.swap(nodes_[n].items);
  nodes_[n].leaf = false;
  nodes_[n].count -= static_cast<int>(items.size());
  // Re-insert below n: walk down from n only.
  for (int id : items) {
    const Vec3& p = position_[id];
    int m = n;
    while (true) {
      Node& node = nodes_[m];
      ++node.count;
      if (node.leaf) break;
      m = ChildToward(m, p);
    }
    leaf_of_[id] = m;
    slot_[id] = static_cast<int>(nodes_[m].items.size());
    nodes_[m].items.push_back(id);
  }
  // A child that received everything (all points in one octant) splits again on next insert.
}

void VertexOctree::Remove(int id) {
  if (!Contains(id)) return;
  const int n = leaf_of_[id];
  Node& leaf = nodes_[n];
  const int s = slot_[id];
  const int last = leaf.items.back();
  leaf.items[s] = last;
  slot_[last] = s;
  leaf.items.pop_back();
  leaf_of_[id] = -1;
  slot_[id] = -1;
  --size_;
  // Update counts upward and merge the highest ancestor whose subtree became small.
  int merge_at = -1;
  for (int m = n; m >= 0; m = nodes_[m].parent) {
    --nodes_[m].count;
    if (!nodes_[m].leaf && nodes_[m].count <= bucket_size_ / 2) merge_at = m;
  }
  if (merge_at >= 0) CollapseSubtree(merge_at);
}

void VertexOctree::GatherItems(int n, std::vector<int>& out) {
  Node& node = nodes_[n];
  if (node.leaf) {
    out.insert(out.end(), node.items.begin(), node.items.end());
    return;
  }
  for (int c : node.children) {
    if (c >= 0) GatherItems(c, out);
  }
}

void VertexOctree::CollapseSubtree(int n) {
  std::vector<int> items;
  GatherItems(n, items);
  // Free every descendant.
  std::vector<int> stack;
  for (int c : nodes_[n].children) {
    if (c >= 0) stack.push_back(c);
  }
  while (!stack.empty()) {
    const int m = stack.back();
    stack.pop_back();
    for (int c : nodes_[m].children) {
      if (c >= 0) stack.push_back(c);
    }
    FreeNode(m);
  }
  Node& node = nodes_[n];
  std::fill(std::begin(node.children), std::end(node.children), -1);
  node.leaf = true;
  node.items = std::move(items);
  for (size_t i = 0; i < node.items.size(); ++i) {
    leaf_of_[node.items[i]] = n;
    slot_[node.items[i]] = static_cast<int>(i);
  }
}

void VertexOctree::Move(int id, const Vec3& p) {
  const int n = leaf_of_[id];
  if (n >= 0 && InCube(nodes_[n], p)) {
    position_[id] = p;
    return;
  }
  Remove(id);
  Insert(id, p);
}

int VertexOctree::Nearest(const Vec3& q) const {
  if (size_ == 0) return -1;
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  Search(root_, q, best, best_d2);
  return best;
}

void VertexOctree::Search(int n, const Vec3& q, int& best, double& best_d2) const {
  const Node& node = nodes_[n];
  if (node.leaf) {
    for (int id : node.items) {
      const Vec3& p = position_[id];
      const double d2 = Sq(p[0] - q[0]) + Sq(p[1] - q[1]) + Sq(p[2] - q[2]);
      if (d2 < best_d2) {
        best_d2 = d2;
        best = id;
      }
    }
    return;
  }
  // The octant holding q first: it most likely holds the answer and tightens the bound.
  const int first = Octant(node, q);
  if (node.children[first] >= 0 && nodes_[node.children[first]].count > 0) {
    Search(node.children[first], q, best, best_d2);
  }
  for (int o = 0; o < 8; ++o) {
    const int c = node.children[o];
    if (o == first || c < 0) continue;
    const Node& child = nodes_[c];
    if (child.count == 0) continue;
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double d = std::abs(q[i] - child.center[i]) - child.half;
      if (d > 0) d2 += d * d;
    }
    if (d2 < best_d2) Search(c, q, best, best_d2);
  }
}

int VertexOctree::Depth() const { return DepthOf(root_); }

int VertexOctree::DepthOf(int n) const {
  const Node& node = nodes_[n];
  if (node.leaf) return 0;
  int d = 0;
  for (int c : node.children) {
    if (c >= 0) d = std::max(d, 1 + DepthOf(c));
  }
  return d;
}

}  // namespace neuralmesh
