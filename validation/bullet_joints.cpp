// cairn joints as Bullet constraints, and the row-softness plumbing.
//
//   ball           btPoint2PointConstraint
//   hinge          btHingeConstraint, frames z = axis, x = anyPerpendicular(axis);
//                  useReferenceFrameA = false (Bullet's default) makes its
//                  hinge angle and motor a's about +axis relative to b
//                  (cairn's hingeAngle)
//   slider         btSliderConstraint, frames x = axis, y = anyPerpendicular;
//                  useLinearReferenceFrameA = false (position = axis.(p_a - p_b),
//                  cairn's sliderPosition); rotation about the axis locked
//                  (angular limits 0, 0)
//   fixed          btFixedConstraint (btGeneric6DofSpring2, all six locked)
//   universal      btUniversalConstraint (axis on a = z, axis2 on b = y)
//   cone_twist     btConeTwistConstraint, frames x = axis, y = anyPerpendicular
//                  (so swing_span1 limits the tilt toward y, as cairn's s1
//                  does toward its reference axis); Bullet's twist span is
//                  symmetric, so frame a is turned by the limits' center
//                  c = (lower + upper)/2 about the twist axis and the span is
//                  (upper - lower)/2
//   distance       DistanceRow below: Bullet has no distance joint
//   angular_motor  btGeneric6DofSpring2Constraint, everything free, motors
//                  on its Euler axes (x = axis 1, z = axis 2, y = axis 3)
//   six_dof        btGeneric6DofSpring2Constraint (RO_XYZ) with the bodies
//                  swapped (Bullet's A = cairn's b): its translations are
//                  then B's anchor in A's frame, cairn's a in b's, and its
//                  Euler angles A relative to B, so x (twist) is the
//                  innermost rotation as in cairn's swing-twist, and every
//                  angle (and the linear motors' sense) is cairn's negated
//
// Bullet's joint rows (btSequentialImpulseConstraintSolver::convertJoint)
// are never warm-started and ignore m_sor; their CFM is relative to the
// row's effective mass (bullet_internal.hpp), and m_globalCfm reaches only
// the first row of each joint unless the joint copies info->cfm[0] into its
// other rows (the 6-dof joints do, hinge, slider, point and cone-twist do
// not). With match_cairn every row's CFM is rewritten by CairnCfm<>.
#include "validation/bullet_internal.hpp"

#include "cairn/error.hpp"

#include <BulletDynamics/ConstraintSolver/btFixedConstraint.h>
#include <BulletDynamics/ConstraintSolver/btGeneric6DofSpring2Constraint.h>
#include <BulletDynamics/ConstraintSolver/btUniversalConstraint.h>

#include <cmath>
#include <sstream>

