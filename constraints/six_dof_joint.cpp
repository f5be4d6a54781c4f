// Six-degree-of-freedom joint (Jolt's SixDOFConstraint, Bullet's
// btGeneric6DofSpring2Constraint): each of its six coordinates is free,
// limited or locked, and may have a spring and a motor.
//
// Frames F_a (fixed in a) and F_b (fixed in b) sit at the anchor with
// x = axis, y = axis2 at creation; Q_a, Q_b are their world orientations.
// The coordinates are F_a measured in F_b: a relative to b, the sign of
// every joint coordinate (docs/constraints.md, "Sign conventions").
//
//   translation  s_i = e_i.(p_a - p_b), e_i the axes of F_b; the rate
//                has e_i fixed in b (relativeTravel in parts.hpp)
//   rotation     q = Q_b^* Q_a = q_swing q_twist: a twist about x, then a
//                swing about an axis in the y-z plane (Jolt's
//                SwingTwistConstraintPart). With q = (w, x, y, z),
//                q_swing = (w^2 + x^2, 0, w y - x z, w z + x y) / sqrt(w^2 + x^2):
//                  twist    theta_x = 2 atan2(x, w)
//                  swing    theta_y = 2 atan2(w y - x z, w^2 + x^2)
//                           theta_z = 2 atan2(w z + x y, w^2 + x^2)
//                Each is the angle about its own axis when the others are
//                zero, and the map is singular only at a swing of pi: a
//                limit near 90 degrees holds, where Euler angles lock
//                (Bullet's middle angle is bounded by pi/2).
//                Rate: dq/dt = 1/2 (0, W) q with W = R_b^T (w_a - w_b), so
//                d theta_i/dt = G_i.W with G_i[k] = d theta_i(1/2 (0, e_k) q)
//                and the row is J = [0, R_b G_i, 0, -R_b G_i]: the exact
//                gradient, so limits, springs and motors act on the
//                coordinate they name at any pose.
//
// Rows per axis i: a limit or lock (slot i), a spring (6 + i), a motor
// (12 + i). A spring is an implicit spring-damper toward its rest value
// with no force bound; a motor is addMotorPart's. A locked axis (or
// lower == upper) gets neither: the lock holds it.
#include "constraints/joint.hpp"

#include <cmath>

namespace cairn {

namespace {

// theta = 2 atan2(n, d): d theta = 2 (d dn - n dd) / (n^2 + d^2).
Real halfAngleRate(Real n, Real d, Real dn, Real dd) { return 2 * (d * dn - n * dd) / (n * n + d * d); }

struct Coordinates {
  std::array<Real, kDofCount> s{};
  std::array<RowJacobian, kDofCount> rate;
};

Coordinates coordinates(const Joint& j, const BodyView& a, const BodyView& b) {
  Coordinates c;
  const Vec3 pa = worldPoint(a, j.local_anchor_a), pb = worldPoint(b, j.local_anchor_b);
  const Quat qa = a.q * j.local_frame_a, qb = b.q * j.local_frame_b;
  const Mat3 rb = qb.toRotationMatrix();
  for (int i = 0; i < 3; ++i) {
    const Vec3 e = rb.col(i);
    c.s[i] = e.dot(pa - pb);
    c.rate[i] = relativeTravel(a, b, e, pa, pb, false);
  }
  const Quat q = qb.conjugate() * qa;
  const Real w = q.w(), x = q.x(), y = q.y(), z = q.z();
  const Real d = w * w + x * x, ny = w * y - x * z, nz = w * z + x * y;
  c.s[3] = wrapAngle(2 * std::atan2(x, w));
  c.s[4] = 2 * std::atan2(ny, d);
  c.s[5] = 2 * std::atan2(nz, d);
  Mat3 g;  // row i: G_i, in F_b
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = Vec3::Unit(k);
    const Real dw = -Real(0.5) * e.dot(q.vec());
    const Vec3 dv = Real(0.5) * (w * e + e.cross(q.vec()));
    const Real dd = 2 * (w * dw + x * dv.x());
    g(0, k) = halfAngleRate(x, w, dv.x(), dw);
    g(1, k) = halfAngleRate(ny, d, dw * y + w * dv.y() - dv.x() * z - x * dv.z(), dd);
    g(2, k) = halfAngleRate(nz, d, dw * z + w * dv.z() + dv.x() * y + x * dv.y(), dd);
  }
  for (int i = 0; i < 3; ++i) c.rate[3 + i] = relativeRotation(rb * g.row(i).transpose());
  return c;
}

// The limit a six_dof axis puts on its coordinate.
LimitDef axisLimit(const DofDef& dof) {
  LimitDef l;
  if (dof.mode == DofMode::Limited) l = dof.limit;
  l.enabled = dof.mode != DofMode::Free;  // locked: lower = upper = 0 with the joint's softness
  return l;
}

}  // namespace

std::array<Real, kDofCount> sixDofCoordinates(const Joint& j, const BodyView& a, const BodyView& b) {
  return coordinates(j, a, b).s;
}

void buildSixDofRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx,
                     const JointRowSettings& settings) {
  const Coordinates c = coordinates(j, a, b);
  for (int i = 0; i < kDofCount; ++i) {
    const DofDef& dof = j.def.dofs[static_cast<size_t>(i)];
    const bool angular = i >= 3;
    const LimitDef limit = axisLimit(dof);
    const Real s = angular ? angleNearLimits(c.s[i], limit) : c.s[i];
    ctx.kind = angular ? RowKind::JointAngular : RowKind::JointLinear;
    addLimitPart(ctx, a, b, i, limit, s, c.rate[i], settings.restitution_threshold);
    if (locks(limit)) continue;  // a spring or motor would fight the lock
    if (dof.spring.enabled) {
      const Real stretch = angular ? wrapAngle(s - dof.spring.rest) : s - dof.spring.rest;
      addRow(ctx, a, b, 6 + i, c.rate[i], stretch, &dof.spring.softness);
    }
    if (dof.motor.enabled) addMotorPart(ctx, a, b, 12 + i, dof.motor, s, angular, c.rate[i]);
  }
}

}  // namespace cairn
