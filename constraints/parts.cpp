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

}  // namespace

int addRow(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, const Vec3& lin_a, const Vec3& ang_a,
           const Vec3& lin_b, const Vec3& ang_b, Real c, const Softness* axis_softness, Real lo, Real hi) {
  ConstraintRow r;
  r.body_a = a.solver_index;
  r.body_b = b.solver_index;
  r.j_lin_a = lin_a;
  r.j_ang_a = ang_a;
  r.j_lin_b = lin_b;
  r.j_ang_b = ang_b;
  r.m_lin_a = a.inv_mass * a.lin_factor.cwiseProduct(lin_a);
  r.m_ang_a = a.inv_inertia * ang_a;
  r.m_lin_b = b.inv_mass * b.lin_factor.cwiseProduct(lin_b);
  r.m_ang_b = b.inv_inertia * ang_b;
  const Real diag = lin_a.dot(r.m_lin_a) + ang_a.dot(r.m_ang_a) + lin_b.dot(r.m_lin_b) + ang_b.dot(r.m_ang_b);
  if (!(diag > Real(1e-300))) return -1;  // neither body can move along this row
  const ErpCfm soft = resolveSoftness(axis_softness, *ctx.joint_softness, ctx.erp, ctx.cfm, 1 / diag, ctx.h);
  r.cfm = soft.cfm / ctx.h;  // ODE's CFM multiplies a force; lambda is an impulse
  r.inv_diag = 1 / (diag + r.cfm);
  const bool own_softness = (axis_softness && axis_softness->isSet()) || ctx.joint_softness->isSet();
  const Real bias = correctionBias(ctx, soft, c, lin_a, lin_b);
  if (ctx.correction != Correction::InRhs && !own_softness) {
    r.correction = ctx.correction;
    r.bias_rhs = bias;
  } else {
    r.rhs = bias;
  }
  r.lo = lo;
  r.hi = hi;
  r.kind = ctx.kind;
  r.owner = ctx.owner;
  r.owner_row = static_cast<std::int8_t>(slot);
  if (ctx.warm && slot < static_cast<int>(ctx.warm->size())) {
    r.lambda = std::clamp(ctx.warm_factor * (*ctx.warm)[slot], lo, hi);
  }
  ctx.rows->push_back(r);
  return static_cast<int>(ctx.rows->size() - 1);
}

void addPointPart(RowContext& ctx, const BodyView& a, const BodyView& b, int first_slot, const Vec3& p_a,
                  const Vec3& p_b) {
  const Vec3 ra = p_a - a.x, rb = p_b - b.x;
  const Vec3 err = p_b - p_a;
  ctx.shared_error_norm = err.norm();  // the cap scales the three rows together
  for (int k = 0; k < 3; ++k) {
    const Vec3 n = Vec3::Unit(k);
    addRow(ctx, a, b, first_slot + k, -n, -ra.cross(n), n, rb.cross(n), err[k]);
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
                  const Vec3& lin_a, const Vec3& ang_a, const Vec3& lin_b, const Vec3& ang_b, Real threshold) {
  if (!limit.enabled) return;
  const Real rate = lin_a.dot(a.v) + ang_a.dot(a.w) + lin_b.dot(b.v) + ang_b.dot(b.w);
  const Real to_lower = s - limit.lower;  // >= 0 inside
  const Real to_upper = limit.upper - s;  // >= 0 inside
  const RowKind saved = ctx.kind;
  ctx.kind = RowKind::Limit;
  // Lower bound: the row may only push s up (lambda >= 0).
  if (to_lower <= 0 || to_lower + ctx.h * rate < 0) {
    const int i = addRow(ctx, a, b, slot, lin_a, ang_a, lin_b, ang_b, std::min(to_lower, Real(0)),
                         &limit.softness, 0, kInf);
    if (i >= 0) {
      ConstraintRow& r = (*ctx.rows)[i];
      if (to_lower > 0) r.rhs = -to_lower / ctx.h;  // speculative: close the gap, no more
      if (limit.restitution > 0 && -rate > threshold) r.rhs = std::max(r.rhs, -limit.restitution * rate);
    }
  } else if (to_upper <= 0 || to_upper - ctx.h * rate < 0) {
    const int i = addRow(ctx, a, b, slot, lin_a, ang_a, lin_b, ang_b, -std::min(to_upper, Real(0)),
                         &limit.softness, -kInf, 0);
    if (i >= 0) {
      ConstraintRow& r = (*ctx.rows)[i];
      if (to_upper > 0) r.rhs = to_upper / ctx.h;
      if (limit.restitution > 0 && rate > threshold) r.rhs = std::min(r.rhs, -limit.restitution * rate);
    }
  }
  ctx.kind = saved;
}

void addMotorPart(RowContext& ctx, const BodyView& a, const BodyView& b, int slot, Real target, Real max_force,
                  const Vec3& lin_a, const Vec3& ang_a, const Vec3& lin_b, const Vec3& ang_b) {
  const RowKind saved = ctx.kind;
  ctx.kind = RowKind::Motor;
  // A motor is a pure velocity row: rigid (no CFM), no position feedback.
  static const Softness rigid{Real(0), Real(0), {}, {}, {}, {}};
  const Real bound = max_force * ctx.h;
  const int i = addRow(ctx, a, b, slot, lin_a, ang_a, lin_b, ang_b, 0, &rigid, -bound, bound);
  if (i >= 0) (*ctx.rows)[i].rhs = target;
  ctx.kind = saved;
}

Real angleAbout(const Vec3& axis, const Vec3& ref_a, const Vec3& ref_b) {
  return std::atan2(ref_a.cross(ref_b).dot(axis), ref_a.dot(ref_b));
}

}  // namespace cairn
