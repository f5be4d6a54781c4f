// A convex shape against a static triangle mesh: each triangle whose box
// overlaps the shape's (grown by the margin) is a thin convex polygon and
// goes through the general convex path (collide_convex.cpp), giving one
// manifold per touching triangle, tagged with the triangle's index.
//
// The shape's box is computed in the mesh's frame, so the mesh's triangles
// are tested without transforming them (through the mesh's BVH when it has
// one, mesh_bvh.hpp); only the candidates are moved to world space. Triangles are two-sided (a body pushed through a triangle is
// pushed out of whichever side is nearer), and neighbouring triangles are
// not consulted, so a box sliding across a flat mesh can catch on an
// internal edge (see docs/collision.md).
//
// Feature ids are mixed with the triangle index (a fixed odd multiplier), so
// ids stay unique across the pair's manifolds and stable over time.
#include "collision/aabb.hpp"
#include "collision/mesh_bvh.hpp"
#include "collision/narrowphase.hpp"
#include "collision/triangle_area.hpp"

#include <algorithm>

namespace cairn::narrow {

int meshConvex(const ShapeDesc& mesh, const Transform& tm, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  if (!mesh.mesh || (b.type == ShapeType::ConvexHull && !b.hull)) return 0;
  const TriangleMeshData& md = *mesh.mesh;
  const Transform local{tm.applyInverse(tb.p), (tm.q.conjugate() * tb.q).normalized()};
  const Aabb box = shapeAabb(b, local).expanded(margin);
  const ConvexProxy pb = makeProxy(b, tb);
  // Candidates in triangle order, so the manifolds come out in the same
  // order whether or not the mesh has a tree.
  thread_local std::vector<int> candidates;
  candidates.clear();
  queryMeshTriangles(md, box, [&](int t) { candidates.push_back(t); });
  std::sort(candidates.begin(), candidates.end());
  int added = 0;
  for (const int t : candidates) {
    const auto& tri = md.triangles[t];
    const Vec3 w0 = tm.apply(md.vertices[tri[0]]), w1 = tm.apply(md.vertices[tri[1]]), w2 = tm.apply(md.vertices[tri[2]]);
    if (!triangleHasArea(w0, w1, w2)) continue;  // no area, no normal (a mesh built in code may have them)
    Manifold m;
    if (!convexProxies(makeTriangleProxy(w0, w1, w2), pb, margin, m)) continue;
    m.triangle = t;
    const std::uint32_t salt = static_cast<std::uint32_t>(t) * 2654435761u;
    for (int k = 0; k < m.count; ++k) m.points[k].feature_id ^= salt;
    out.push_back(m);
    ++added;
  }
  return added;
}

}  // namespace cairn::narrow
