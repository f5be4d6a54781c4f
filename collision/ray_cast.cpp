// Ray casts against the convex shapes and the plane, in closed form in the
// shape's frame (conventions in ray_cast.hpp). The segment is moved into the
// frame, o + f d; fractions do not change under a rigid motion, and the hit
// point is computed in world space from the fraction.
//
// Entering a quadric: |o + f d|^2 = r^2 (sphere, or the infinite cylinder
// with the axial components dropped) is
//   a f^2 + 2 b f + c = 0,   a = d.d,  b = o.d,  c = o.o - r^2.
// The segment enters at the smaller root when it starts outside or on the
// surface (c >= 0) and moves inward (b < 0) and the line meets it
// (b^2 - a c >= 0). That root, written
//   f = c / (-b + sqrt(b^2 - a c)),
// avoids the cancellation of (-b - sqrt(.)) / a when a c << b^2.
//
// sphere    the quadric; normal (x - 0) / |x|.
// box       slabs (aabb.hpp) on [-h, h]: the segment's line is inside for
//           f in [t_near, t_far]; it enters at t_near >= 0 through the
//           face of the axis that set t_near, normal -sgn(d_i) e_i.
// capsule   the union of the side (the infinite cylinder of radius r about
//           y, where |y| <= hh) and the two cap spheres at y = +-hh. Each
//           part is convex and the first entry into a union is the first
//           entry into any part (a sphere entered at |y| < hh is entered
//           from inside the capsule, never first), so the answer is the
//           smallest valid entry.
// cylinder  the side (as the capsule's, |y| <= hh) and the caps: the plane
//           y = hh is entered at f = (hh - o_y) / d_y when o_y >= hh and
//           d_y < 0, valid where x^2 + z^2 <= r^2 (and mirrored below).
// hull      Cyrus and Beck, "Generalized Two- and Three-Dimensional
//           Clipping", 1978: each face plane n.x <= e bounds f by
//           (e - n.o) / (n.d), from below where n.d < 0 (entering) and from
//           above where n.d > 0; the entry is the largest lower bound, on
//           that face.
// plane     n.x <= e: s = n.o - e; entered at f = s / (-n.d) when s >= 0 and
//           n.d < 0.
// The origin is strictly inside when its signed distance is negative: the
// quadric's c < 0, every slab or face plane strictly holding it.
#include "collision/ray_cast.hpp"

#include "collision/aabb.hpp"
#include "collision/support.hpp"

