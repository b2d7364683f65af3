// An octree over the vertices of the neural mesh that answers exact nearest-vertex queries
// while vertices move, appear and disappear (Section 2.1: "The search is done using an octree
// updated every time the position of a vertex changes").
//
// Leaves hold up to `bucket_size` vertices; a leaf that overflows splits, a subtree that drops
// to half a bucket merges back into a leaf, and the root doubles toward any point inserted
// outside it, so no bounding box has to be known in advance (points stream in).
// Query: O(log v) expected; a move that stays inside its leaf is O(1), others O(log v).
//
// Layout and search (for speed: every Basic Step of the learner makes one query and about 7
// moves): the children of a node are allocated together as one block of 8 compact nodes that
// also holds their parent's cube, so a query reads one block per level; a leaf keeps only the
// ids of its points, in a fixed-size bucket, and reads their coordinates from the caller's
// array of points (the learner's mesh positions, which the smoothing around the winner reads
// too, so a search and the step after it share those cache lines). A move that stays in its
// leaf then writes nothing. A query first scans the leaf on q's side, then searches
// depth-first (explicit stack, nearest octant first, pruned by cube distance) from the lowest
// cube on that path that contains the ball the first leaf bounds. Leaves at the maximum depth
// (many coincident points) chain further buckets.
#ifndef NEURALMESH_CORE_LEARNING_VERTEX_OCTREE_H_
#define NEURALMESH_CORE_LEARNING_VERTEX_OCTREE_H_

#include <cstdint>
#include <vector>

#include "core/bounding_box.h"
#include "core/huge_page_allocator.h"
#include "core/mesh.h"

namespace neuralmesh {

// A descent of a VertexOctree toward the leaf on a query point's side, taken ahead of the query
// and a few levels at a time (VertexOctree::Descend): the node it has reached, which stays on
// that path while the tree keeps its shape (no leaf split or merged, the root not grown),
// whatever moves in between. `node` < 0: not started.
struct OctreeDescent {
  int32_t node = -1;
  uint64_t shape = 0;
};

class VertexOctree {
 public:
  // Indexes points of `points` (by id), which the caller owns and keeps: the octree stores ids
  // only and reads (*points)[id] whenever it compares or routes id, so the vector must outlive
  // the octree (it may grow). `initial_box` sizes the root; it grows as needed. `bucket_size`
  // (at least 2) is the capacity of a leaf (32 measured best or near-best from 1K to 100K
  // points on a surface in random order, bench/octree_bench.cc; the learner, whose points are
  // in Morton order, uses 64: learner.cc).
  VertexOctree(const BoundingBox& initial_box, const std::vector<Vec3>* points,
               int bucket_size = 32);

  // Ids are small non-negative integers (vertex indices) below points->size(); their points
  // must be finite.
  void Insert(int id);
  void Remove(int id);
  // Call after (*points)[id] changed. Several points may change before their Moves; every
  // changed point needs its Move before the next Nearest.
  void Move(int id);
  bool Contains(int id) const {
    return id >= 0 && id < static_cast<int>(where_.size()) && where_[id].slot >= 0;
  }

  // A hint: starts loading where `id` is kept, for a caller that will Move it after other
  // work. On a large tree that lookup is a cache miss, the one Move would otherwise wait for.
  void PrefetchLocation(int id) const {
    if (static_cast<size_t>(id) < where_.size()) __builtin_prefetch(&where_[id]);
  }
  // Hints for a Nearest(q) to come, each a little after the one before, so that what one
  // starts loading has arrived when the next reads it. Descend goes down at most `levels` levels
  // of the tree toward the leaf on q's side, from where `descent` stopped (from the root if it
  // has not started or the tree has changed shape since), and starts loading what the next
  // level down reads: the block of the children or, at a leaf, the ids it holds.
  // PrefetchNearestPoints, at a leaf whose ids have loaded, starts loading their points.
  // Nearest, given a descent that has reached its leaf, starts there.
  static constexpr int kToLeaf = 1 << 30;
  void Descend(const Vec3& q, int levels, OctreeDescent* descent) const;
  void PrefetchNearestPoints(const OctreeDescent& descent) const;

  // The id of the point nearest to `q` (ties: any), or -1 when empty. Exact. With `distance2`,
  // also stores its squared distance to `q` there (dx^2 + dy^2 + dz^2 in that order). With a
  // `descent` toward q (one that has not reached its leaf, or is stale, is ignored), the same
  // answer as without.
  int Nearest(const Vec3& q, double* distance2 = nullptr, const OctreeDescent& descent = {}) const;

