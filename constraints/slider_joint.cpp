// Slider (prismatic) joint, 5 rows plus an optional limit and motor.
//
//   orientation part  the relative rotation stays as created     (3 rows)
//   two axis rows     d = p_b - p_a has no component along p or q,
//                     the directions perpendicular to the slide axis
//                     fixed in a: C = p.d, q.d                   (2 rows)
//   limit             on s = ax.(p_a - p_b), the travel of a relative
//                     to b along the axis fixed in a (ODE's
//                     dJointGetSliderPosition), only at or past a
//                     bound                                      (0-1 row)
//   motor             s' -> target_velocity or s -> target_position,
//                     |lambda| <= max force h                    (0-1 row)
#include "constraints/joint.hpp"

namespace cairn {

Real sliderPosition(const Joint& j, const BodyView& a, const BodyView& b) {
  return worldVector(a, j.local_axis_a).dot(worldPoint(a, j.local_anchor_a) - worldPoint(b, j.local_anchor_b));
}

void buildSliderRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx, const JointRowSettings& s) {
  ctx.kind = RowKind::JointAngular;
  addOrientationPart(ctx, a, b, 0, j.rel_orientation0);

  ctx.kind = RowKind::JointLinear;
  const Vec3 pa = worldPoint(a, j.local_anchor_a), pb = worldPoint(b, j.local_anchor_b);
  const Vec3 ax = worldVector(a, j.local_axis_a);
  const Vec3 p = worldVector(a, j.local_ref_a);
  const Vec3 q = ax.cross(p);
  const Vec3 d = pb - pa;
  addAxisPart(ctx, a, b, 3, p, pa, pb, p.dot(d));
  addAxisPart(ctx, a, b, 4, q, pa, pb, q.dot(d));

  if (!j.def.limit.enabled && !j.def.motor.enabled) return;
  const Real travel = -ax.dot(d);
  const RowJacobian rate = relativeTravel(a, b, ax, pa, pb, true);
  addLimitPart(ctx, a, b, 5, j.def.limit, travel, rate, s.restitution_threshold);
  if (j.def.motor.enabled && !locks(j.def.limit)) addMotorPart(ctx, a, b, 6, j.def.motor, travel, false, rate);
}

}  // namespace cairn
