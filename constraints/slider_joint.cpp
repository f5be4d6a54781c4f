// Slider (prismatic) joint, 5 rows plus an optional limit and motor.
//
//   orientation part  the relative rotation stays as created     (3 rows)
//   two axis rows     d = p_b - p_a has no component along p or q,
//                     the directions perpendicular to the slide axis
//                     fixed in a: C = p.d, q.d                   (2 rows)
//   limit             on s = ax.d, only at or past a bound       (0-1 row)
//   motor             s' -> target, |lambda| <= max force h      (0-1 row)
#include "constraints/joint.hpp"

namespace cairn {

Real sliderPosition(const Joint& j, const BodyView& a, const BodyView& b) {
  return worldVector(a, j.local_axis_a).dot(worldPoint(b, j.local_anchor_b) - worldPoint(a, j.local_anchor_a));
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

  // Rate of s = ax.d with ax fixed in a (the axis part's Jacobian).
  const Vec3 lin_a = -ax, ang_a = -(pb - a.x).cross(ax), lin_b = ax, ang_b = (pb - b.x).cross(ax);
  if (j.def.limit.enabled)
    addLimitPart(ctx, a, b, 5, j.def.limit, ax.dot(d), lin_a, ang_a, lin_b, ang_b, s.restitution_threshold);
  if (j.def.motor.enabled)
    addMotorPart(ctx, a, b, 6, j.def.motor.target_velocity, j.def.motor.max_force, lin_a, ang_a, lin_b, ang_b);
}

}  // namespace cairn