  size_t size() const { return size_; }
  // Depth of the deepest leaf; for tests and diagnostics.
  int Depth() const;

 private:
  // A node is named by an int: block * 8 + octant; node 0 (in block 0, whose other slots are
  // unused) is the root. `child` >= 0: internal, its children are block `child`;
  // kEmpty: a leaf without points; otherwise a leaf whose first bucket is LeafBucket(child).
  struct Node {
    int32_t child;
    int32_t count;  // Points in the subtree.
  };
  // The 8 children of one node plus that node's cube, from which the children's cubes follow
  // (ChildCenter). 128 bytes, aligned so that it spans one adjacent pair of cache lines.
  struct alignas(128) Block {
    double center[3];
    double half;
    int32_t parent;  // The node whose children these are.
    int32_t next_free;
    Node nodes[8];
  };
  // Where a point is kept: its slot in ids_ and its leaf. Move tests the new position against
  // the leaf's cube, which follows from the leaf's block (usually in cache: the learner moves
  // vertices near the one it has just searched for).
  struct Location {
    int32_t slot;  // Index in ids_, or -1 when absent.
    int32_t leaf;
  };
  static constexpr int32_t kEmpty = -1;
  static int32_t LeafChild(int bucket) { return -2 - bucket; }
  static int LeafBucket(int32_t child) { return -2 - child; }

  Node& node(int n) { return blocks_[n >> 3].nodes[n & 7]; }
  const Node& node(int n) const { return blocks_[n >> 3].nodes[n & 7]; }
  int Parent(int n) const { return n == 0 ? -1 : blocks_[n >> 3].parent; }
  // The cube of node n (the root's is stored, the others follow from their block).
  void NodeCube(int n, double center[3], double* half) const;
  int32_t* BucketIds(int b) { return &ids_[static_cast<size_t>(b) * bucket_size_]; }
  const int32_t* BucketIds(int b) const { return &ids_[static_cast<size_t>(b) * bucket_size_]; }
  const double* PointOf(int id) const { return (*points_)[static_cast<size_t>(id)].data(); }
  // The node `levels` levels below node n toward q, or the leaf on q's side if that is higher.
  int DescendFrom(int n, const double q[3], int levels) const;
  // Whether `descent` has reached a non-empty leaf of this shape.
  bool AtLeaf(const OctreeDescent& descent) const {
    return descent.node >= 0 && descent.shape == shape_ && node(descent.node).child < kEmpty;
  }

  int NewBlock(int parent, const double center[3], double half);
  void FreeBlock(int b);
  int NewBucket();
  void FreeBucket(int b);
  // Appends id to leaf n (which may be empty), chaining a bucket if needed.
  void AppendToLeaf(int n, int id);
  void GrowRootToward(const double p[3]);
  void InsertIntoTree(int id, const double p[3]);
  void SplitLeaf(int n);
  void CollapseSubtree(int n);
  void GatherIds(int n, std::vector<int32_t>& out) const;
  void FreeSubtree(int n);
  // Updates (best, best_d2) with the points of a non-empty leaf.
  void ScanLeaf(const Node& leaf, const double q[3], int* best, double* best_d2) const;
  int DepthOf(int n) const;

  HugePageVector<Block> blocks_;
  int free_blocks_ = -1;
  const std::vector<Vec3>* points_;
  HugePageVector<int32_t> ids_;   // bucket_size_ ids per bucket; fewer than 2^31 in all.
  std::vector<int> bucket_next_;  // The next bucket of the same leaf, or -1.
  std::vector<int> free_buckets_;
  HugePageVector<Location> where_;  // By id.
  double root_center_[3];
  double root_half_;
  // Tolerance added to the cube of an old root: after the root grows, the old root's cube as
  // derived from the new root may differ from the stored one by a rounding error.
  double slack_ = 0;
  // Changes whenever a leaf splits or merges or the root grows (OctreeDescent): a count of those
  // events, starting from a value no other octree of the process has had.
  uint64_t shape_;
  int bucket_size_;
  size_t size_ = 0;
  std::vector<int32_t> scratch_;  // For SplitLeaf and CollapseSubtree.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_VERTEX_OCTREE_H_
