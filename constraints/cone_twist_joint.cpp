// Cone-twist joint (ragdoll shoulders and hips): a ball joint whose twist
// axis on b must stay inside a cone about the twist axis on a, and whose
// twist about that axis stays within limits.
//
//   point part   p_b - p_a = 0                                   (3 rows)
//   swing        theta_s = angle(t_a, t_b); the cone is elliptical with
//                half-angles s1 (toward a's reference axis) and s2 (toward
//                t_a x ref): the span in the swing direction phi is
//                1 / sqrt((cos phi / s1)^2 + (sin phi / s2)^2). One row about
//                n = t_a x t_b / |.|, only at or past the cone     (0-1 row)
//   twist        the twist part of the swing-twist decomposition of a's
//                rotation away from its rest pose relative to b (the
//                sign of every joint coordinate, docs/constraints.md);
//                one limit row about t_b, only at or past a bound (0-1 row)
#include "constraints/joint.hpp"

#include <cmath>

namespace cairn {

void coneTwistAngles(const Joint& j, const BodyView& a, const BodyView& b, Real& swing, Real& twist) {
  const Vec3 ta = worldVector(a, j.local_axis_a), tb = worldVector(b, j.local_axis_b);
  swing = std::acos(std::clamp(ta.dot(tb), Real(-1), Real(1)));
  // Deviation of b from its rest orientation relative to a, in b's frame;
  // a's twist relative to b is the opposite of b's relative to a.
  const Quat d = (a.q * j.rel_orientation0).conjugate() * b.q;
  const Real proj = d.vec().dot(j.local_axis_b);
  twist = wrapAngle(-2 * std::atan2(proj, d.w()));
}

void buildConeTwistRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx,
                        const JointRowSettings& s) {
  ctx.kind = RowKind::JointLinear;
  addPointPart(ctx, a, b, 0, worldPoint(a, j.local_anchor_a), worldPoint(b, j.local_anchor_b));

  const Vec3 ta = worldVector(a, j.local_axis_a), tb = worldVector(b, j.local_axis_b);
  Real swing, twist;
  coneTwistAngles(j, a, b, swing, twist);

  // Swing axis: t_a x t_b, or, while the axes are aligned, the direction the
  // relative spin is about to swing them (so a fast swing that would cross
  // the cone within this step is caught speculatively).
  Vec3 n = ta.cross(tb);
  if (n.norm() < Real(1e-9)) {
    const Vec3 w_rel = b.w - a.w;
    n = w_rel - ta * ta.dot(w_rel);
  }
  if (n.norm() > Real(1e-12)) {
    n.normalize();
    const Vec3 ref = worldVector(a, j.local_ref_a);
    const Vec3 dir = n.cross(ta);  // where t_b leans, in the plane normal to t_a
    const Real phi = std::atan2(dir.dot(ta.cross(ref)), dir.dot(ref));
    const Real c = std::cos(phi) / j.def.swing_span1, sn = std::sin(phi) / j.def.swing_span2;
    LimitDef cone;
    cone.enabled = true;
    cone.lower = -kInf;
    cone.upper = 1 / std::sqrt(c * c + sn * sn);
    cone.softness = j.def.limit.softness;
    RowJacobian opening;  // the swing angle grows with (w_b - w_a).n
    opening.ang_a = -n;
    opening.ang_b = n;
    addLimitPart(ctx, a, b, 3, cone, swing, opening, s.restitution_threshold);
  }
  if (j.def.limit.enabled) addLimitPart(ctx, a, b, 4, j.def.limit, angleNearLimits(twist, j.def.limit), relativeRotation(tb),
                                           s.restitution_threshold);
}

}  // namespace cairn