namespace cairn {
namespace {

// The entering root of a f^2 + 2 b f + c = 0 (see the top of the file), or
// +infinity when the segment does not enter.
Real enterQuadric(Real a, Real b, Real c) {
  if (c < 0 || b >= 0) return kInf;
  const Real disc = b * b - a * c;
  if (disc < 0) return kInf;
  return c / (-b + std::sqrt(disc));
}

// A hit candidate in the shape's frame: fraction and outward normal.
struct Entry {
  Real f = kInf;
  Vec3 n = Vec3::UnitY();
  void keep(Real f_new, const Vec3& n_new) {
    if (f_new < f) f = f_new, n = n_new;
  }
};

Entry sphereEntry(const Vec3& o, const Vec3& d, const Vec3& center, Real r) {
  const Vec3 oc = o - center;
  Entry e;
  e.f = enterQuadric(d.dot(d), oc.dot(d), oc.dot(oc) - r * r);
  if (e.f < kInf) e.n = (oc + e.f * d).normalized();
  return e;
}

// The side of a capsule or cylinder: the infinite cylinder about y, where
// the hit lies within |y| <= hh.
Entry sideEntry(const Vec3& o, const Vec3& d, Real r, Real hh) {
  Entry e;
  const Real f = enterQuadric(d.x() * d.x() + d.z() * d.z(), o.x() * d.x() + o.z() * d.z(),
                              o.x() * o.x() + o.z() * o.z() - r * r);
  if (f == kInf || std::abs(o.y() + f * d.y()) > hh) return e;
  e.f = f;
  e.n = Vec3(o.x() + f * d.x(), 0, o.z() + f * d.z()).normalized();
  return e;
}

Entry boxEntry(const Vec3& h, const Vec3& o, const Vec3& d) {
  Real t0 = -kInf, t1 = kInf;
  int axis = -1;
  Entry e;
  if (!clipLineToBox(-h, h, o, d.cwiseInverse(), t0, t1, &axis) || axis < 0 || t0 < 0) return e;
  e.f = t0;
  e.n = Vec3::Zero();
  e.n[axis] = d[axis] > 0 ? Real(-1) : Real(1);
  return e;
}

Entry capsuleEntry(Real r, Real hh, const Vec3& o, const Vec3& d) {
  Entry e = sideEntry(o, d, r, hh);
  for (const Real y : {hh, -hh}) {
    const Entry s = sphereEntry(o, d, Vec3(0, y, 0), r);
    e.keep(s.f, s.n);
  }
  return e;
}

Entry cylinderEntry(Real r, Real hh, const Vec3& o, const Vec3& d) {
  Entry e = sideEntry(o, d, r, hh);
  for (const Real sign : {Real(1), Real(-1)}) {
    // Cap at y = sign * hh, outward normal sign * e_y.
    const Real oy = sign * o.y(), dy = sign * d.y();
    if (oy < hh || dy >= 0) continue;
    const Real f = (hh - oy) / dy;
    const Real x = o.x() + f * d.x(), z = o.z() + f * d.z();
    if (x * x + z * z <= r * r) e.keep(f, Vec3(0, sign, 0));
  }
  return e;
}

Entry hullEntry(const ConvexHullData& h, const Vec3& o, const Vec3& d) {
  Real t0 = -kInf, t1 = kInf;
  int face = -1;
  Entry e;
  for (size_t k = 0; k < h.face_normals.size(); ++k) {
    const Vec3& n = h.face_normals[k];
    const Real num = h.face_offsets[k] - n.dot(o), den = n.dot(d);
    if (den == 0) {
      if (num < 0) return e;  // parallel and outside this face
      continue;
    }
    const Real t = num / den;
    if (den < 0 && t > t0) t0 = t, face = static_cast<int>(k);
    if (den > 0 && t < t1) t1 = t;
    if (t0 > t1) return e;
  }
  if (face < 0 || t0 < 0) return e;
  e.f = t0;
  e.n = h.face_normals[static_cast<size_t>(face)];
  return e;
}

bool strictlyInside(const ShapeDesc& s, const Vec3& o) {
  switch (s.type) {
    case ShapeType::Sphere: return o.squaredNorm() < s.radius * s.radius;
    case ShapeType::Box: return (o.cwiseAbs().array() < s.half_extents.array()).all();
    case ShapeType::Capsule: {
      const Real y = std::clamp(o.y(), -s.half_height, s.half_height);
      return (o - Vec3(0, y, 0)).squaredNorm() < s.radius * s.radius;
    }
    case ShapeType::Cylinder:
      return o.x() * o.x() + o.z() * o.z() < s.radius * s.radius && std::abs(o.y()) < s.half_height;
    case ShapeType::ConvexHull:
      for (size_t k = 0; k < s.hull->face_normals.size(); ++k)
        if (!(s.hull->face_normals[k].dot(o) < s.hull->face_offsets[k])) return false;
      return true;
    case ShapeType::Plane:
    case ShapeType::Mesh: break;
  }
  return false;
}

}  // namespace

std::optional<CastHit> rayCast(const ShapeDesc& s, const Transform& t, const Vec3& origin, const Vec3& translation,
                               Real max_fraction) {
  if (translation.squaredNorm() == 0) return std::nullopt;
  if (s.type == ShapeType::ConvexHull && !s.hull) return std::nullopt;
  CastHit hit;
  if (s.type == ShapeType::Plane) {
    Vec3 n;
    Real e;
    worldPlane(s, t, n, e);
    const Real dist = n.dot(origin) - e, den = n.dot(translation);
    if (dist < 0) {
      hit.inside = true;
    } else {
      if (den >= 0 || dist > -den * max_fraction) return std::nullopt;
      hit.fraction = dist / -den;
      hit.normal = n;
    }
  } else if (s.type == ShapeType::Mesh) {
    if (!s.mesh) return std::nullopt;
    const auto local = rayCastMeshLocal(*s.mesh, t.applyInverse(origin), t.q.conjugate() * translation, max_fraction);
    if (!local) return std::nullopt;
    hit = *local;
    hit.normal = t.q * local->normal;
  } else {
    const Vec3 o = t.applyInverse(origin), d = t.q.conjugate() * translation;
    if (strictlyInside(s, o)) {
      hit.inside = true;
    } else {
      Entry e;
      switch (s.type) {
        case ShapeType::Sphere: e = sphereEntry(o, d, Vec3::Zero(), s.radius); break;
        case ShapeType::Box: e = boxEntry(s.half_extents, o, d); break;
        case ShapeType::Capsule: e = capsuleEntry(s.radius, s.half_height, o, d); break;
        case ShapeType::Cylinder: e = cylinderEntry(s.radius, s.half_height, o, d); break;
        case ShapeType::ConvexHull: e = hullEntry(*s.hull, o, d); break;
        case ShapeType::Plane:
        case ShapeType::Mesh: break;
      }
      if (!(e.f <= max_fraction)) return std::nullopt;
      hit.fraction = e.f;
      hit.normal = t.q * e.n;
    }
  }
  if (hit.inside) hit.normal = -translation.normalized();
  hit.point = origin + hit.fraction * translation;
  return hit;
}

}  // namespace cairn
