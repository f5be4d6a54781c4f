// Constraint parts: the small reusable pieces joints are made of (after
// Jolt's AxisConstraintPart / PointConstraintPart / AngleConstraintPart).
// Each part writes finished rows (J, M^-1 J^T, 1/(A_ii + cfm), rhs, bounds)
// into the step's row array.
//
// Notation: body a and b with centers x_a, x_b; anchors p_a, p_b (world);
// r_a = p_a - x_a, r_b = p_b - x_b. A linear row along unit n has
//   J = [ -n^T, -(r_a x n)^T, n^T, (r_b x n)^T ]      (d/dt of n.(p_b - p_a))
// and an angular row about unit axis u has
//   J = [ 0, -u^T, 0, u^T ]                           (u . (w_b - w_a)).
// Those are the bilateral rows, where the sign does not matter. Limits and
// motors act on a joint coordinate measured as body a relative to body b
// (ODE's and Bullet's convention, docs/constraints.md "Sign conventions"),
// and take its rate as a RowJacobian:
//   rotation of a relative to b about u:   J = [ 0, u, 0, -u ]
//   travel n.(p_a - p_b), n fixed in a:    J = [ n, (p_b - x_a) x n, -n, -(r_b x n) ]
//   travel n.(p_a - p_b), n fixed in b:    J = [ n, r_a x n, -n, -((p_a - x_b) x n) ]
// (d/dt n = w x n for the body n is fixed in: its lever arm reaches the
// other anchor, so the rows are exact for separated anchors).
#pragma once

#include "constraints/row.hpp"
#include "constraints/softness.hpp"
#include "cairn/defs.hpp"

#include <vector>

namespace cairn {

// The parts of a body a row needs. The world is a static BodyView at the
// origin with zero inverse mass.
struct BodyView {
  std::int32_t solver_index = 0;  // 0 = world
  Vec3 x = Vec3::Zero();
  Quat q = Quat::Identity();
  Mat3 rot = Mat3::Identity();
  Real inv_mass = 0;
  Vec3 lin_factor = Vec3::Ones();   // 0 on world axes the body's translation is locked along
  Mat3 inv_inertia = Mat3::Zero();  // world frame (projected when rotations are locked)
  Vec3 v = Vec3::Zero(), w = Vec3::Zero();
};

// World-frame points and vectors fixed in a body, at its current pose.
inline Vec3 worldPoint(const BodyView& v, const Vec3& local) { return rotateAdd(v.x, v.q, local); }
inline Vec3 worldVector(const BodyView& v, const Vec3& local) { return rotate(v.q, local); }

// The rate of a joint coordinate: lin_a.v_a + ang_a.w_a + lin_b.v_b + ang_b.w_b.
struct RowJacobian {
  Vec3 lin_a = Vec3::Zero(), ang_a = Vec3::Zero();
  Vec3 lin_b = Vec3::Zero(), ang_b = Vec3::Zero();
  Real rate(const BodyView& a, const BodyView& b) const {
    return lin_a.dot(a.v) + ang_a.dot(a.w) + lin_b.dot(b.v) + ang_b.dot(b.w);
  }
};

// Rotation of a relative to b about the world axis u (unit).
RowJacobian relativeRotation(const Vec3& u);
// Travel n.(p_a - p_b) along the world direction n (unit), n fixed in a
// (`fixed_in_a`) or in b.
RowJacobian relativeTravel(const BodyView& a, const BodyView& b, const Vec3& n, const Vec3& p_a, const Vec3& p_b,
                           bool fixed_in_a);

// 1 / (J M^-1 J^T): the mass the row moves (0 when neither body can move).
Real effectiveMass(const BodyView& a, const BodyView& b, const RowJacobian& j);

// Everything a row builder needs besides the bodies.
struct RowContext {
  Real h = Real(1) / 60;
  Real erp = Real(0.2);  // global
  Real cfm = 0;          // global, ODE units
  const Softness* joint_softness = nullptr;
  std::int32_t owner = -1;
  RowKind kind = RowKind::JointLinear;
  std::vector<ConstraintRow>* rows = nullptr;
  const std::vector<Real>* warm = nullptr;  // carried impulses per owner row slot
  Real warm_factor = 1;
  // How rows with the default softness correct their position error. Rows
  // with a softness of their own keep it in rhs: there ERP and CFM stand for
  // a real spring-damper and must act on the velocities in the same solve.
  Correction correction = Correction::InRhs;
  // Cap on the speed a rigid linear row's position feedback -ERP/h C may ask
  // for (m/s), as contacts cap their push-out (settings.max_correction_velocity).
  Real max_correction_velocity = kInf;
  // Set by a part whose rows share one error vector (the point part): the
  // vector's length, so the cap scales its rows together and keeps the
  // correction's direction. 0: each row's own |C|.
  Real shared_error_norm = 0;
};

// Appends one row from its Jacobian. C is the position error (the row
// drives J v toward -ERP/h C); `axis_softness` overrides the joint's.
// Returns the row index, or -1 when the row cannot act (both bodies fixed).
int addRow(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const Vec3& lin_a,
           const Vec3& ang_a, const Vec3& lin_b, const Vec3& ang_b, Real position_error,
           const Softness* axis_softness = nullptr, Real lo = -kInf, Real hi = kInf);
inline int addRow(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const RowJacobian& j,
                  Real position_error, const Softness* axis_softness = nullptr, Real lo = -kInf, Real hi = kInf) {
  return addRow(ctx, a, b, slot, j.lin_a, j.ang_a, j.lin_b, j.ang_b, position_error, axis_softness, lo, hi);
}

// Point part (3 rows): p_a and p_b coincide. Rows along the world axes.
void addPointPart(RowContext& ctx, const BodyView& a, const BodyView& b, int first_slot, const Vec3& p_a,
                  const Vec3& p_b);

// Axis part (1 row): n . (p_b - p_a) = target. For sliders the lever arm of
// body a is taken to p_b so that the row is exact for separated anchors.
int addAxisPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const Vec3& n, const Vec3& p_a,
                const Vec3& p_b, Real position_error, const Softness* axis_softness = nullptr,
                Real lo = -kInf, Real hi = kInf);

