// The generic constraint row (ODE's quickstep formulation, section 12.6.2).
//
// A row constrains the relative velocity of two bodies along one direction:
//
//     J v = J_lin_a . v_a + J_ang_a . w_a + J_lin_b . v_b + J_ang_b . w_b
//
// cairn solves for the row's impulse lambda (N s, or N m s for angular
// rows) such that, with A = J M^-1 J^T,
//
//     J v+ = rhs - cfm lambda,   v+ = v* + M^-1 J^T lambda,
//     lo <= lambda <= hi        (a mixed LCP: lambda at a bound lets J v+
//                                 deviate in the direction of that bound).
//
// rhs carries the position feedback -ERP/h C (plus restitution or a motor's
// target speed) -- unless split impulse is on, see bias_rhs below; cfm is ODE's CFM divided by h, because ODE's CFM multiplies
// a force and lambda here is an impulse (docs/constraints.md derives it).
//
// Friction rows point at their normal row (ODE's findex): their bounds are
// -+ mu lambda_normal, updated during the solve. Rows are solved island by
// island, and normal_row counts from the first row of the island, so a
// solver handed one island's span finds the normal row in that span.
//
// The row caches M^-1 J^T for both bodies and 1 / (A_ii + cfm) so that the
// PGS inner loop is a dot product, a clamp and two axpy's.
#pragma once

#include "cairn/math.hpp"
#include "cairn/settings.hpp"
#include "cairn/stats.hpp"

#include <cstdint>

namespace cairn {

struct ConstraintRow {
  std::int32_t body_a = 0, body_b = 0;  // solver body indices (0 = the world)
  Vec3 j_lin_a = Vec3::Zero(), j_ang_a = Vec3::Zero();
  Vec3 j_lin_b = Vec3::Zero(), j_ang_b = Vec3::Zero();
  Vec3 m_lin_a = Vec3::Zero(), m_ang_a = Vec3::Zero();  // M^-1 J^T for body a
  Vec3 m_lin_b = Vec3::Zero(), m_ang_b = Vec3::Zero();  // M^-1 J^T for body b
  Real inv_diag = 0;      // 1 / (A_ii + cfm)
  Real rhs = 0;           // target J v (velocity units)
  Real cfm = 0;           // impulse-form CFM (ODE's CFM / h)
  Real lo = -kInf, hi = kInf;
  Real lambda = 0;        // accumulated impulse (warm-started)
  Real mu = 0;            // friction coefficient when normal_row >= 0
  std::int32_t normal_row = -1;  // friction: index of its normal row, counted from the island's first row
  RowKind kind = RowKind::JointLinear;
  std::int32_t owner = -1;       // joint index or contact index
  std::int8_t owner_row = 0;     // row number inside its owner (warm start key)
  // The position error's target -ERP/h C when it is solved in its own pass.
  Real bias_rhs = 0;
  Correction correction = Correction::InRhs;
};

}  // namespace cairn
