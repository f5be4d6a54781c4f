// Convex proxies: world-space support mappings over the local closed forms.
#include "collision/convex_proxy.hpp"

#include "collision/support.hpp"

namespace cairn {

Vec3 ConvexProxy::supportCore(const Vec3& d) const {
  switch (kind) {
    case Kind::Point: return p;
    case Kind::Segment: return p + r.col(1) * (r.col(1).dot(d) < 0 ? -half_height : half_height);
    case Kind::Box: {
      const Vec3 dl = r.transpose() * d;
      return p + r * Vec3(dl.x() < 0 ? -half_extents.x() : half_extents.x(),
                          dl.y() < 0 ? -half_extents.y() : half_extents.y(),
                          dl.z() < 0 ? -half_extents.z() : half_extents.z());
    }
    case Kind::Cylinder: {
      // In the local frame the radial part (dx, 0, dz) is exactly
      // perpendicular to the axis; computing d - a (a.d) in world space
      // instead leaves a round-off residue that, normalized when d is along
      // the axis, points anywhere.
      const Vec3 dl = r.transpose() * d;
      const Real len = std::hypot(dl.x(), dl.z());
      const Real k = len > 0 ? cylinder_radius / len : Real(0);
      return p + r * Vec3(k * dl.x(), dl.y() < 0 ? -half_height : half_height, k * dl.z());
    }
    case Kind::Hull: return p + r * hull->vertices[hullSupportIndex(*hull, r.transpose() * d)];
    case Kind::Polygon: {
      int best = 0;
      for (int i = 1; i < poly_count; ++i)
        if (d.dot(poly[i]) > d.dot(poly[best])) best = i;
      return poly[best];
    }
  }
  return p;
}

Vec3 ConvexProxy::center() const {
  if (kind != Kind::Polygon) return p;
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < poly_count; ++i) c += poly[i];
  return c / Real(poly_count);
}

ConvexProxy makeProxy(const ShapeDesc& s, const Transform& t) {
  ConvexProxy x;
  x.p = t.p;
  x.r = t.q.toRotationMatrix();
  switch (s.type) {
    case ShapeType::Sphere:
      x.kind = ConvexProxy::Kind::Point;
      x.radius = s.radius;
      x.scale = s.radius;
      break;
    case ShapeType::Capsule:
      x.kind = ConvexProxy::Kind::Segment;
      x.radius = s.radius;
      x.half_height = s.half_height;
      x.scale = s.radius + s.half_height;
      break;
    case ShapeType::Box:
      x.kind = ConvexProxy::Kind::Box;
      x.half_extents = s.half_extents;
      x.scale = s.half_extents.norm();
      break;
    case ShapeType::Cylinder:
      x.kind = ConvexProxy::Kind::Cylinder;
      x.cylinder_radius = s.radius;
      x.half_height = s.half_height;
      x.scale = std::sqrt(s.radius * s.radius + s.half_height * s.half_height);
      break;
    case ShapeType::ConvexHull: {
      x.kind = ConvexProxy::Kind::Hull;
      x.hull = s.hull.get();
      Real m = 0;
      for (const Vec3& v : s.hull->vertices) m = std::max(m, v.norm());
      x.scale = m;
      break;
    }
    case ShapeType::Plane:
    case ShapeType::Mesh: break;  // not convex solids: never proxied
  }
  if (!(x.scale > 0)) x.scale = 1;
  return x;
}

ConvexProxy makeTriangleProxy(const Vec3& a, const Vec3& b, const Vec3& c) {
  ConvexProxy x;
  x.kind = ConvexProxy::Kind::Polygon;
  x.poly[0] = a;
  x.poly[1] = b;
  x.poly[2] = c;
  x.poly_count = 3;
  x.p = x.center();
  x.scale = std::max({(a - x.p).norm(), (b - x.p).norm(), (c - x.p).norm()});
  if (!(x.scale > 0)) x.scale = 1;
  return x;
}

}  // namespace cairn