// Angle part (1 row): relative angular velocity about u, with the given
// angle error (rad).
int addAnglePart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const Vec3& u, Real angle_error,
                 const Softness* axis_softness = nullptr, Real lo = -kInf, Real hi = kInf);

// Orientation lock (3 rows): the relative rotation of b to a stays q_rel0.
void addOrientationPart(RowContext& ctx, const BodyView& a, const BodyView& b, int first_slot, const Quat& q_rel0);

// Limit on a coordinate s (angle or distance) whose rate is J v (one row).
//  - lower == upper: a bilateral row holding s there (a locked axis);
//  - a spring softness (the limit's, else the joint's: stiffness/damping or
//    frequency): past a bound, a bilateral spring-damper row toward it (it
//    pushes back and brakes the return alike), none inside the range;
//  - rigid: a unilateral row only when s is at or past a bound, or would
//    cross it within this step (speculative, so fast joints do not
//    overshoot). Restitution applies above the approach speed `threshold`.
void addLimitPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const LimitDef& limit, Real s,
                  const RowJacobian& j, Real restitution_threshold);

// Motor on a coordinate s with rate J v (one row, |lambda| <= max_force h):
// a velocity motor drives J v to target_velocity (rigid, or through its
// damper); a position motor drives s to target_position through an
// implicit spring-damper (MotorDef). `angular`: s is an angle, and the
// servo takes the short way round (error wrapped into (-pi, pi]).
void addMotorPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const MotorDef& motor, Real s,
                  bool angular, const RowJacobian& j);

// The softness a position motor's row uses (MotorDef): the motor's own,
// 2 Hz critically damped when unset, critically damped (c = 2 sqrt(k m))
// when only a stiffness is given; `effective_mass` is the row's.
Softness servoSoftness(const Softness& motor_softness, Real effective_mass);

// A limit with lower == upper holds its coordinate: a motor (or a spring)
// on it has nothing to move, and ODE and Bullet switch it off
// (dxJointLimitMotor::addLimot, btHingeConstraint::getInfo2Internal: "the
// joint motor is ineffective"); cairn builds no row for it.
inline bool locks(const LimitDef& l) { return l.enabled && l.lower == l.upper; }

// True for the spring spellings (stiffness/damping, frequency/damping_ratio).
inline bool isSpring(const Softness& s) { return s.stiffness || s.damping || s.frequency || s.damping_ratio; }

// x wrapped into (-pi, pi].
Real wrapAngle(Real x);

// The angle s (in (-pi, pi]) or s -+ 2 pi, whichever is nearer the limit's
// range, so that a range reaching past +-pi is not crossed the long way
// round (Bullet's btAdjustAngleToLimits); for lower == upper, the
// representative nearest the locked value.
Real angleNearLimits(Real s, const LimitDef& limit);

// Angle of the rotation taking `from` to `to` about `axis` (world), both
// perpendicular to it: atan2((from x to).axis, from.to).
Real angleAbout(const Vec3& axis, const Vec3& from, const Vec3& to);

}  // namespace cairn
