// Shape casts per target type (the formulas are in shape_cast.hpp).
#include "collision/shape_cast.hpp"

#include "collision/aabb.hpp"
#include "collision/gjk_raycast.hpp"
#include "collision/mesh_bvh.hpp"
#include "collision/support.hpp"

namespace cairn {
namespace {

std::optional<CastHit> castOntoPlane(const ShapeDesc& moving, const Transform& pose, const Vec3& translation,
                                     const ShapeDesc& plane, const Transform& tp, Real max_fraction) {
  Vec3 n;
  Real e;
  worldPlane(plane, tp, n, e);
  const Vec3 deepest = supportWorld(moving, pose, -n);
  const Real height = n.dot(deepest) - e, den = n.dot(translation);
  CastHit hit;
  if (height < 0) {
    hit.inside = true;
    hit.normal = -translation.normalized();
    hit.point = pose.p;
    return hit;
  }
  if (den >= 0 || height > -den * max_fraction) return std::nullopt;
  hit.fraction = height / -den;
  hit.normal = n;
  hit.point = deepest + hit.fraction * translation;
  return hit;
}

std::optional<CastHit> castOntoMesh(const ShapeDesc& moving, const Transform& pose, const Vec3& translation,
                                    const TriangleMeshData& mesh, const Transform& tm, Real max_fraction) {
  // Everything in the mesh's frame: the triangles stay as stored.
  const Transform local{tm.applyInverse(pose.p), (tm.q.conjugate() * pose.q).normalized()};
  const Vec3 r = tm.q.conjugate() * translation;
  const Aabb box = shapeAabb(moving, local);
  const ConvexProxy a = makeProxy(moving, local);
  std::optional<CastHit> best;
  castMeshTriangles(mesh, box.center(), r, max_fraction, Real(0.5) * box.extent(), [&](int t, Real max_f) {
    const auto& tri = mesh.triangles[t];
    const auto h = gjkRaycast(a, r, makeTriangleProxy(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]),
                              max_f);
    if (h && (!best || h->fraction < best->fraction || (h->fraction == best->fraction && t < best->triangle))) {
      best = h;
      best->triangle = t;
    }
    return best ? std::min(max_f, best->fraction) : max_f;
  });
  if (!best) return std::nullopt;
  best->normal = tm.q * best->normal;
  best->point = best->inside ? pose.p : tm.apply(best->point);
  return best;
}

}  // namespace

bool isConvexQueryShape(const ShapeDesc& s) {
  switch (s.type) {
    case ShapeType::Sphere:
    case ShapeType::Box:
    case ShapeType::Capsule:
    case ShapeType::Cylinder: return true;
    case ShapeType::ConvexHull: return s.hull != nullptr;
    case ShapeType::Plane:
    case ShapeType::Mesh: return false;
  }
  return false;
}

std::optional<CastHit> shapeCast(const ShapeDesc& moving, const Transform& pose, const Vec3& translation,
                                 const ShapeDesc& target, const Transform& target_pose, Real max_fraction) {
  if (!isConvexQueryShape(moving) || translation.squaredNorm() == 0) return std::nullopt;
  switch (target.type) {
    case ShapeType::Plane: return castOntoPlane(moving, pose, translation, target, target_pose, max_fraction);
    case ShapeType::Mesh:
      if (!target.mesh) return std::nullopt;
      return castOntoMesh(moving, pose, translation, *target.mesh, target_pose, max_fraction);
    default:
      if (!isConvexQueryShape(target)) return std::nullopt;
      return gjkRaycast(makeProxy(moving, pose), translation, makeProxy(target, target_pose), max_fraction);
  }
}

}  // namespace cairn
