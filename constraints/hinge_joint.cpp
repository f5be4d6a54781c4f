// Hinge (revolute) joint, 5 rows plus an optional limit and motor.
//
//   point part       p_b - p_a = 0                              (3 rows)
//   two angle rows   the axes stay parallel: with e = ax_a x ax_b
//                    (the small rotation from a's axis to b's),
//                    C_p = e.p and C_q = e.q for p, q perpendicular
//                    to ax_a; J = [0, -p, 0, p] and [0, -q, 0, q]  (2 rows)
//   limit            on theta, the angle of a about ax_a relative to b
//                    (ODE's dJointGetHingeAngle, Bullet's getHingeAngle),
//                    J = [0, ax_a, 0, -ax_a]                      (0-1 row)
//   motor            theta' -> target_velocity or theta -> target_position,
//                    |lambda| <= max torque h                    (0-1 row)
#include "constraints/joint.hpp"

namespace cairn {

Real hingeAngle(const Joint& j, const BodyView& a, const BodyView& b) {
  return angleAbout(worldVector(a, j.local_axis_a), worldVector(b, j.local_ref_b), worldVector(a, j.local_ref_a));
}

void buildHingeRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx, const JointRowSettings& s) {
  ctx.kind = RowKind::JointLinear;
  addPointPart(ctx, a, b, 0, worldPoint(a, j.local_anchor_a), worldPoint(b, j.local_anchor_b));

  ctx.kind = RowKind::JointAngular;
  const Vec3 ax_a = worldVector(a, j.local_axis_a);
  const Vec3 ax_b = worldVector(b, j.local_axis_b);
  const Vec3 p = worldVector(a, j.local_ref_a);
  const Vec3 q = ax_a.cross(p);
  const Vec3 e = ax_a.cross(ax_b);
  addAnglePart(ctx, a, b, 3, p, e.dot(p));
  addAnglePart(ctx, a, b, 4, q, e.dot(q));

  if (!j.def.limit.enabled && !j.def.motor.enabled) return;
  const Real theta = hingeAngle(j, a, b);
  const RowJacobian rate = relativeRotation(ax_a);
  addLimitPart(ctx, a, b, 5, j.def.limit, angleNearLimits(theta, j.def.limit), rate, s.restitution_threshold);
  if (j.def.motor.enabled && !locks(j.def.limit)) addMotorPart(ctx, a, b, 6, j.def.motor, theta, true, rate);
}

}  // namespace cairn
