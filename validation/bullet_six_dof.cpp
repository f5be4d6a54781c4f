// cairn's six_dof joint as Bullet's btGeneric6DofSpring2Constraint.
//
// Bullet's 6-dof-2 measures its translations as B's frame origin in A's
// frame and its rotation as Euler angles of A relative to B
// (matrixToEulerXYZ reads R_A^-1 R_B transposed, so with RO_XYZ
// R_B^-1 R_A = Rx(x) Ry(y) Rz(z) and z is the innermost rotation in A).
// cairn measures a's frame in b's, with the twist about x innermost
// (constraints/six_dof_joint.cpp). Built with Bullet's A = cairn's b and
// B = cairn's a:
//   - translations are cairn's exactly: B's origin (a's anchor) in A's frame
//     (b's frame); limits and spring rest points map as they are;
//   - R_B^-1 R_A = (cairn's q)^-1 = Rx(x) Ry(y) Rz(z), so
//     q = Rz(-z) Ry(-y) Rx(-x): the twist x is innermost as in cairn's
//     swing-twist, and Bullet's angles are cairn's negated (to first order
//     in the swing; they part at second order, and Bullet's middle angle y
//     is bounded by pi/2);
//   - every motor row is J = [ax, -ax] on (A, B), i.e. b relative to a:
//     velocity targets are negated, linear and angular alike.
// Limits: 6-dof-2 emits both limit rows of a limited axis at all times,
// with rhs STOP_ERP/h times the gap, so it caps the approach speed at
// STOP_ERP gap / h; with match_cairn STOP_ERP is 1 on limited axes, cairn's
// speculative limit (close the gap within the step, no more). Once the
// joint would cross within the step, though, get_limit_motor_info2 replaces
// the target by the bounce (0 without restitution): a joint running into a
// bound stops up to a step's travel short of it, where cairn's reaches it.
// Springs: Bullet's spring row applies the explicit force k x + c v of the
// state at the start of the step (bounded by it); cairn's is implicit
// Euler. Servos (target_position) are not mapped: Bullet's servo drives at
// the motor's target velocity toward the target, not through a spring.
#include "validation/bullet_internal.hpp"

#include <cmath>

