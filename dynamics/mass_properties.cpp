#include "dynamics/mass_properties.hpp"

namespace cairn {

const char* shapeTypeName(ShapeType t) {
  switch (t) {
    case ShapeType::Sphere: return "sphere";
    case ShapeType::Box: return "box";
    case ShapeType::Capsule: return "capsule";
    case ShapeType::Cylinder: return "cylinder";
    case ShapeType::Plane: return "plane";
    case ShapeType::ConvexHull: return "convex_hull";
    case ShapeType::Mesh: return "mesh";
  }
  return "unknown";
}

namespace {

// Mass properties of a closed polyhedron by summing signed tetrahedra
// (o, a, b, c) over a fan triangulation of each face. The second moment of
// a tetrahedron with edge matrix A = [a-o b-o c-o] is det(A) A C0 A^T with
// C0 = [[2,1,1],[1,2,1],[1,1,2]] / 120 (canonical tetrahedron), and
// I = tr(C) E - C.
//
// The apex o is the mean of the hull's vertices, not the shape's origin: the
// sums are then of vectors as long as the hull is wide, and the second
// moment about the center of mass, C - m c c^T, is a difference of terms of
// the hull's own size. About a far origin (a hull 10 km from its body's
// origin) C and m c c^T would each be ~|c|^2 / width^2 times larger than
// their difference, and that many digits of it would be lost (1e-16 x
// (1e4 / 0.1)^2 = 1e-6 relative for a 0.1 m hull at 10 km, much more
// further out), down to a tensor that is no longer positive definite.
MassProperties hullMassProperties(const ConvexHullData& hull, Real density) {
  if (hull.vertices.empty()) return {};
  Mat3 c0;
  c0 << 2, 1, 1, 1, 2, 1, 1, 1, 2;
  c0 /= Real(120);
  Vec3 o = Vec3::Zero();
  for (const Vec3& v : hull.vertices) o += v;
  o /= Real(hull.vertices.size());
  Real volume = 0;
  Vec3 first_moment = Vec3::Zero();
  Mat3 second_moment = Mat3::Zero();
  for (const auto& face : hull.faces) {
    for (size_t i = 1; i + 1 < face.size(); ++i) {
      Mat3 a;
      a.col(0) = hull.vertices[face[0]] - o;
      a.col(1) = hull.vertices[face[i]] - o;
      a.col(2) = hull.vertices[face[i + 1]] - o;
      const Real det = a.determinant();
      volume += det / Real(6);
      first_moment += det / Real(24) * (a.col(0) + a.col(1) + a.col(2));
      second_moment += det * a * c0 * a.transpose();
    }
  }
  MassProperties mp;
  if (volume <= 0) return mp;
  mp.mass = density * volume;
  const Vec3 center_from_o = first_moment / volume;
  mp.center = o + center_from_o;
  const Mat3 c_com = density * second_moment - mp.mass * center_from_o * center_from_o.transpose();
  mp.inertia = c_com.trace() * Mat3::Identity() - c_com;
  return mp;
}

}  // namespace

Real shapeVolume(const ShapeDesc& s) {
  switch (s.type) {
    case ShapeType::Sphere: return Real(4) / 3 * kPi * s.radius * s.radius * s.radius;
    case ShapeType::Box: return 8 * s.half_extents.prod();
    case ShapeType::Cylinder: return kPi * s.radius * s.radius * 2 * s.half_height;
    case ShapeType::Capsule:
      return kPi * s.radius * s.radius * (2 * s.half_height + Real(4) / 3 * s.radius);
    case ShapeType::ConvexHull: return s.hull ? hullMassProperties(*s.hull, 1).mass : 0;
    case ShapeType::Plane:
    case ShapeType::Mesh: return 0;
  }
  return 0;
}

MassProperties shapeMassProperties(const ShapeDesc& s, Real density) {
  MassProperties mp;
  const Real r = s.radius;
  switch (s.type) {
    case ShapeType::Sphere:
      mp.mass = density * shapeVolume(s);
      mp.inertia = Mat3::Identity() * (Real(0.4) * mp.mass * r * r);
      break;
    case ShapeType::Box: {
      mp.mass = density * shapeVolume(s);
      const Vec3 h2 = s.half_extents.cwiseProduct(s.half_extents);
      mp.inertia = (mp.mass / 3 * Vec3(h2.y() + h2.z(), h2.x() + h2.z(), h2.x() + h2.y())).asDiagonal();
      break;
    }
    case ShapeType::Cylinder: {
      mp.mass = density * shapeVolume(s);
      const Real len = 2 * s.half_height;
      const Real ixx = mp.mass / 12 * (3 * r * r + len * len);
      mp.inertia = Vec3(ixx, Real(0.5) * mp.mass * r * r, ixx).asDiagonal();
      break;
    }
    case ShapeType::Capsule: {
      const Real len = 2 * s.half_height;
      const Real m_cyl = density * kPi * r * r * len;
      const Real m_hemi = density * Real(2) / 3 * kPi * r * r * r;
      mp.mass = m_cyl + 2 * m_hemi;
      const Real iyy = Real(0.5) * m_cyl * r * r + 2 * (Real(0.4) * m_hemi * r * r);
      // Hemisphere: 2/5 m r^2 about its flat-face center, moved to its own
      // center of mass (3/8 r inside), then out to the capsule center.
      const Real hemi_com = Real(3) / 8 * r;
      const Real i_hemi_own = Real(0.4) * m_hemi * r * r - m_hemi * hemi_com * hemi_com;
      const Real d = s.half_height + hemi_com;
      const Real ixx = m_cyl / 12 * (3 * r * r + len * len) + 2 * (i_hemi_own + m_hemi * d * d);
      mp.inertia = Vec3(ixx, iyy, ixx).asDiagonal();
      break;
    }
    case ShapeType::ConvexHull:
      if (s.hull) mp = hullMassProperties(*s.hull, density);
      break;
    case ShapeType::Plane:
    case ShapeType::Mesh:
      break;
  }
  return mp;
}

Mat3 parallelAxis(const Mat3& inertia_com, Real mass, const Vec3& d) {
  return inertia_com + mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
}

MassProperties compoundMassProperties(const std::vector<ShapeDesc>& shapes, Real density) {
  MassProperties total;
  std::vector<MassProperties> parts;
  parts.reserve(shapes.size());
  for (const auto& s : shapes) {
    MassProperties p = shapeMassProperties(s, density);
    // Into the body frame: rotate the tensor, move the center.
    const Mat3 r = s.local.q.toRotationMatrix();
    p.inertia = r * p.inertia * r.transpose();
    p.center = s.local.apply(p.center);
    total.mass += p.mass;
    total.center += p.mass * p.center;
    parts.push_back(p);
  }
  if (total.mass <= 0) return MassProperties{};
  total.center /= total.mass;
  for (const auto& p : parts) total.inertia += parallelAxis(p.inertia, p.mass, p.center - total.center);
  return total;
}

}  // namespace cairn
