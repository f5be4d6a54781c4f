#include "constraints/parts.hpp"

#include <algorithm>
#include <cmath>

namespace cairn {

namespace {

// The position feedback -ERP/h C, with the safety cap: a rigid (CFM = 0)
// linear row never asks for more than max_correction_velocity, whatever the
// mode it is solved in, so a joint pulled metres apart closes at a bounded
// speed instead of being flung together (a 10 m gap at ERP 0.2, h = 1/60
// would ask 120 m/s). Soft rows (CFM > 0) are implicit springs, stable at
// any stretch, and keep their force law; angular rows are left alone (an
// angle error is at most pi, so -ERP/h C is bounded already).
Real correctionBias(const RowContext& ctx, const ErpCfm& soft, Real c, const Vec3& lin_a, const Vec3& lin_b) {
  const Real bias = -soft.erp / ctx.h * c;
  const bool linear = lin_a.squaredNorm() + lin_b.squaredNorm() > 0;
  if (!linear || soft.cfm > 0 || !(ctx.max_correction_velocity < kInf)) return bias;
  const Real norm = std::max(std::abs(c), ctx.shared_error_norm);
  const Real asked = soft.erp / ctx.h * norm;
  return asked > ctx.max_correction_velocity ? bias * (ctx.max_correction_velocity / asked) : bias;
}

// A speculative limit row (the bound not reached yet): its target is the
// rate that closes the gap within the step, in the velocity pass and in a
// separate correction pass alike. Left at the bias pass's zero (no
// position error), that pass would stop the joint a step short of the
// bound and leave Baumgarte to close the last step's travel.
void speculate(ConstraintRow& r, Real target) {
  r.rhs = target;
  if (r.correction != Correction::InRhs) r.bias_rhs = target;
}

// addRow's body, inlined where a part makes several rows at once (the
// point part's three): the Jacobians stay in registers instead of being
// stored for a call, and the unit axes are constants.
inline __attribute__((always_inline)) int appendRow(RowContext& ctx, const BodyView& a, const BodyView& b, int slot,
                                                    const Vec3& lin_a, const Vec3& ang_a, const Vec3& lin_b,
                                                    const Vec3& ang_b, Real c, const Softness* axis_softness, Real lo,
                                                    Real hi) {
  // M^-1 J^T and the diagonal from locals; the row is written once (no
  // read back of what was just stored).
  const Vec3 m_lin_a = a.inv_mass * a.lin_factor.cwiseProduct(lin_a);
  const Vec3 m_ang_a = a.inv_inertia * ang_a;
  const Vec3 m_lin_b = b.inv_mass * b.lin_factor.cwiseProduct(lin_b);
  const Vec3 m_ang_b = b.inv_inertia * ang_b;
  const Real diag = lin_a.dot(m_lin_a) + ang_a.dot(m_ang_a) + lin_b.dot(m_lin_b) + ang_b.dot(m_ang_b);
  if (!(diag > Real(1e-300))) return -1;  // neither body can move along this row
  // Most rows keep the global ERP and CFM: the softness is resolved (a
  // call, and a division for the effective mass) only where it is set.
  const bool own_softness = (axis_softness && axis_softness->isSet()) || ctx.joint_softness->isSet();
  const ErpCfm soft = own_softness ? resolveSoftness(axis_softness, *ctx.joint_softness, ctx.erp, ctx.cfm, 1 / diag, ctx.h)
                                   : ErpCfm{ctx.erp, ctx.cfm};
  const Real cfm = soft.cfm / ctx.h;  // ODE's CFM multiplies a force; lambda is an impulse
  const bool separate = ctx.correction != Correction::InRhs && !own_softness;
  const Real bias = correctionBias(ctx, soft, c, lin_a, lin_b);
  const Real lambda = ctx.warm && slot < static_cast<int>(ctx.warm->size())
                          ? std::clamp(ctx.warm_factor * (*ctx.warm)[slot], lo, hi)
                          : Real(0);
  // Every member named: value-initialising the row first (then writing
  // it) cleared its ~300 bytes with a string store a row.
  ctx.rows->push_back(ConstraintRow{.body_a = a.solver_index,
                                    .body_b = b.solver_index,
                                    .j_lin_a = lin_a,
                                    .j_ang_a = ang_a,
                                    .j_lin_b = lin_b,
                                    .j_ang_b = ang_b,
                                    .m_lin_a = m_lin_a,
                                    .m_ang_a = m_ang_a,
                                    .m_lin_b = m_lin_b,
                                    .m_ang_b = m_ang_b,
                                    .inv_diag = 1 / (diag + cfm),
                                    .rhs = separate ? Real(0) : bias,
                                    .cfm = cfm,
                                    .lo = lo,
                                    .hi = hi,
                                    .lambda = lambda,
                                    .mu = 0,
                                    .normal_row = -1,
                                    .kind = ctx.kind,
                                    .owner = ctx.owner,
                                    .owner_row = static_cast<std::int8_t>(slot),
                                    .bias_rhs = separate ? bias : Real(0),
                                    .correction = separate ? ctx.correction : Correction::InRhs});
  return static_cast<int>(ctx.rows->size() - 1);
}

}  // namespace

RowJacobian relativeRotation(const Vec3& u) {
  RowJacobian j;
  j.ang_a = u;
  j.ang_b = -u;
  return j;
}

RowJacobian relativeTravel(const BodyView& a, const BodyView& b, const Vec3& n, const Vec3& p_a, const Vec3& p_b,
                           bool fixed_in_a) {
  // d/dt n.(p_a - p_b) = n.(v_pa - v_pb) + (w x n).(p_a - p_b) for w the
  // spin of the body n is fixed in; (w x n).d = w.(n x d) moves that body's
  // lever arm from its own anchor to the other one, so both arms reach the
  // anchor of the body n is not fixed in.
  const Vec3 p = fixed_in_a ? p_b : p_a;
  RowJacobian j;
  j.lin_a = n;
  j.ang_a = (p - a.x).cross(n);
  j.lin_b = -n;
  j.ang_b = -(p - b.x).cross(n);
  return j;
}

Real effectiveMass(const BodyView& a, const BodyView& b, const RowJacobian& j) {
  const Real diag = a.inv_mass * j.lin_a.dot(a.lin_factor.cwiseProduct(j.lin_a)) + j.ang_a.dot(a.inv_inertia * j.ang_a) +
                    b.inv_mass * j.lin_b.dot(b.lin_factor.cwiseProduct(j.lin_b)) + j.ang_b.dot(b.inv_inertia * j.ang_b);
  return diag > Real(1e-300) ? 1 / diag : 0;
}

Real wrapAngle(Real x) {
  x = std::remainder(x, 2 * kPi);  // [-pi, pi]
  return x <= -kPi ? x + 2 * kPi : x;
}

Real angleNearLimits(Real s, const LimitDef& l) {
  if (!l.enabled) return s;
  if (l.lower == l.upper) return l.lower + wrapAngle(s - l.lower);
  if (s < l.lower && std::abs(wrapAngle(l.lower - s)) >= std::abs(wrapAngle(l.upper - s))) return s + 2 * kPi;
  if (s > l.upper && std::abs(wrapAngle(s - l.upper)) >= std::abs(wrapAngle(s - l.lower))) return s - 2 * kPi;
  return s;
}

int addRow(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const Vec3& lin_a, const Vec3& ang_a,
           const Vec3& lin_b, const Vec3& ang_b, Real c, const Softness* axis_softness, Real lo, Real hi) {
  return appendRow(ctx, a, b, slot, lin_a, ang_a, lin_b, ang_b, c, axis_softness, lo, hi);
}

void addPointPart(RowContext& ctx, const BodyView& a, const BodyView& b, int first_slot, const Vec3& p_a,
                  const Vec3& p_b) {
  const Vec3 ra = p_a - a.x, rb = p_b - b.x;
  const Vec3 err = p_b - p_a;
  ctx.shared_error_norm = err.norm();  // the cap scales the three rows together
  for (int k = 0; k < 3; ++k) {
    const Vec3 n = Vec3::Unit(k);
    appendRow(ctx, a, b, first_slot + k, -n, -ra.cross(n), n, rb.cross(n), err[k], nullptr, -kInf, kInf);
  }
  ctx.shared_error_norm = 0;
}

int addAxisPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const Vec3& n, const Vec3& /*p_a*/,
                const Vec3& p_b, Real c, const Softness* axis_softness, Real lo, Real hi) {
  // d/dt n.(p_b - p_a) with n fixed in a: the lever arm of a reaches p_b.
  const Vec3 ra = p_b - a.x, rb = p_b - b.x;
  return addRow(ctx, a, b, slot, -n, -ra.cross(n), n, rb.cross(n), c, axis_softness, lo, hi);
}

