// A dynamic bounding volume hierarchy: a binary tree of AABBs whose leaves
// are proxies and whose inner nodes bound their two children.
//
// Insertion picks the sibling that minimizes the total surface area the
// tree gains (the surface area heuristic: a query box hits a node with
// probability proportional to its area, MacDonald and Booth 1990). Pairing
// the new leaf L with node S under a new parent costs
//   SA(S u L)                          the new parent's area
//   + sum over ancestors A of S of SA(A u L) - SA(A)   their growth,
// and S is found by one descent from the root that follows the child whose
// subtree could cost least and stops when no subtree can beat the best S
// seen (Bittner, Hapala, Havran 2013, bound the search the same way; Catto,
// "Dynamic Bounding Volume Hierarchies", GDC 2019, and Box2D v3 descend one
// path; dynamic_tree.cpp says why one path).
//
// Balance: after every insert and remove, the path to the root is refitted
// and each node whose children's heights differ by more than one is rotated
// (AVL rotation: the taller child moves up and keeps its taller grandchild;
// children of a BVH node are unordered, so one rotation kind covers the
// zig-zag case too), so the height stays below 1.44 log2(n + 2) whatever the
// insertion order and a query costs O(log n + k) node tests for k hits.
//
// Storage: one contiguous array of nodes; freed nodes form a free list
// threaded through `parent`, so inserting and removing never allocate once
// the array has grown to the peak node count.
#pragma once

#include "collision/aabb.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace cairn {

class DynamicTree {
 public:
  struct Node {
    Aabb box;
    int parent = -1;  // next free node while on the free list
    int child1 = -1;  // -1 for a leaf
    int child2 = -1;
    int height = -1;  // 0 for a leaf, -1 for a free node
    int user = -1;    // leaves only
    bool isLeaf() const { return child1 < 0; }
  };

  // Adds a leaf with `box`; returns its node index (stable until removed).
  int insert(const Aabb& box, int user);
  void remove(int leaf);
  // Replaces the leaf's box, re-inserting it (the leaf keeps its index).
  void update(int leaf, const Aabb& box);

  const Aabb& box(int leaf) const { return nodes_[leaf].box; }
  int user(int leaf) const { return nodes_[leaf].user; }
  int root() const { return root_; }
  const Node& node(int i) const { return nodes_[i]; }
  int height() const { return root_ < 0 ? 0 : nodes_[root_].height; }
  int leafCount() const { return leaves_; }
  // Sum of inner node areas over the root's: the SAH quality measure.
  Real areaRatio() const;
  // Structural invariants (parents, heights, enclosing boxes, balance).
  bool validate() const;

  // Calls visit(leaf) for every leaf whose box overlaps `box`; visit returns
  // false to stop. Adds the number of box-box tests to *tests if given.
  template <class Visit>
  void query(const Aabb& box, Visit&& visit, std::uint64_t* tests = nullptr) const {
    if (root_ < 0) return;
    // AVL balance bounds the height by 1.44 log2(n + 2): 128 entries would
    // need more leaves than memory can hold.
    int stack[128];
    int top = 0;
    stack[top++] = root_;
    std::uint64_t count = 0;
    while (top > 0) {
      const Node& n = nodes_[stack[--top]];
      ++count;
      if (!n.box.overlaps(box)) continue;
      if (n.isLeaf()) {
        if (!visit(static_cast<int>(&n - nodes_.data()))) break;
      } else {
        stack[top++] = n.child1;
        stack[top++] = n.child2;
      }
    }
    if (tests) *tests += count;
  }

  // Segment query (Box2D's b2DynamicTree_RayCast and b2DynamicTree_ShapeCast,
  // with slab tests): calls visit(leaf, max_fraction) for every leaf whose
  // box, grown by `extent` on every side, meets the segment
  //   origin + f * translation, 0 <= f <= max_fraction.
  // visit returns the new max_fraction: a hit's fraction clips the segment
  // and prunes every node it no longer reaches; a negative value stops. Of
  // two children the nearer (smaller entry fraction) is visited first, so a
  // closest-hit query clips early. Adds the number of node tests to *tests.
  template <class Visit>
  void rayCast(const Vec3& origin, const Vec3& translation, Real max_fraction, const Vec3& extent, Visit&& visit,
               std::uint64_t* tests = nullptr) const {
    if (root_ < 0) return;
    const Vec3 inv = translation.cwiseInverse();
    auto enter = [&](int i) {
      Real t0 = 0, t1 = max_fraction;
      const Aabb& b = nodes_[i].box;
      return clipLineToBox(b.lo - extent, b.hi + extent, origin, inv, t0, t1) ? t0 : kInf;
    };
    SegmentEntry stack[128];  // depth-first: at most one pending sibling per level
    int top = 0;
    std::uint64_t count = 1;
    const Real f_root = enter(root_);
    if (f_root <= max_fraction) stack[top++] = {root_, f_root};
    while (top > 0) {
      const SegmentEntry e = stack[--top];
      if (e.enter > max_fraction) continue;  // clipped since it was pushed
      const Node& n = nodes_[e.node];
      if (n.isLeaf()) {
        const Real f = visit(e.node, max_fraction);
        if (f < 0) break;
        max_fraction = std::min(max_fraction, f);
        continue;
      }
      count += 2;
      pushNearerLast(stack, top, {n.child1, enter(n.child1)}, {n.child2, enter(n.child2)}, max_fraction);
    }
    if (tests) *tests += count;
  }

 private:
  int allocateNode();
  void freeNode(int i);
  void insertLeaf(int leaf);
  void removeLeaf(int leaf);
  int rotate(int a);
  int balance(int a);
  void refit(int i);
  void refitUpFrom(int i);

  std::vector<Node> nodes_;
  int root_ = -1;
  int free_ = -1;
  int leaves_ = 0;
};

}  // namespace cairn
