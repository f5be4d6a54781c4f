// Overlap tests per target type (the rules are in overlap.hpp).
#include "collision/overlap.hpp"

#include "collision/aabb.hpp"
#include "collision/gjk.hpp"
#include "collision/mesh_bvh.hpp"
#include "collision/shape_cast.hpp"
#include "collision/support.hpp"

namespace cairn {
namespace {

bool proxiesOverlap(const ConvexProxy& a, const ConvexProxy& b) {
  const Real radii = a.radius + b.radius;
  const GjkResult g = gjkDistance(a, b, false, radii);
  return !g.beyond && (g.overlap || g.distance <= radii);
}

bool overlapsMesh(const ShapeDesc& query, const Transform& pose, const TriangleMeshData& mesh, const Transform& tm) {
  const Transform local{tm.applyInverse(pose.p), (tm.q.conjugate() * pose.q).normalized()};
  const ConvexProxy a = makeProxy(query, local);
  bool found = false;
  queryMeshTriangles(mesh, shapeAabb(query, local), [&](int t) {
    if (found) return;
    const auto& tri = mesh.triangles[t];
    found = proxiesOverlap(a, makeTriangleProxy(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]));
  });
  return found;
}

}  // namespace

bool overlaps(const ShapeDesc& query, const Transform& pose, const ShapeDesc& target, const Transform& target_pose) {
  if (!isConvexQueryShape(query)) return false;
  switch (target.type) {
    case ShapeType::Plane: {
      Vec3 n;
      Real e;
      worldPlane(target, target_pose, n, e);
      return n.dot(supportWorld(query, pose, -n)) <= e;
    }
    case ShapeType::Mesh: return target.mesh && overlapsMesh(query, pose, *target.mesh, target_pose);
    default:
      return isConvexQueryShape(target) && proxiesOverlap(makeProxy(query, pose), makeProxy(target, target_pose));
  }
}

}  // namespace cairn