int addAnglePart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const Vec3& u, Real angle_error,
                 const Softness* axis_softness, Real lo, Real hi) {
  return addRow(ctx, a, b, slot, Vec3::Zero(), -u, Vec3::Zero(), u, angle_error, axis_softness, lo, hi);
}

void addOrientationPart(RowContext& ctx, const BodyView& a, const BodyView& b, int first_slot, const Quat& q_rel0) {
  // Error rotation (world frame) taking the desired orientation of b,
  // q_a q_rel0, to its actual one: e = log(q_b (q_a q_rel0)^-1).
  const Vec3 e = rotationVectorFromQuat(b.q * (a.q * q_rel0).conjugate());
  for (int k = 0; k < 3; ++k) addAnglePart(ctx, a, b, first_slot + k, Vec3::Unit(k), e[k]);
}

void addLimitPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const LimitDef& limit, Real s,
                  const RowJacobian& j, Real threshold) {
  if (!limit.enabled) return;
  const RowKind saved = ctx.kind;
  ctx.kind = RowKind::Limit;
  const Softness& soft = limit.softness.isSet() ? limit.softness : *ctx.joint_softness;
  const Real to_lower = s - limit.lower;  // >= 0 inside
  const Real to_upper = limit.upper - s;  // >= 0 inside
  if (limit.lower == limit.upper) {
    // Locked: held from both sides, as ODE's and Bullet's limits do when
    // lostop == histop, whether the row is rigid or a spring.
    addRow(ctx, a, b, slot, j, to_lower, &limit.softness);
  } else if (isSpring(soft)) {
    // A soft stop is a spring-damper toward the bound it is past: the
    // impulse may take either sign, so the damper brakes the return too
    // (a one-sided row would clip that and let the joint spring back
    // faster than the damped oscillator it stands for).
    if (to_lower <= 0) addRow(ctx, a, b, slot, j, to_lower, &limit.softness);
    else if (to_upper <= 0) addRow(ctx, a, b, slot, j, -to_upper, &limit.softness);
  } else {
    const Real rate = j.rate(a, b);
    // Lower bound: the row may only push s up (lambda >= 0).
    if (to_lower <= 0 || to_lower + ctx.h * rate < 0) {
      const int i = addRow(ctx, a, b, slot, j, std::min(to_lower, Real(0)), &limit.softness, 0, kInf);
      if (i >= 0) {
        ConstraintRow& r = (*ctx.rows)[i];
        if (to_lower > 0) speculate(r, -to_lower / ctx.h);  // close the gap, no more
        if (limit.restitution > 0 && -rate > threshold) r.rhs = std::max(r.rhs, -limit.restitution * rate);
      }
    } else if (to_upper <= 0 || to_upper - ctx.h * rate < 0) {
      const int i = addRow(ctx, a, b, slot, j, -std::min(to_upper, Real(0)), &limit.softness, -kInf, 0);
      if (i >= 0) {
        ConstraintRow& r = (*ctx.rows)[i];
        if (to_upper > 0) speculate(r, to_upper / ctx.h);
        if (limit.restitution > 0 && rate > threshold) r.rhs = std::min(r.rhs, -limit.restitution * rate);
      }
    }
  }
  ctx.kind = saved;
}

