// An octree over the vertices of the neural mesh that answers exact nearest-vertex queries
// while vertices move, appear and disappear (Section 2.1: "The search is done using an octree
// updated every time the position of a vertex changes").
//
// Leaves hold up to `bucket_size` vertices; a leaf that overflows splits, a subtree that drops
// to half a bucket merges back into a leaf, and the root doubles toward any point inserted
// outside it, so no bounding box has to be known in advance (points stream in).
// Query: O(log v) expected; a move that stays inside its leaf is O(1), others O(log v).
#ifndef NEURALMESH_CORE_LEARNING_VERTEX_OCTREE_H_
#define NEURALMESH_CORE_LEARNING_VERTEX_OCTREE_H_

#include <vector>

#include "core/bounding_box.h"
#include "core/mesh.h"

namespace neuralmesh {

class VertexOctree {
 public:
  // `initial_box` sizes the root; it grows as needed.
  explicit VertexOctree(const BoundingBox& initial_box, int bucket_size = 12);

  // Ids are small non-negative integers (vertex indices); `p` must be finite.
  void Insert(int id, const Vec3& p);
  void Remove(int id);
  void Move(int id, const Vec3& p);
  bool Contains(int id) const {
    return id >= 0 && id < static_cast<int>(leaf_of_.size()) && leaf_of_[id] >= 0;
  }

  // The id of the point nearest to `q` (ties: any), or -1 when empty. Exact.
  int Nearest(const Vec3& q) const;

  size_t size() const { return size_; }
  // Depth of the deepest leaf; for tests and diagnostics.
  int Depth() const;

 private:
  struct Node {
    Vec3 center;
    double half = 0;
    int parent = -1;
    int count = 0;  // Points in the subtree.
    int children[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
    bool leaf = true;
    std::vector<int> items;  // Leaf only.
  };

  int NewNode(const Vec3& center, double half, int parent);
  void FreeNode(int n);
  bool InCube(const Node& node, const Vec3& p) const;
  int Octant(const Node& node, const Vec3& p) const;
  void GrowRootToward(const Vec3& p);
  // The child of internal node n that contains p, created (as an empty leaf) if absent.
  int ChildToward(int n, const Vec3& p);
  void InsertIntoTree(int id);
  void SplitLeaf(int n);
  void CollapseSubtree(int n);
  void GatherItems(int n, std::vector<int>& out);
  void Search(int n, const Vec3& q, int& best, double& best_d2) const;
  int DepthOf(int n) const;

  std::vector<Node> nodes_;
  std::vector<int> free_nodes_;
  std::vector<Vec3> position_;
  std::vector<int> leaf_of_;  // -1 when absent.
  std::vector<int> slot_;     // Index in the leaf's items.
  int root_ = -1;
  int bucket_size_;
  size_t size_ = 0;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_LEARNING_VERTEX_OCTREE_H_