namespace cairn::validation::detail {

namespace {

// 1 / (J M^-1 J^T) of a 6-dof-2 row along the world direction e at the
// anchor (linear) or about it (angular), for a frequency spring's k and c.
Real effectiveMass(const btRigidBody& a, const btRigidBody& b, const btVector3& e, const btVector3& anchor,
                   bool angular) {
  Real diag = 0;
  for (const btRigidBody* body : {&a, &b}) {
    if (body->getInvMass() == 0) continue;
    const btVector3 arm = angular ? e : (anchor - body->getCenterOfMassPosition()).cross(e);
    diag += (angular ? 0 : body->getInvMass()) + arm.dot(body->getInvInertiaTensorWorld() * arm);
  }
  return diag > 0 ? 1 / diag : 0;
}

}  // namespace

void configureSixDof(CairnCfm<btGeneric6DofSpring2Constraint>& c, const JointDef& def, const Vec3& anchor,
                     const Mat3& frame, const SolverSettings& s, Real h, bool match, std::vector<std::string>& notes,
                     const std::string& who) {
  std::array<bool, kDofCount> locked_by_mode{};
  Real soft_limit_erp = -1;
  for (int i = 0; i < kDofCount; ++i) {
    const DofDef& dof = def.dofs[static_cast<size_t>(i)];
    const bool angular = i >= 3;
    const Real sign = angular ? -1 : 1;  // Bullet's coordinate over cairn's
    const std::string axis = std::string(" ") + dofName(i);
    locked_by_mode[static_cast<size_t>(i)] = dof.mode == DofMode::Locked;
    switch (dof.mode) {
      case DofMode::Free: c.setLimit(i, 1, -1); break;  // lower > upper: free
      case DofMode::Locked: {
        c.setLimit(i, 0, 0);
        const RowSoftness soft = resolveRowSoftness(nullptr, def.softness, s.erp, s.cfm, h);
        if (match) c.setParam(BT_CONSTRAINT_STOP_ERP, soft.erp, i);
        break;
      }
      case DofMode::Limited: {
        const LimitDef& l = dof.limit;
        if (angular) c.setLimit(i, -l.upper, -l.lower);
        else c.setLimit(i, l.lower, l.upper);
        const RowSoftness soft = resolveRowSoftness(&l.softness, def.softness, s.erp, s.cfm, h);
        const bool spring = l.softness.isSet() ? (l.softness.stiffness || l.softness.damping || l.softness.frequency)
                                               : (def.softness.stiffness || def.softness.damping || def.softness.frequency);
        if (match) c.setParam(BT_CONSTRAINT_STOP_ERP, l.lower == l.upper || spring ? soft.erp : 1, i);
        if (spring && l.lower < l.upper)
          notes.push_back(who + axis + ": soft limit is one-sided in Bullet (cairn's pushes and pulls past the bound)");
        if (spring || l.lower == l.upper) {
          if (soft_limit_erp >= 0 && soft_limit_erp != soft.erp)
            notes.push_back(who + axis + ": limit softness differs between axes; Bullet's rows share the first one's CFM");
          soft_limit_erp = soft.erp;
        }
        if (l.restitution > 0) {
          c.setBounce(i, l.restitution);
          notes.push_back(who + axis + ": limit restitution applies at any approach speed in Bullet");
        }
        break;
      }
    }
    if (dof.spring.enabled) {
      const Softness& sp = dof.spring.softness;
      Real k = sp.stiffness.value_or(0), damping = sp.damping.value_or(0);
      if (sp.frequency) {
        const btVector3 e = toBt(Vec3(frame.col(i % 3)));
        const Real m = effectiveMass(c.getRigidBodyA(), c.getRigidBodyB(), e, toBt(anchor), angular);
        const Real omega = 2 * kPi * *sp.frequency;
        k = m * omega * omega;
        damping = 2 * sp.damping_ratio.value_or(1) * m * omega;
      }
      c.enableSpring(i, true);
      c.setStiffness(i, k, false);
      c.setDamping(i, damping, false);
      c.setEquilibriumPoint(i, sign * dof.spring.rest);
      notes.push_back(who + axis + ": spring mapped to 6-dof-2's explicit spring (cairn's is implicit Euler)");
    }
    if (dof.motor.enabled) {
      if (dof.motor.target_position) {
        notes.push_back(who + axis + ": position motor (target_position) not mapped: 6-dof-2's servo drives at a "
                                     "set speed toward its target; left off");
      } else {
        c.enableMotor(i, true);
        c.setTargetVelocity(i, -dof.motor.target_velocity);
        c.setMaxMotorForce(i, *dof.motor.max_force);
        if (dof.motor.softness.isSet()) notes.push_back(who + axis + ": motor damping not mapped (rigid in Bullet)");
      }
    }
  }
  if (!match) return;
  // Row roles in 6-dof-2's order (getInfo2: rotations x, y, z for RO_XYZ,
  // then translations; per axis its limit rows, motor, spring), so that the
  // lock rows get the joint's CFM, limit rows the limit's, and the spring
  // rows keep Bullet's (its spring is a force-bounded row, not a CFM one).
  btGeneric6DofSpring2Constraint* self = &c;
  c.plan.role = [self, locked_by_mode](int row) {
    int r = 0;
    for (int k = 0; k < kDofCount; ++k) {
      const int i = k < 3 ? k + 3 : k - 3;  // Bullet's index: rotations first
      int limit_rows = 0;
      bool motor = false, spring = false;
      if (i >= 3) {
        const btRotationalLimitMotor2* m = self->getRotationalLimitMotor(i - 3);
        limit_rows = m->m_currentLimit == 4 ? 2 : m->m_currentLimit != 0 ? 1 : 0;
        motor = m->m_enableMotor;
        spring = m->m_enableSpring;
      } else {
        const btTranslationalLimitMotor2* m = self->getTranslationalLimitMotor();
        limit_rows = m->m_currentLimit[i] == 4 ? 2 : m->m_currentLimit[i] != 0 ? 1 : 0;
        motor = m->m_enableMotor[i];
        spring = m->m_enableSpring[i];
      }
      if (row < r + limit_rows) return locked_by_mode[static_cast<size_t>(i)] ? RowRole::Joint : RowRole::Limit;
      r += limit_rows;
      if (motor && row == r++) return RowRole::Motor;
      if (spring && row == r++) return RowRole::Spring;
    }
    return RowRole::Joint;
  };
  if (soft_limit_erp >= 0) {
    for (int i = 0; i < kDofCount; ++i) {
      const DofDef& dof = def.dofs[static_cast<size_t>(i)];
      if (dof.mode != DofMode::Limited) continue;
      c.plan.limit = resolveRowSoftness(&dof.limit.softness, def.softness, s.erp, s.cfm, h).cfm;
      break;
    }
  }
}

}  // namespace cairn::validation::detail