Softness servoSoftness(const Softness& motor_softness, Real effective_mass) {
  Softness s = motor_softness;
  if (!s.isSet()) {
    s.frequency = 2;  // Jolt's MotorSettings default: 2 Hz, critically damped
    s.damping_ratio = 1;
  } else if (s.stiffness && !s.damping) {
    s.damping = 2 * std::sqrt(*s.stiffness * effective_mass);  // critical: zeta = c / (2 sqrt(k m)) = 1
  }
  return s;
}

void addMotorPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const MotorDef& motor, Real s,
                  bool angular, const RowJacobian& j) {
  const RowKind saved = ctx.kind;
  ctx.kind = RowKind::Motor;
  const Real bound = motor.max_force.value_or(0) * ctx.h;
  if (motor.target_position) {
    // Servo: the row is the implicit spring-damper of softness.hpp on the
    // error s - target, rhs = -ERP/h (s - target), cfm = CFM/h.
    const Real error = angular ? wrapAngle(s - *motor.target_position) : s - *motor.target_position;
    const Softness soft = servoSoftness(motor.softness, effectiveMass(a, b, j));
    addRow(ctx, a, b, slot, j, error, &soft, -bound, bound);
  } else {
    // Velocity motor: no position feedback; rigid (ERP 0, CFM 0) unless it
    // has a damper, whose CFM = 1/c makes the force c (target - J v+).
    static const Softness rigid{Real(0), Real(0), {}, {}, {}, {}};
    const Softness* soft = motor.softness.isSet() ? &motor.softness : &rigid;
    const int i = addRow(ctx, a, b, slot, j, 0, soft, -bound, bound);
    if (i >= 0) (*ctx.rows)[i].rhs = motor.target_velocity;
  }
  ctx.kind = saved;
}

Real angleAbout(const Vec3& axis, const Vec3& from, const Vec3& to) {
  return std::atan2(from.cross(to).dot(axis), from.dot(to));
}

}  // namespace cairn