namespace cairn::validation::detail {

namespace {

// Bullet's joint iteration l <- (rhs - J v)/A - cfm_b l is l_k = b (1 - (-cfm_b)^k) / (1 + cfm_b)
// for a lone row: it diverges for cfm_b >= 1 and, at 10 iterations, is
// still 6% short at cfm_b = 0.75. Larger values are clamped here (0.5^10 =
// 1e-3) and reported.
constexpr Real kMaxRelativeCfm = Real(0.5);

std::string fmt(Real v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

bool resolveOne(const Softness& s, Real global_erp, Real global_cfm, Real h, RowSoftness& out) {
  if (s.stiffness || s.damping) {
    const Real k = s.stiffness.value_or(0), c = s.damping.value_or(0);
    const Real denom = h * k + c;
    if (denom <= 0) {
      out = {0, {kInf, 0}};  // neither spring nor damper: the row does nothing
    } else {
      out = {h * k / denom, {1 / denom, 0}};
    }
    return true;
  }
  if (s.frequency) {
    const Real hw = h * 2 * kPi * *s.frequency, two_zeta = 2 * s.damping_ratio.value_or(1);
    out = {hw / (hw + two_zeta), {0, 1 / (hw * (hw + two_zeta))}};
    return true;
  }
  if (s.erp || s.cfm) {
    out = {s.erp.value_or(global_erp), {s.cfm.value_or(global_cfm), 0}};
    return true;
  }
  return false;
}

// A one-row distance constraint |p_b - p_a| = L, with cairn's Jacobian
// J = [-n, -(r_a x n), n, r_b x n] and rhs -ERP/h (|d| - L).
class DistanceRow : public btTypedConstraint {
 public:
  DistanceRow(btRigidBody& a, btRigidBody& b, const btVector3& local_a, const btVector3& local_b, btScalar length)
      : btTypedConstraint(MAX_CONSTRAINT_TYPE, a, b), local_a_(local_a), local_b_(local_b), length_(length) {}

  void getInfo1(btConstraintInfo1* info) override {
    const btVector3 d = m_rbB.getCenterOfMassTransform() * local_b_ - m_rbA.getCenterOfMassTransform() * local_a_;
    info->m_numConstraintRows = d.length2() > btScalar(1e-18) ? 1 : 0;  // direction undefined otherwise
    info->nub = info->m_numConstraintRows;
  }

  void getInfo2(btConstraintInfo2* info) override {
    const btTransform& ta = m_rbA.getCenterOfMassTransform();
    const btTransform& tb = m_rbB.getCenterOfMassTransform();
    const btVector3 pa = ta * local_a_, pb = tb * local_b_;
    const btVector3 d = pb - pa;
    const btScalar len = d.length();
    const btVector3 n = d / len;
    const btVector3 ja = -(pa - ta.getOrigin()).cross(n), jb = (pb - tb.getOrigin()).cross(n);
    for (int k = 0; k < 3; ++k) {
      info->m_J1linearAxis[k] = -n[k];
      info->m_J1angularAxis[k] = ja[k];
      info->m_J2linearAxis[k] = n[k];
      info->m_J2angularAxis[k] = jb[k];
    }
    const btScalar erp = has_erp_ ? erp_ : info->erp;
    info->m_constraintError[0] = -info->fps * erp * (len - length_);
    if (has_cfm_) info->cfm[0] = cfm_;
    info->m_lowerLimit[0] = -SIMD_INFINITY;
    info->m_upperLimit[0] = SIMD_INFINITY;
  }

  void setParam(int num, btScalar value, int /*axis*/) override {
    if (num == BT_CONSTRAINT_ERP || num == BT_CONSTRAINT_STOP_ERP) {
      erp_ = value;
      has_erp_ = true;
    } else {
      cfm_ = value;
      has_cfm_ = true;
    }
  }
  btScalar getParam(int num, int /*axis*/) const override {
    return (num == BT_CONSTRAINT_ERP || num == BT_CONSTRAINT_STOP_ERP) ? erp_ : cfm_;
  }

 private:
  btVector3 local_a_, local_b_;
  btScalar length_;
  btScalar erp_ = 0, cfm_ = 0;
  bool has_erp_ = false, has_cfm_ = false;
};

bool isSpringSoftness(const Softness& s) { return s.stiffness || s.damping || s.frequency; }

btTransform rotationAboutX(Real angle) {
  return btTransform(btQuaternion(btVector3(1, 0, 0), angle), btVector3(0, 0, 0));
}

}  // namespace

btTransform frameXY(const Vec3& origin, const Vec3& x, const Vec3& y) {
  const Vec3 z = x.cross(y);
  const btMatrix3x3 basis(x.x(), y.x(), z.x(), x.y(), y.y(), z.y(), x.z(), y.z(), z.z());
  return btTransform(basis, toBt(origin));
}

RowSoftness resolveRowSoftness(const Softness* axis, const Softness& joint, Real global_erp, Real global_cfm, Real h) {
  RowSoftness out{global_erp, {global_cfm, 0}};
  if (axis && resolveOne(*axis, global_erp, global_cfm, h, out)) return out;
  resolveOne(joint, global_erp, global_cfm, h, out);
  return out;
}

void applyCfmPlan(const btTypedConstraint& c, btTypedConstraint::btConstraintInfo2* info, int rows, CfmPlan& plan) {
  if (!plan.active) return;
  const btRigidBody& a = c.getRigidBodyA();
  const btRigidBody& b = c.getRigidBodyB();
  const int skip = info->rowskip;
  for (int r = 0; r < rows; ++r) {
    const RowRole role = plan.role ? plan.role(r) : RowRole::Joint;
    if (role == RowRole::Spring) continue;
    const RowCfm& spec = role == RowRole::Joint ? plan.joint : role == RowRole::Limit ? plan.limit : plan.motor;
    Real cfm = spec.relative;
    if (spec.ode > 0) {
      const int o = r * skip;
      const btVector3 l1(info->m_J1linearAxis[o], info->m_J1linearAxis[o + 1], info->m_J1linearAxis[o + 2]);
      const btVector3 a1(info->m_J1angularAxis[o], info->m_J1angularAxis[o + 1], info->m_J1angularAxis[o + 2]);
      const btVector3 l2(info->m_J2linearAxis[o], info->m_J2linearAxis[o + 1], info->m_J2linearAxis[o + 2]);
      const btVector3 a2(info->m_J2angularAxis[o], info->m_J2angularAxis[o + 1], info->m_J2angularAxis[o + 2]);
      const Real diag = a.getInvMass() * l1.length2() + a1.dot(a.getInvInertiaTensorWorld() * a1) +
                        b.getInvMass() * l2.length2() + a2.dot(b.getInvInertiaTensorWorld() * a2);
      if (diag > Real(1e-300)) cfm += spec.ode * info->fps / diag;
    }
    if (!(cfm < kMaxRelativeCfm)) {
      cfm = kMaxRelativeCfm;
      plan.clamped = true;
    }
    info->cfm[r * skip] = cfm;
  }
}

BuiltJoint buildJoint(const JointDef& def, const JointEnd& a, const JointEnd& b, const JointContext& ctx) {
  BuiltJoint out;
  const std::string who = "joint '" + def.name + "' (" + jointTypeName(def.type) + ")";
  auto& notes = *ctx.notes;
  const SolverSettings& s = *ctx.solver;
  const Real h = ctx.h;
  const btTransform ta = a.body->getCenterOfMassTransform();
  const btTransform tb = b.body->getCenterOfMassTransform();
  const btTransform ta_inv = ta.inverse(), tb_inv = tb.inverse();
  const auto inA = [&](const Vec3& p) { return fromBt(ta_inv * toBt(p)); };
  const auto inB = [&](const Vec3& p) { return fromBt(tb_inv * toBt(p)); };
  out.local_a = inA(def.anchor);
  out.local_b = inB(def.anchor);

  if (!a.dynamic && !b.dynamic) {
    notes.push_back(who + ": not built, neither body is dynamic (it cannot act)");
    out.measure = JointMeasure::Point;
    return out;
  }

  const RowSoftness joint_soft = resolveRowSoftness(nullptr, def.softness, s.erp, s.cfm, h);
  const RowSoftness limit_soft = resolveRowSoftness(&def.limit.softness, def.softness, s.erp, s.cfm, h);
  const bool own_erp = joint_soft.erp != s.erp;
  const bool match = ctx.match;
  const Vec3 axis = def.axis.normalized();
  const Vec3 ref = anyPerpendicular(axis);

  // The plan every CairnCfm joint gets (used only with match_cairn).
  CfmPlan plan;
  plan.joint = joint_soft.cfm;
  plan.limit = limit_soft.cfm;
  // cairn's velocity motors are rigid rows unless they have a damper.
  plan.motor = def.motor.softness.isSet() && !def.motor.target_position
                   ? resolveRowSoftness(&def.motor.softness, Softness{}, 0, 0, h).cfm
                   : RowCfm{0, 0};
  // A servo has no counterpart in Bullet's hinge and slider motors (they
  // drive a speed); a soft limit is one-sided there.
  const bool velocity_motor = def.motor.enabled && !def.motor.target_position;
  if (def.motor.enabled && def.motor.target_position)
    notes.push_back(who + ": position motor (target_position) not mapped: Bullet's " + jointTypeName(def.type) +
                    " motor drives a velocity; left off");
  if (def.limit.enabled && def.limit.lower < def.limit.upper &&
      isSpringSoftness(def.limit.softness.isSet() ? def.limit.softness : def.softness))
    notes.push_back(who + ": soft limit is a one-sided row in Bullet (cairn's pushes and pulls past the bound)");
  const auto adopt = [&](auto* c) {
    out.constraint.reset(c);
    if (match) {
      c->plan = plan;
      out.plan = &c->plan;
    } else {
      c->plan.active = false;  // Bullet's own CFM convention
    }
    return c;
  };
  switch (def.type) {
    case JointType::Ball: {
      auto* c = adopt(new CairnCfm<btPoint2PointConstraint>(*a.body, *b.body, toBt(out.local_a), toBt(out.local_b)));
      if (own_erp) c->setParam(BT_CONSTRAINT_ERP, joint_soft.erp);
      break;
    }
    case JointType::Hinge: {
      const btTransform f = frameXY(def.anchor, ref, axis.cross(ref));  // z = axis
      auto* c = adopt(new CairnCfm<btHingeConstraint>(*a.body, *b.body, ta_inv * f, tb_inv * f, false));
      if (own_erp) c->setParam(BT_CONSTRAINT_ERP, joint_soft.erp);
      if (def.limit.enabled) {
        if (match) {
          // Bullet's limit row: rhs = biasFactor * max(fps stopERP err, -relaxation v).
          c->setLimit(def.limit.lower, def.limit.upper, btScalar(0.9), 1, def.limit.restitution);
          c->setParam(BT_CONSTRAINT_STOP_ERP, limit_soft.erp);
          if (def.limit.restitution > 0)
            notes.push_back(who + ": limit restitution " + fmt(def.limit.restitution) +
                            " applies at any approach speed in Bullet (no restitution threshold)");
        } else {
          c->setLimit(def.limit.lower, def.limit.upper);
        }
      }
      if (velocity_motor) c->enableAngularMotor(true, def.motor.target_velocity, *def.motor.max_force * h);
      if (match) {
        c->plan.role = [c](int row) {
          if (row < 5) return RowRole::Joint;
          return c->getSolveLimit() ? RowRole::Limit : RowRole::Motor;
        };
      }
      break;
    }
    case JointType::Slider: {
      const btTransform f = frameXY(def.anchor, axis, ref);  // x = axis
      auto* c = adopt(new CairnCfm<btSliderConstraint>(*a.body, *b.body, ta_inv * f, tb_inv * f, false));
      c->setLowerAngLimit(0);  // rotation about the axis locked: cairn's slider has 5 rows
      c->setUpperAngLimit(0);
      if (match && own_erp) {
        for (int ax : {1, 2, 4, 5}) c->setParam(BT_CONSTRAINT_STOP_ERP, joint_soft.erp, ax);
        // The axial lock row uses erp * softnessLimAng (or softnessLimAng^2 with its flag).
        if (s.erp > 0) c->setSoftnessLimAng(joint_soft.erp / s.erp);
        else c->setParam(BT_CONSTRAINT_STOP_ERP, std::sqrt(joint_soft.erp), 3);
      }
      if (def.limit.enabled) {
        c->setLowerLinLimit(def.limit.lower);
        c->setUpperLinLimit(def.limit.upper);
        if (match) {
          // Bullet's linear limit row: rhs = softnessLimLin * max(fps erp err, -|1 - dampingLimLin| v),
          // with erp = m_erp, or softnessLimLin again when STOP_ERP is set.
          Real soft = 0;
          if (s.erp > 0) {
            soft = limit_soft.erp / s.erp;
            c->setSoftnessLimLin(soft);
          } else {
            soft = std::sqrt(limit_soft.erp);
            c->setParam(BT_CONSTRAINT_STOP_ERP, soft, 0);
          }
          c->setDampingLimLin(1);  // no bounce: see below
          if (def.limit.restitution > 0)
            notes.push_back(who + ": limit restitution " + fmt(def.limit.restitution) +
                            " not mapped (btSliderConstraint's linear bounce term pulls toward the stop "
                            "with useLinearReferenceFrameA = false and never fires with true)");
        }
      }
      if (velocity_motor) {
        c->setPoweredLinMotor(true);
        c->setTargetLinMotorVelocity(def.motor.target_velocity);
        c->setMaxLinMotorForce(*def.motor.max_force);
      }
      if (match) {
        c->plan.role = [c](int row) {
          if (row < 4) return RowRole::Joint;
          const bool linear_row = c->getSolveLinLimit() || c->getPoweredLinMotor();
          if (row == 4 && linear_row) return c->getSolveLinLimit() ? RowRole::Limit : RowRole::Motor;
          return RowRole::Joint;  // the axial rotation lock
        };
      }
      out.measure = JointMeasure::OffAxis;
      out.local_axis_a = fromBt(ta_inv.getBasis() * toBt(axis));
      break;
    }
    case JointType::Fixed: {
      const btTransform f(btQuaternion::getIdentity(), toBt(def.anchor));
      auto* c = adopt(new CairnCfm<btFixedConstraint>(*a.body, *b.body, ta_inv * f, tb_inv * f));
      if (own_erp)
        for (int ax = 0; ax < 6; ++ax) c->setParam(BT_CONSTRAINT_STOP_ERP, joint_soft.erp, ax);
      break;
    }
    case JointType::Universal: {
      Vec3 axis2 = def.axis2 - axis * axis.dot(def.axis2);
      axis2.normalize();
      auto* c = adopt(new CairnCfm<btUniversalConstraint>(*a.body, *b.body, toBt(def.anchor), toBt(axis), toBt(axis2)));
      if (own_erp)
        for (int ax = 0; ax < 6; ++ax) c->setParam(BT_CONSTRAINT_STOP_ERP, joint_soft.erp, ax);
      notes.push_back(who + ": btUniversalConstraint's Euler decomposition limits the rotation about axis2 to "
                            "+-(90 - 0.57) deg and about axis to +-(180 - 0.57) deg; cairn leaves both free");
      break;
    }
    case JointType::ConeTwist: {
      const btTransform f = frameXY(def.anchor, axis, ref);  // x = twist axis, y = cairn's reference axis
      const Real center = def.limit.enabled ? Real(0.5) * (def.limit.lower + def.limit.upper) : 0;
      const Real span = def.limit.enabled ? Real(0.5) * (def.limit.upper - def.limit.lower) : Real(BT_LARGE_FLOAT);
      // Bullet's twist is A's relative to B (qAB = qB^-1 qA), as cairn's;
      // turning frame A by -center makes its zero cairn's twist = center.
      auto* c = adopt(new CairnCfm<btConeTwistConstraint>(*a.body, *b.body, ta_inv * f * rotationAboutX(-center), tb_inv * f));
      if (match) {
        c->setLimit(def.swing_span1, def.swing_span2, span, 1, limit_soft.erp, 1);
        if (own_erp)
          for (int ax = 0; ax < 3; ++ax) c->setParam(BT_CONSTRAINT_ERP, joint_soft.erp, ax);
        c->plan.role = [](int row) { return row < 3 ? RowRole::Joint : RowRole::Limit; };
      } else {
        c->setLimit(def.swing_span1, def.swing_span2, span);
      }
      if (def.limit.enabled && def.limit.restitution > 0)
        notes.push_back(who + ": twist limit restitution not mapped (btConeTwistConstraint has no bounce)");
      break;
    }
    case JointType::Distance: {
      out.local_a = inA(def.anchor_a);
      out.local_b = inB(def.anchor_b);
      out.length = def.length.value_or((def.anchor_b - def.anchor_a).norm());
      auto* c = adopt(new CairnCfm<DistanceRow>(*a.body, *b.body, toBt(out.local_a), toBt(out.local_b), out.length));
      if (own_erp) c->setParam(BT_CONSTRAINT_ERP, joint_soft.erp, -1);
      out.measure = JointMeasure::Distance;
      notes.push_back(who + ": Bullet has no distance joint; mapped to a one-row btTypedConstraint written for "
                            "the oracle (cairn's row, solved by Bullet's solver)");
      break;
    }
    case JointType::AngularMotor: {
      // Orthonormal frame: x = axis 1, z = axis 2, y = z x x. Bullet's Euler
      // decomposition (RO_XYZ) keeps x and z unbounded; y is the middle angle.
      const size_t n = def.motor_axes.size();
      std::vector<Vec3> u;
      for (const Vec3& v : def.motor_axes) u.push_back(v.normalized());
      const Vec3 x = u[0];
      Vec3 z = n > 1 ? Vec3(u[1] - x * x.dot(u[1])) : anyPerpendicular(x);
      z.normalize();
      const Vec3 y = z.cross(x);
      bool orthogonal = n < 2 || std::abs(u[0].dot(u[1])) < Real(1e-6);
      if (n > 2) orthogonal = orthogonal && std::abs(std::abs(u[2].dot(y)) - 1) < Real(1e-6);
      const btTransform f = frameXY(fromBt(tb.getOrigin()), x, y);
      auto* c = adopt(new CairnCfm<btGeneric6DofSpring2Constraint>(*a.body, *b.body, ta_inv * f, tb_inv * f, RO_XYZ));
      c->setLinearLowerLimit(btVector3(1, 1, 1));  // lower > upper: free
      c->setLinearUpperLimit(btVector3(-1, -1, -1));
      c->setAngularLowerLimit(btVector3(1, 1, 1));
      c->setAngularUpperLimit(btVector3(-1, -1, -1));
      // 6-dof-2's motors drive (w_a - w_b).axis toward the target, as
      // cairn's angular motor does.
      const int index[3] = {3, 5, 4};
      const Vec3 frame_axis[3] = {x, z, y};
      for (size_t k = 0; k < n; ++k) {
        const Real sign = u[k].dot(frame_axis[k]) < 0 ? -1 : 1;
        c->enableMotor(index[k], true);
        c->setTargetVelocity(index[k], sign * def.motor_targets[k]);
        c->setMaxMotorForce(index[k], def.motor_max_torques[k]);
      }
      if (match) c->plan.role = [](int) { return RowRole::Motor; };
      out.measure = JointMeasure::None;
      notes.push_back(who + ": " + std::to_string(n) +
                      (n == 1 ? " axis" : " axes") +
                      " mapped to btGeneric6DofSpring2Constraint motors on its Euler axes (x = axis 1, z = axis 2, "
                      "y = axis 3), which stay on cairn's axes (fixed in a) only while b turns about them" +
                      (orthogonal ? "" : "; the axes are not orthogonal and were orthogonalized (targets approximate)"));
      break;
    }
    case JointType::SixDof: {
      Mat3 frame;
      frame.col(0) = axis;
      frame.col(1) = (def.axis2 - axis * axis.dot(def.axis2)).normalized();
      frame.col(2) = axis.cross(frame.col(1));
      const btTransform f = frameXY(def.anchor, frame.col(0), frame.col(1));
      // Bullet's A is cairn's b (bullet_six_dof.cpp says why).
      auto* c = adopt(new CairnCfm<btGeneric6DofSpring2Constraint>(*b.body, *a.body, tb_inv * f, ta_inv * f, RO_XYZ));
      configureSixDof(*c, def, def.anchor, frame, s, h, match, notes, who);
      const bool point = def.dofs[0].mode == DofMode::Locked && def.dofs[1].mode == DofMode::Locked &&
                         def.dofs[2].mode == DofMode::Locked;
      out.measure = point ? JointMeasure::Point : JointMeasure::None;
      break;
    }
  }

  btTypedConstraint* c = out.constraint.get();
  if (!match && def.softness.isSet() && std::isfinite(joint_soft.cfm.ode) && joint_soft.cfm.ode > 0) {
    // Bullet as a user would set it: the raw value through setParam.
    switch (def.type) {
      case JointType::Ball:
      case JointType::Hinge:
      case JointType::Distance: c->setParam(BT_CONSTRAINT_CFM, joint_soft.cfm.ode); break;
      case JointType::Slider:
      case JointType::Fixed:
      case JointType::Universal:
      case JointType::ConeTwist:
        for (int ax = 1; ax < 6; ++ax) c->setParam(BT_CONSTRAINT_STOP_CFM, joint_soft.cfm.ode, ax);
        break;
      case JointType::AngularMotor:
      case JointType::SixDof: break;
    }
  }

  if (std::isfinite(def.break_force) || std::isfinite(def.break_torque)) {
    const Real limit = std::min(def.break_force, def.break_torque);
    c->setBreakingImpulseThreshold(limit * h);
    notes.push_back(who + ": breaking approximated by Bullet's per-row impulse threshold " + fmt(limit) +
                    " x h (any single row, linear or angular, at or above it breaks the joint; cairn compares "
                    "the force and torque vectors' norms with break_force and break_torque)");
  }
  return out;
}

}  // namespace cairn::validation::detail
