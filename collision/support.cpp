// Support mappings of the primitive shapes (closed forms in support.hpp).
#include "collision/support.hpp"

namespace cairn {

namespace {
inline Real sgn(Real x) { return x < 0 ? Real(-1) : Real(1); }
}  // namespace

Real coreRadius(const ShapeDesc& s) {
  return (s.type == ShapeType::Sphere || s.type == ShapeType::Capsule) ? s.radius : Real(0);
}

int hullSupportIndex(const ConvexHullData& h, const Vec3& d) {
  int best = 0;
  Real best_dot = -kInf;
  for (int i = 0; i < static_cast<int>(h.vertices.size()); ++i) {
    const Real dot = d.dot(h.vertices[i]);
    if (dot > best_dot) best_dot = dot, best = i;
  }
  return best;
}

Vec3 supportCoreLocal(const ShapeDesc& s, const Vec3& d) {
  switch (s.type) {
    case ShapeType::Sphere: return Vec3::Zero();
    case ShapeType::Capsule: return Vec3(0, sgn(d.y()) * s.half_height, 0);
    case ShapeType::Box:
      return Vec3(sgn(d.x()) * s.half_extents.x(), sgn(d.y()) * s.half_extents.y(), sgn(d.z()) * s.half_extents.z());
    case ShapeType::Cylinder: {
      const Real radial = std::sqrt(d.x() * d.x() + d.z() * d.z());
      // Along the axis every rim point is a support point; the cap center is
      // the symmetric (and continuous in the limit) choice.
      const Real k = radial > 0 ? s.radius / radial : Real(0);
      return Vec3(k * d.x(), sgn(d.y()) * s.half_height, k * d.z());
    }
    case ShapeType::ConvexHull: return s.hull ? s.hull->vertices[hullSupportIndex(*s.hull, d)] : Vec3::Zero();
    case ShapeType::Mesh: {
      if (!s.mesh || s.mesh->vertices.empty()) return Vec3::Zero();
      Vec3 best = s.mesh->vertices[0];
      for (const Vec3& v : s.mesh->vertices)
        if (d.dot(v) > d.dot(best)) best = v;
      return best;
    }
    case ShapeType::Plane: return s.normal * (s.offset / s.normal.squaredNorm());
  }
  return Vec3::Zero();
}

Vec3 supportLocal(const ShapeDesc& s, const Vec3& d) {
  const Vec3 core = supportCoreLocal(s, d);
  const Real r = coreRadius(s);
  if (r <= 0) return core;
  const Real len = d.norm();
  // A zero direction has no farthest point; any point of the surface will do.
  return len > 0 ? Vec3(core + d * (r / len)) : Vec3(core + Vec3(r, 0, 0));
}

}  // namespace cairn
