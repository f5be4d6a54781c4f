// Sphere against sphere, capsule and box: closed forms.
//
// Sphere-sphere (and sphere-capsule, after finding the point q of the
// capsule's segment nearest the sphere center):
//   d = c_b - c_a,  n = d / |d|,  depth = r_a + r_b - |d|,
//   surface points c_a + r_a n and c_b - r_b n, contact halfway between.
// Coincident centers have no direction; +y (or, against a capsule, a fixed
// direction perpendicular to its axis) keeps the output finite.
//
// Sphere-box (Ericson 5.1.3), in the box frame: clamp the center c to the
// box, q = clamp(c, -h, h). Outside, n = (c - q) / |c - q| and
// depth = r - |c - q|. Inside (q = c) the nearest face is the axis i with the
// least h_i - |c_i|: n = sgn(c_i) e_i, depth = r + h_i - |c_i|. The feature
// id says which faces clamped the center (face, edge or corner region), the
// same code inside and outside a face so it survives sinking in.
#include "collision/closest_points.hpp"
#include "collision/narrowphase.hpp"

namespace cairn::narrow {
namespace {

int spherePair(const Vec3& ca, Real ra, const Vec3& cb, Real rb, const Vec3& fallback, Real margin, Out& out) {
  const Vec3 d = cb - ca;
  const Real dist = d.norm();
  if (dist - ra - rb > margin) return 0;
  const Real tiny = Real(1e-12) * (ra + rb);
  const Vec3 n = dist > tiny ? Vec3(d / dist) : fallback;
  Manifold& m = out.emplace_back();
  m.normal = n;
  m.count = 1;
  m.points[0] = ContactPoint{Real(0.5) * ((ca + n * ra) + (cb - n * rb)), ra + rb - dist, 0};
  return 1;
}

}  // namespace

int sphereSphere(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  return spherePair(ta.p, a.radius, tb.p, b.radius, Vec3::UnitY(), margin, out);
}

int sphereCapsule(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  const Vec3 axis = tb.q * Vec3::UnitY();
  const Vec3 q = closestOnSegment(ta.p, tb.p - axis * b.half_height, tb.p + axis * b.half_height);
  // Center on the axis: push out sideways, never along the axis.
  return spherePair(ta.p, a.radius, q, b.radius, anyPerpendicular(axis), margin, out);
}

int sphereBox(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  const Vec3 h = b.half_extents;
  const Vec3 c = tb.applyInverse(ta.p);
  const Vec3 q = c.cwiseMax(-h).cwiseMin(h);
  const Real r = a.radius;
  Vec3 n_local;  // from the box toward the sphere
  Real depth;
  Vec3 box_point = q;
  std::uint32_t code = 0;
  const Vec3 diff = c - q;
  const Real dist = diff.norm();
  if (dist > 0) {
    if (dist - r > margin) return 0;
    n_local = diff / dist;
    depth = r - dist;
    for (int i = 2; i >= 0; --i) code = code * 3 + (c[i] > h[i] ? 1u : c[i] < -h[i] ? 2u : 0u);
  } else {
    int axis = 0;
    (h - c.cwiseAbs()).minCoeff(&axis);
    const Real s = c[axis] < 0 ? Real(-1) : Real(1);
    n_local = Vec3::Unit(axis) * s;
    depth = r + h[axis] - std::abs(c[axis]);
    box_point[axis] = s * h[axis];
    for (int i = 2; i >= 0; --i) code = code * 3 + (i == axis ? (s > 0 ? 1u : 2u) : 0u);
  }
  const Vec3 n = tb.q * (-n_local);  // sphere (A) toward box (B)
  const Vec3 sphere_point = ta.p + n * r;
  Manifold& m = out.emplace_back();
  m.normal = n;
  m.count = 1;
  m.points[0] = ContactPoint{Real(0.5) * (sphere_point + tb.apply(box_point)), depth, code};
  return 1;
}

}  // namespace cairn::narrow
