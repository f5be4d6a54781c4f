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
inline Vec3 worldPoint(const BodyView& v, const Vec3& local) { return v.x + v.q * local; }
inline Vec3 worldVector(const BodyView& v, const Vec3& local) { return v.q * local; }

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

// Limit on a coordinate s (angle or distance) whose rate is J v for the row
// (lin_a, ang_a, lin_b, ang_b). Adds a row only when s is at or past a
// bound, or would cross it within this step (speculative, so fast joints do
// not overshoot). Restitution applies above the approach speed `threshold`.
void addLimitPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const LimitDef& limit, Real s,
                  const Vec3& lin_a, const Vec3& ang_a, const Vec3& lin_b, const Vec3& ang_b,
                  Real restitution_threshold);

// Velocity motor: drives J v toward `target` with |lambda| <= max_force h.
void addMotorPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, Real target, Real max_force,
                  const Vec3& lin_a, const Vec3& ang_a, const Vec3& lin_b, const Vec3& ang_b);

// Angle of rotation of b relative to a about `axis` (world), measured with
// reference vectors perpendicular to it: atan2((ref_a x ref_b).axis, ref_a.ref_b).
Real angleAbout(const Vec3& axis, const Vec3& ref_a, const Vec3& ref_b);

}  // namespace cairn
