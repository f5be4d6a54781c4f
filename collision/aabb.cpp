// World bounds of each shape type (formulas in aabb.hpp).
#include "collision/aabb.hpp"

#include "collision/support.hpp"

namespace cairn {

Aabb shapeAabb(const ShapeDesc& s, const Transform& t) {
  // The rotation matrix only where the box depends on it (not a sphere's).
  switch (s.type) {
    case ShapeType::Sphere: return Aabb::fromCenterHalf(t.p, Vec3::Constant(s.radius));
    case ShapeType::Box: return Aabb::fromCenterHalf(t.p, t.q.toRotationMatrix().cwiseAbs() * s.half_extents);
    case ShapeType::Capsule:
      return Aabb::fromCenterHalf(t.p, t.q.toRotationMatrix().col(1).cwiseAbs() * s.half_height + Vec3::Constant(s.radius));
    case ShapeType::Cylinder: {
      const Vec3 a = t.q.toRotationMatrix().col(1);
      Vec3 half;
      for (int i = 0; i < 3; ++i)
        half[i] = s.half_height * std::abs(a[i]) + s.radius * std::sqrt(std::max(Real(0), 1 - a[i] * a[i]));
      return Aabb::fromCenterHalf(t.p, half);
    }
    case ShapeType::ConvexHull: {
      Aabb box;
      if (s.hull)
        for (const Vec3& v : s.hull->vertices) box.grow(t.apply(v));
      return box;
    }
    case ShapeType::Mesh: {
      Aabb box;
      if (s.mesh)
        for (const Vec3& v : s.mesh->vertices) box.grow(t.apply(v));
      return box;
    }
    case ShapeType::Plane: {
      // Points with n.x <= d. Only an axis-aligned normal bounds anything.
      Vec3 n;
      Real d;
      worldPlane(s, t, n, d);
      Aabb box{Vec3::Constant(-kInf), Vec3::Constant(kInf)};
      for (int i = 0; i < 3; ++i) {
        if (std::abs(n[i]) == 1) {
          if (n[i] > 0) box.hi[i] = d;
          else box.lo[i] = -d;
        }
      }
      return box;
    }
  }
  return Aabb{};
}

Aabb bodyShapeAabb(const ShapeDesc& shape, const Transform& body) {
  // The composition's rotation is a quaternion product, a square root and
  // a division: a third of the proxies' refit on chain-100's links.
  if (shape.type == ShapeType::Sphere) return Aabb::fromCenterHalf(body.apply(shape.local.p), Vec3::Constant(shape.radius));
  return shapeAabb(shape, body * shape.local);
}

}  // namespace cairn
