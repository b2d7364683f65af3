#include "core/learning/vertex_octree.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/avx2_clone.h"

namespace neuralmesh {
namespace {

// Splitting stops here: only (nearly) coincident points get this deep, and they go into
// chained buckets instead.
constexpr int kMaxDepth = 40;

bool InCube(const double center[3], double half, const double p[3]) {
  return std::abs(p[0] - center[0]) <= half && std::abs(p[1] - center[1]) <= half &&
         std::abs(p[2] - center[2]) <= half;
}

int Octant(const double center[3], const double p[3]) {
  return (p[0] >= center[0] ? 1 : 0) | (p[1] >= center[1] ? 2 : 0) | (p[2] >= center[2] ? 4 : 0);
}

// The centre of child `octant` of the cube (center, half). Every cube below the root is
// computed by this one expression from its parent's stored centre, so that routing a point
// down the tree and bounding a subtree during a search agree to the last bit.
// (Multiplying by +-1 is exact and, unlike a conditional, compiles without a branch.)
void ChildCenter(const double center[3], double half, int octant, double out[3]) {
  static constexpr double kSign[2] = {-1.0, 1.0};
  const double h = half * 0.5;
#pragma GCC unroll 3
  for (int i = 0; i < 3; ++i) out[i] = center[i] + h * kSign[(octant >> i) & 1];
}

// max(x, 0) without a branch (exact: x + |x| is 2x or 0).
double PositivePart(double x) { return (x + std::abs(x)) * 0.5; }

// The bits of a non-negative double, which order like the values: comparing them compiles to
// conditional moves where comparing doubles would compile to an unpredictable branch.
uint64_t OrderedBits(double x) {
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return bits;
}

// The first shape of a new octree: its own range of 2^32 values, so that no descent taken in
// another octree (the learner replaces its octree at every Step 3) can match it.
uint64_t NewShapeRange() {
  static std::atomic<uint64_t> next{0};
  return next.fetch_add(uint64_t{1} << 32, std::memory_order_relaxed);
}

struct SearchEntry {
  int node;
  double d2;  // Squared distance from the query to the node's cube.
};
constexpr int kInlineSearchEntries = 256;

// Moves the search stack (`capacity` entries at *stack) to the heap with twice the room;
// returns the new capacity. Only trees deeper than about 30 levels need it.
int GrowSearchStack(int capacity, SearchEntry** stack, std::vector<SearchEntry>* heap) {
  std::vector<SearchEntry> bigger(2 * static_cast<size_t>(capacity));
  std::copy(*stack, *stack + capacity, bigger.begin());
  heap->swap(bigger);
  *stack = heap->data();
  return static_cast<int>(heap->size());
}

}  // namespace

VertexOctree::VertexOctree(const BoundingBox& initial_box, const std::vector<Vec3>* points,
                           int bucket_size)
    : points_(points), shape_(NewShapeRange()), bucket_size_(std::max(2, bucket_size)) {
  Vec3 center(0, 0, 0);
  double half = 1;
  if (!initial_box.empty()) {
    center = initial_box.center();
    const Vec3 extent = initial_box.max - initial_box.min;
    half = std::max({extent[0], extent[1], extent[2]}) * 0.5 * 1.01;
    if (!(half > 0) || !std::isfinite(half)) half = 1;
  }
  for (int i = 0; i < 3; ++i) root_center_[i] = center[i];
  root_half_ = half;
  // Block 0 holds only the root, in slot 0.
  blocks_.resize(1);
  Block& b = blocks_[0];
  for (int i = 0; i < 3; ++i) b.center[i] = root_center_[i];
  b.half = root_half_;
  b.parent = -1;
  b.next_free = -1;
  for (Node& n : b.nodes) n = Node{kEmpty, 0};
}

inline void VertexOctree::NodeCube(int n, double center[3], double* half) const {
  if (n == 0) {
    for (int i = 0; i < 3; ++i) center[i] = root_center_[i];
    *half = root_half_;
    return;
  }
  const Block& b = blocks_[n >> 3];
  ChildCenter(b.center, b.half, n & 7, center);
  *half = b.half * 0.5;
}

int VertexOctree::NewBlock(int parent, const double center[3], double half) {
  int b;
  if (free_blocks_ >= 0) {
    b = free_blocks_;
    free_blocks_ = blocks_[b].next_free;
  } else {
    b = static_cast<int>(blocks_.size());
    blocks_.emplace_back();
  }
  Block& block = blocks_[b];
  for (int i = 0; i < 3; ++i) block.center[i] = center[i];
  block.half = half;
  block.parent = parent;
  block.next_free = -1;
  for (Node& n : block.nodes) n = Node{kEmpty, 0};
  return b;
}

void VertexOctree::FreeBlock(int b) {
  blocks_[b].next_free = free_blocks_;
  free_blocks_ = b;
}

int VertexOctree::NewBucket() {
  int b;
  if (!free_buckets_.empty()) {
    b = free_buckets_.back();
    free_buckets_.pop_back();
  } else {
    b = static_cast<int>(bucket_next_.size());
    bucket_next_.push_back(-1);
    ids_.resize(ids_.size() + static_cast<size_t>(bucket_size_));
  }
  bucket_next_[b] = -1;
  return b;
}

void VertexOctree::FreeBucket(int b) { free_buckets_.push_back(b); }

void VertexOctree::AppendToLeaf(int n, int id) {
  if (node(n).child == kEmpty) node(n).child = LeafChild(NewBucket());
  int b = LeafBucket(node(n).child);
  int k = node(n).count;
  while (k >= bucket_size_) {
    if (bucket_next_[b] < 0) {
      const int chained = NewBucket();
      bucket_next_[b] = chained;
    }
    b = bucket_next_[b];
    k -= bucket_size_;
  }
  BucketIds(b)[k] = id;
  where_[id] = Location{b * bucket_size_ + k, n};
  ++node(n).count;
}

void VertexOctree::GrowRootToward(const double p[3]) {
  // The new root doubles the old one; the old root becomes the child on the far side of p.
  ++shape_;
  double center[3];
  int octant = 0;
  for (int i = 0; i < 3; ++i) {
    const bool up = p[i] >= root_center_[i];
    center[i] = root_center_[i] + (up ? root_half_ : -root_half_);
    if (!up) octant |= (1 << i);
  }
  const double half = root_half_ * 2;
  const Node old = node(0);
  const int block = NewBlock(0, center, half);
  const int m = block * 8 + octant;
  node(m) = old;
  if (old.child >= 0) {
    blocks_[old.child].parent = m;
  } else if (old.child != kEmpty) {
    int remaining = old.count;
    for (int b = LeafBucket(old.child); remaining > 0; b = bucket_next_[b]) {
      const int k = std::min(remaining, bucket_size_);
      for (int j = 0; j < k; ++j) where_[BucketIds(b)[j]].leaf = m;
      remaining -= k;
    }
  }
  node(0) = Node{block, old.count};
  // The old root's cube as a search derives it from the new root may be off by a rounding
  // error from the one its points were sorted by; searches widen every cube by that much.
  double derived[3];
  ChildCenter(center, half, octant, derived);
  for (int i = 0; i < 3; ++i) {
    slack_ = std::max(slack_, 2 * std::abs(derived[i] - root_center_[i]));
    root_center_[i] = center[i];
  }
  root_half_ = half;
}

void VertexOctree::Insert(int id) {
  if (id >= static_cast<int>(where_.size())) {
    where_.resize(static_cast<size_t>(id) + 1, Location{-1, -1});
  }
  if (Contains(id)) Remove(id);
  const double* pos = PointOf(id);
  for (int guard = 0; !InCube(root_center_, root_half_, pos) && guard < 2048; ++guard) {
    GrowRootToward(pos);
  }
  InsertIntoTree(id, pos);
  ++size_;
}

void VertexOctree::InsertIntoTree(int id, const double p[3]) {
  int n = 0;
  int depth = 0;
  while (true) {
    Node& nd = node(n);
    if (nd.child >= 0) {
      ++nd.count;
      n = nd.child * 8 + Octant(blocks_[nd.child].center, p);
      ++depth;
    } else if (nd.child != kEmpty && nd.count >= bucket_size_ && depth < kMaxDepth) {
      SplitLeaf(n);  // n is internal now; the next iteration descends into it.
    } else {
      AppendToLeaf(n, id);
      return;
    }
  }
}

void VertexOctree::SplitLeaf(int n) {
  ++shape_;
  scratch_.clear();
  GatherIds(n, scratch_);
  for (int b = LeafBucket(node(n).child); b >= 0; b = bucket_next_[b]) FreeBucket(b);
  double center[3], half;
  NodeCube(n, center, &half);
  const int block = NewBlock(n, center, half);
  node(n) = Node{block, static_cast<int32_t>(scratch_.size())};
  for (const int32_t id : scratch_) AppendToLeaf(block * 8 + Octant(center, PointOf(id)), id);
  // A child that received every point is full; the insertion that follows splits it again.
}

void VertexOctree::Remove(int id) {
  if (!Contains(id)) return;
  const int hole = where_[id].slot;
  const int n = where_[id].leaf;
  Node& leaf = node(n);
  // Fill the hole with the leaf's last id.
  const int head = LeafBucket(leaf.child);
  int last = head;
  int before_last = -1;
  int k = leaf.count - 1;
  while (k >= bucket_size_) {
    before_last = last;
    last = bucket_next_[last];
    k -= bucket_size_;
  }
  const int32_t moved = BucketIds(last)[k];
  ids_[hole] = moved;
  where_[moved].slot = hole;
  where_[id] = Location{-1, -1};
  if (k == 0 && before_last >= 0) {
    bucket_next_[before_last] = -1;
    FreeBucket(last);
  }
  if (--leaf.count == 0) {
    FreeBucket(head);
    leaf.child = kEmpty;
  }
  --size_;
  // Update counts upward and merge the highest ancestor whose subtree became small.
  int merge_at = -1;
  for (int m = Parent(n); m >= 0; m = Parent(m)) {
    if (--node(m).count <= bucket_size_ / 2) merge_at = m;
  }
  if (merge_at >= 0) CollapseSubtree(merge_at);
}

void VertexOctree::GatherIds(int n, std::vector<int32_t>& out) const {
  const Node& nd = node(n);
  if (nd.child >= 0) {
    for (int o = 0; o < 8; ++o) GatherIds(nd.child * 8 + o, out);
    return;
  }
  if (nd.child == kEmpty) return;
  int remaining = nd.count;
  for (int b = LeafBucket(nd.child); b >= 0 && remaining > 0; b = bucket_next_[b]) {
    const int m = std::min(remaining, bucket_size_);
    out.insert(out.end(), BucketIds(b), BucketIds(b) + m);
    remaining -= m;
  }
}

void VertexOctree::FreeSubtree(int n) {
  const Node nd = node(n);
  if (nd.child >= 0) {
    for (int o = 0; o < 8; ++o) FreeSubtree(nd.child * 8 + o);
    FreeBlock(nd.child);
  } else if (nd.child != kEmpty) {
    for (int b = LeafBucket(nd.child); b >= 0; b = bucket_next_[b]) FreeBucket(b);
  }
  node(n) = Node{kEmpty, 0};
}

void VertexOctree::CollapseSubtree(int n) {
  ++shape_;
  scratch_.clear();
  GatherIds(n, scratch_);
  FreeSubtree(n);
  for (const int32_t id : scratch_) AppendToLeaf(n, id);
}

// Move and Nearest, the octree's part of every Basic Step, are compiled for AVX2 as well as
// for the baseline (avx2_clone.h): the same arithmetic in fewer instructions.
NEURALMESH_AVX2_CLONE void VertexOctree::Move(int id) {
  if (Contains(id)) {
    double center[3], half;
    NodeCube(where_[id].leaf, center, &half);
    if (InCube(center, half, PointOf(id))) return;
  }
  Remove(id);
  Insert(id);
}

// Inlined into Descend and into both builds of Nearest.
__attribute__((always_inline)) inline int VertexOctree::DescendFrom(int n, const double q[3],
                                                                     int levels) const {
  for (int i = 0; i < levels && node(n).child >= 0; ++i) {
    const int block = node(n).child;
    n = block * 8 + Octant(blocks_[block].center, q);
  }
  return n;
}

void VertexOctree::Descend(const Vec3& q, int levels, OctreeDescent* descent) const {
  if (descent->node < 0 || descent->shape != shape_) *descent = OctreeDescent{0, shape_};
  const double qp[3] = {q[0], q[1], q[2]};
  const int n = DescendFrom(descent->node, qp, levels);
  descent->node = n;
  const Node& reached = node(n);
  if (reached.child >= 0) {
    const char* block = reinterpret_cast<const char*>(&blocks_[reached.child]);
    __builtin_prefetch(block);
    __builtin_prefetch(block + 64);
  } else if (reached.child != kEmpty) {
    const char* ids = reinterpret_cast<const char*>(BucketIds(LeafBucket(reached.child)));
    const size_t bytes =
        sizeof(int32_t) * static_cast<size_t>(std::min(reached.count, bucket_size_));
    for (size_t offset = 0; offset < bytes; offset += 64) __builtin_prefetch(ids + offset);
  }
}

void VertexOctree::PrefetchNearestPoints(const OctreeDescent& descent) const {
  if (!AtLeaf(descent)) return;
  const Node& leaf = node(descent.node);
  const int32_t* ids = BucketIds(LeafBucket(leaf.child));
  const int m = std::min(leaf.count, bucket_size_);
  for (int j = 0; j < m; ++j) __builtin_prefetch(PointOf(ids[j]));
}

// Inlined into both builds of Nearest.
__attribute__((always_inline)) inline void VertexOctree::ScanLeaf(const Node& leaf,
                                                                  const double q[3], int* best,
                                                                  double* best_d2) const {
  int remaining = leaf.count;
  int b = LeafBucket(leaf.child);
  int found = -1;
  // Squared distances are >= 0 (NaN only if coordinates overflow; then nothing is found).
  uint64_t found_bits = OrderedBits(*best_d2);
  while (true) {
    const int32_t* ids = BucketIds(b);
    const int m = std::min(remaining, bucket_size_);
    for (int j = 0; j < m; ++j) {
      const double* p = PointOf(ids[j]);
      const double dx = p[0] - q[0];
      const double dy = p[1] - q[1];
      const double dz = p[2] - q[2];
      const uint64_t bits = OrderedBits(dx * dx + dy * dy + dz * dz);
      const bool closer = bits < found_bits;
      found = closer ? ids[j] : found;
      found_bits = closer ? bits : found_bits;
    }
    remaining -= m;
    if (remaining == 0) break;
    b = bucket_next_[b];
  }
  if (found >= 0) {
    *best = found;
    std::memcpy(best_d2, &found_bits, sizeof found_bits);
  }
}

NEURALMESH_AVX2_CLONE int VertexOctree::Nearest(const Vec3& q, double* distance2,
                                                const OctreeDescent& descent) const {
  if (size_ == 0) return -1;
  const double qp[3] = {q[0], q[1], q[2]};
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();

  // Depth-first search with an explicit stack; an expansion pushes at most 8 entries, so the
  // stack stays small and lives on the call stack unless the tree is very deep.
  SearchEntry inline_stack[kInlineSearchEntries];
  std::vector<SearchEntry> heap_stack;
  SearchEntry* stack = inline_stack;
  int capacity = kInlineSearchEntries;

  // First the leaf on q's side, the descent's or straight down: it most likely holds the
  // answer.
  int scanned = AtLeaf(descent) ? descent.node : -1;
  if (scanned < 0) {
    const int n = DescendFrom(0, qp, kToLeaf);
    if (node(n).child < kEmpty) scanned = n;  // Else an empty leaf: the search starts at the root.
  }
  int start = 0;
  if (scanned >= 0) {
    ScanLeaf(node(scanned), qp, &best, &best_d2);
    // Anything nearer lies in the ball of radius sqrt(best_d2) around q; the search starts at
    // the lowest cube above that leaf that contains that ball (the test allows for its
    // rounding).
    const double r = std::sqrt(best_d2) * (1 + 1e-12) + slack_;
    for (int n = scanned; n >= 0; n = Parent(n)) {
      double center[3], half;
      NodeCube(n, center, &half);
      bool inside = true;
      for (int i = 0; i < 3; ++i) {
        const double rounding = 1e-15 * (std::abs(qp[i]) + std::abs(center[i]) + half);
        inside &= std::abs(qp[i] - center[i]) + r + rounding <= half;
      }
      if (inside) {
        start = n;
        break;
      }
    }
    if (start == scanned) {
      if (distance2 != nullptr) *distance2 = best_d2;
      return best;
    }
  }

  int top = 0;
  stack[top++] = SearchEntry{start, 0.0};
  while (top > 0) {
    const SearchEntry e = stack[--top];
    if (e.d2 >= best_d2) continue;
    const Node& nd = node(e.node);
    if (nd.child < 0) {
      ScanLeaf(nd, qp, &best, &best_d2);  // Non-empty: empty nodes are never pushed.
      continue;
    }
    if (top + 8 > capacity) capacity = GrowSearchStack(capacity, &stack, &heap_stack);
    const Block& block = blocks_[nd.child];
    const double h = block.half * 0.5;
    const int own = Octant(block.center, qp);
    // Per axis, the squared distance from q to the lower and the upper half of the cube, and
    // the halves within reach, q's own last.
    double axis_d2[3][2];
    int halves[3][2];
    int num_halves[3];
    for (int i = 0; i < 3; ++i) {
      const double lo = PositivePart(std::abs(qp[i] - (block.center[i] - h)) - h - slack_);
      const double hi = PositivePart(std::abs(qp[i] - (block.center[i] + h)) - h - slack_);
      axis_d2[i][0] = lo * lo;
      axis_d2[i][1] = hi * hi;
      const int mine = (own >> i) & 1;
      int k = 0;
      halves[i][k] = mine ^ 1;
      k += axis_d2[i][mine ^ 1] < best_d2;
      halves[i][k] = mine;
      k += axis_d2[i][mine] < best_d2;
      num_halves[i] = k;
    }
    // Pushed so that q's own octant is popped first.
    for (int a = 0; a < num_halves[2]; ++a) {
      const int z = halves[2][a];
      for (int b = 0; b < num_halves[1]; ++b) {
        const int y = halves[1][b];
        const double dyz = axis_d2[1][y] + axis_d2[2][z];
        for (int c = 0; c < num_halves[0]; ++c) {
          const int x = halves[0][c];
          const int o = x | (y << 1) | (z << 2);
          const double d2 = axis_d2[0][x] + dyz;
          const int child = nd.child * 8 + o;
          stack[top] = SearchEntry{child, d2};
          top += (block.nodes[o].count != 0) & (d2 < best_d2) & (child != scanned);
        }
      }
    }
  }
  if (distance2 != nullptr) *distance2 = best_d2;
  return best;
}

int VertexOctree::Depth() const { return DepthOf(0); }

int VertexOctree::DepthOf(int n) const {
  const Node& nd = node(n);
  if (nd.child < 0) return 0;
  int d = 0;
  for (int o = 0; o < 8; ++o) d = std::max(d, 1 + DepthOf(nd.child * 8 + o));
  return d;
}

}  // namespace neuralmesh
