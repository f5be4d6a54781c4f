// Dynamic AABB tree (cost model and balance rule in dynamic_tree.hpp).
#include "collision/dynamic_tree.hpp"

#include <algorithm>
#include <cstdlib>

namespace cairn {

int DynamicTree::allocateNode() {
  if (free_ < 0) {
    nodes_.emplace_back();
    return static_cast<int>(nodes_.size()) - 1;
  }
  const int i = free_;
  free_ = nodes_[i].parent;
  nodes_[i] = Node{};
  return i;
}

void DynamicTree::freeNode(int i) {
  nodes_[i] = Node{};
  nodes_[i].parent = free_;
  free_ = i;
}

int DynamicTree::insert(const Aabb& box, int user) {
  const int leaf = allocateNode();
  nodes_[leaf].box = box;
  nodes_[leaf].user = user;
  nodes_[leaf].height = 0;
  insertLeaf(leaf);
  ++leaves_;
  return leaf;
}

void DynamicTree::remove(int leaf) {
  removeLeaf(leaf);
  freeNode(leaf);
  --leaves_;
}

void DynamicTree::update(int leaf, const Aabb& box) {
  removeLeaf(leaf);
  nodes_[leaf].box = box;
  insertLeaf(leaf);
}

void DynamicTree::insertLeaf(int leaf) {
  if (root_ < 0) {
    root_ = leaf;
    nodes_[leaf].parent = -1;
    return;
  }
  const Aabb lbox = nodes_[leaf].box;  // a copy: allocateNode() may move the array
  // One path down from the root (Catto's descent in Box2D v3,
  // b2FindBestSibling): the cost of pairing L with node S is
  //   C(S) = SA(S u L) + g(S),  g(S) = sum over S's ancestors A of SA(A u L) - SA(A),
  // and nothing at or below a child c can cost less than
  //   g(c) + SA(c u L) + min(0, SA(L) - SA(c))
  // (c's own growth, then at least SA(L) for the new parent). The descent
  // follows the child with the lower bound and stops when neither bound
  // beats the best cost seen. The full branch and bound over a priority
  // queue found slightly better siblings but cost several times more per
  // insertion, and a fast whipping chain reinserts most of its links every
  // step (docs/performance.md).
  const Real leaf_area = lbox.surfaceArea();
  int sibling = root_;
  Real best = nodes_[root_].box.merged(lbox).surfaceArea();
  Real inherited = 0;  // g of the children of `index`
  for (int index = root_; !nodes_[index].isLeaf();) {
    const Node& n = nodes_[index];
    inherited += n.box.merged(lbox).surfaceArea() - n.box.surfaceArea();
    const int child[2] = {n.child1, n.child2};
    Real bound[2];
    for (int k = 0; k < 2; ++k) {
      const Node& c = nodes_[child[k]];
      const Real cost = c.box.merged(lbox).surfaceArea() + inherited;
      if (cost < best) {
        best = cost;
        sibling = child[k];
      }
      bound[k] = c.isLeaf() ? kInf : cost + std::min(Real(0), leaf_area - c.box.surfaceArea());
    }
    if (!(std::min(bound[0], bound[1]) < best)) break;
    index = bound[0] <= bound[1] ? child[0] : child[1];
  }
  const int old_parent = nodes_[sibling].parent;
  const int parent = allocateNode();
  Node& p = nodes_[parent];
  p.parent = old_parent;
  p.box = nodes_[sibling].box.merged(lbox);
  p.height = nodes_[sibling].height + 1;
  p.child1 = sibling;
  p.child2 = leaf;
  nodes_[sibling].parent = parent;
  nodes_[leaf].parent = parent;
  if (old_parent < 0) {
    root_ = parent;
  } else if (nodes_[old_parent].child1 == sibling) {
    nodes_[old_parent].child1 = parent;
  } else {
    nodes_[old_parent].child2 = parent;
  }
  refitUpFrom(parent);
}

void DynamicTree::removeLeaf(int leaf) {
  if (leaf == root_) {
    root_ = -1;
    return;
  }
  const int parent = nodes_[leaf].parent;
  const int grand = nodes_[parent].parent;
  const int sibling = nodes_[parent].child1 == leaf ? nodes_[parent].child2 : nodes_[parent].child1;
  if (grand < 0) {
    root_ = sibling;
    nodes_[sibling].parent = -1;
  } else {
    if (nodes_[grand].child1 == parent) nodes_[grand].child1 = sibling;
    else nodes_[grand].child2 = sibling;
    nodes_[sibling].parent = grand;
    refitUpFrom(grand);
  }
  freeNode(parent);
  nodes_[leaf].parent = -1;
}

// Walks to the root restoring each node's box and height, rotating where the
// subtree heights drifted apart.
void DynamicTree::refitUpFrom(int i) {
  while (i >= 0) {
    i = balance(i);
    refit(i);
    i = nodes_[i].parent;
  }
}

void DynamicTree::refit(int i) {
  Node& n = nodes_[i];
  n.box = nodes_[n.child1].box.merged(nodes_[n.child2].box);
  n.height = 1 + std::max(nodes_[n.child1].height, nodes_[n.child2].height);
}

// One rotation lowers an imbalance of k to k - 1 or k - 2 at the demoted
// node. The SAH may pair a leaf with a tall subtree (k > 2), so the demoted
// node is balanced in turn until every node on the way is within one.
int DynamicTree::balance(int a) {
  const Node& na = nodes_[a];
  if (na.isLeaf()) return a;
  if (std::abs(nodes_[na.child1].height - nodes_[na.child2].height) <= 1) return a;
  const int up = rotate(a);
  balance(a);
  refit(up);
  return up;
}

// AVL rotation at inner node a with children b, c, c the taller: c takes
// a's place; a keeps b and receives c's shorter child; c keeps its taller
// child and adopts a. Symmetric when b is the taller. Returns the node now at
// a's position.
int DynamicTree::rotate(int a) {
  Node& na = nodes_[a];
  const int b = na.child1, c = na.child2;
  const bool c_taller = nodes_[c].height > nodes_[b].height;
  const int up = c_taller ? c : b;      // the taller child moves up
  const int stay = c_taller ? b : c;    // a's other child stays with a
  Node& nu = nodes_[up];
  const int f = nu.child1, g = nu.child2;
  const bool f_taller = nodes_[f].height > nodes_[g].height;
  const int keep = f_taller ? f : g;       // stays under `up`
  const int give = f_taller ? g : f;       // moves under `a`

  // `up` replaces a under a's parent.
  nu.parent = na.parent;
  if (nu.parent < 0) root_ = up;
  else if (nodes_[nu.parent].child1 == a) nodes_[nu.parent].child1 = up;
  else nodes_[nu.parent].child2 = up;

  nu.child1 = a;
  nu.child2 = keep;
  na.parent = up;
  na.child1 = stay;
  na.child2 = give;
  nodes_[give].parent = a;
  nodes_[stay].parent = a;
  nodes_[keep].parent = up;

  na.box = nodes_[stay].box.merged(nodes_[give].box);
  na.height = 1 + std::max(nodes_[stay].height, nodes_[give].height);
  nu.box = na.box.merged(nodes_[keep].box);
  nu.height = 1 + std::max(na.height, nodes_[keep].height);
  return up;
}

Real DynamicTree::areaRatio() const {
  if (root_ < 0) return 0;
  const Real root_area = nodes_[root_].box.surfaceArea();
  Real total = 0;
  for (const Node& n : nodes_)
    if (n.height > 0) total += n.box.surfaceArea();
  return root_area > 0 ? total / root_area : 0;
}

bool DynamicTree::validate() const {
  if (root_ < 0) return leaves_ == 0;
  if (nodes_[root_].parent != -1) return false;
  int leaves = 0;
  std::vector<int> stack{root_};
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    const Node& n = nodes_[i];
    if (n.isLeaf()) {
      if (n.height != 0 || n.child2 != -1) return false;
      ++leaves;
      continue;
    }
    const Node& c1 = nodes_[n.child1];
    const Node& c2 = nodes_[n.child2];
    if (c1.parent != i || c2.parent != i) return false;
    if (n.height != 1 + std::max(c1.height, c2.height)) return false;
    if (std::abs(c1.height - c2.height) > 1) return false;
    if (!n.box.contains(c1.box) || !n.box.contains(c2.box)) return false;
    stack.push_back(n.child1);
    stack.push_back(n.child2);
  }
  return leaves == leaves_;
}

}  // namespace cairn
