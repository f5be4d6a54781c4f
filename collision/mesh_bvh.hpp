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

#include <algorithm>

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

// Calls visit(triangle, max_fraction) for every triangle whose box, grown by
// `extent` on every side, meets the segment origin + f * translation,
// 0 <= f <= max_fraction (in the mesh's frame): a ray for extent 0, the box
// of a moving shape otherwise. Of two children the nearer is visited first;
// visit returns the new max_fraction, so a hit clips the segment and prunes
// the nodes beyond it. Without a tree every triangle's box is tested.
template <class Visit>
void castMeshTriangles(const TriangleMeshData& mesh, const Vec3& origin, const Vec3& translation, Real max_fraction,
                       const Vec3& extent, Visit&& visit) {
  const Vec3 inv = translation.cwiseInverse();
  auto enter = [&](const Vec3& lo, const Vec3& hi) {
    Real t0 = 0, t1 = max_fraction;
    return clipLineToBox(lo - extent, hi + extent, origin, inv, t0, t1) ? t0 : kInf;
  };
  auto triangle = [&](int t) {
    const auto& tri = mesh.triangles[t];
    const Aabb b = triangleAabb(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]);
    if (enter(b.lo, b.hi) <= max_fraction) max_fraction = std::min(max_fraction, visit(t, max_fraction));
  };
  if (mesh.bvh.empty()) {
    for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) triangle(t);
    return;
  }
  SegmentEntry stack[64];  // depth <= log2(n / 4) + 1, plus one pending sibling per level
  int top = 0;
  const Real f_root = enter(mesh.bvh[0].lo, mesh.bvh[0].hi);
  if (f_root <= max_fraction) stack[top++] = {0, f_root};
  while (top > 0) {
    const SegmentEntry e = stack[--top];
    if (e.enter > max_fraction) continue;
    const TriangleMeshData::BvhNode& n = mesh.bvh[e.node];
    if (n.count > 0) {
      for (int k = n.first; k < n.first + n.count; ++k) triangle(mesh.bvh_order[k]);
      continue;
    }
    const auto& c1 = mesh.bvh[n.first];
    const auto& c2 = mesh.bvh[n.first + 1];
    pushNearerLast(stack, top, {n.first, enter(c1.lo, c1.hi)}, {n.first + 1, enter(c2.lo, c2.hi)}, max_fraction);
  }
}

}  // namespace cairn
