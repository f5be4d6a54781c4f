// A static bounding volume hierarchy over a triangle mesh, so that a shape
// meets only the triangles near it: O(log n + k) box tests instead of n.
//
// Built top-down once: each node splits its triangles at the median of
// their box centers along the axis where those centers spread most, until a
// leaf holds at most 4 triangles. A median split gives a tree of depth
// log2(n / 4) + 1 whatever the mesh, and the nodes sit in one array with
// both children of a node adjacent.
#pragma once

#include "collision/aabb.hpp"
#include "cairn/shape.hpp"

namespace cairn {

// Fills mesh.bvh and mesh.bvh_order (replacing any previous tree).
void buildMeshBvh(TriangleMeshData& mesh);

// Calls visit(triangle) for every triangle whose box overlaps `box` (in the
// mesh's frame), using the tree when there is one and scanning otherwise.
template <class Visit>
void queryMeshTriangles(const TriangleMeshData& mesh, const Aabb& box, Visit&& visit) {
  auto triBox = [&](int t) {
    const auto& tri = mesh.triangles[t];
    return triangleAabb(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]);
  };
  if (mesh.bvh.empty()) {
    for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t)
      if (triBox(t).overlaps(box)) visit(t);
    return;
  }
  int stack[64];  // depth <= log2(n / 4) + 1: 64 levels exceed any mesh
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const TriangleMeshData::BvhNode& n = mesh.bvh[stack[--top]];
    if (!Aabb{n.lo, n.hi}.overlaps(box)) continue;
    if (n.count > 0) {
      for (int k = n.first; k < n.first + n.count; ++k) {
        const int t = mesh.bvh_order[k];
        if (triBox(t).overlaps(box)) visit(t);
      }
    } else {
      stack[top++] = n.first;
      stack[top++] = n.first + 1;
    }
  }
}

}  // namespace cairn
