// How far the current impulses are from solving the mixed LCP
// (docs/solvers-exact.md, "Residual").
//
// The mixed (box-constrained) LCP of constraints/row.hpp is: find lambda with
//
//     w = (A + diag(cfm)) lambda + b,   b = J v* - rhs,   lo <= lambda <= hi,
//     lambda_i = lo_i and w_i >= 0, or lambda_i = hi_i and w_i <= 0,
//     or lo_i < lambda_i < hi_i and w_i = 0.
//
// Its standard merit function is the natural map (Facchinei & Pang, "Finite-
// Dimensional Variational Inequalities and Complementarity Problems", 1.5):
//
//     F_i(lambda) = lambda_i - clamp(lambda_i - w_i, lo_i, hi_i),
//
// which is zero for every i exactly when lambda solves the LCP; for an
// unbounded row it is w_i itself. Equivalently F_i = mid(lambda_i - lo_i,
// lambda_i - hi_i, w_i), the median of the three.
//
// Because the solvers keep v = v* + M^-1 J^T lambda, w needs no matrix:
//
//     w_i = J_i v - rhs_i + cfm_i lambda_i,
//
// so the residual costs one dot product per row (O(rows)) and can be
// reported by PGS every step. Friction rows (normal_row >= 0) take the
// bounds -+ mu |lambda_normal| of the current normal impulse (ODE's findex
// rule, with ODE's absolute value).
//
// Units: F_i mixes impulse (lambda) and velocity (w) units, as the natural
// map of any LCP whose two sides have different units does; it is exact
// zero at a solution and scales with the problem, so compare it with a
// tolerance relative to the problem's velocities and impulses.
#pragma once

#include "constraints/row.hpp"
#include "solver/solver_body.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

namespace cairn {

enum class ResidualNorm {
  Max,  // max_i |F_i|: independent of the number of rows (the default)
  Two,  // sqrt(sum_i F_i^2)
};

// One entry of the natural map. Bounds may be infinite.
inline Real naturalMap(Real lambda, Real w, Real lo, Real hi) {
  return lambda - std::min(std::max(lambda - w, lo), hi);
}

// The bounds row i is solved with: its own lo/hi, or -+ mu |lambda_normal|
// for a friction row (normal_row >= 0, a valid index other than i).
inline std::pair<Real, Real> lcpRowBounds(std::span<const ConstraintRow> rows, std::size_t i) {
  const ConstraintRow& r = rows[i];
  if (r.normal_row >= 0 && static_cast<std::size_t>(r.normal_row) < rows.size() &&
      static_cast<std::size_t>(r.normal_row) != i) {
    const Real h = std::abs(r.mu * rows[static_cast<std::size_t>(r.normal_row)].lambda);
    return {-h, h};
  }
  return {r.lo, r.hi};
}

struct LcpResidualReport {
  Real max_norm = 0;
  Real two_norm = 0;
  int worst_row = -1;  // argmax |F_i|, -1 when there are no rows
};

// Natural map of rows[i].lambda with w from the given (post-solve)
// velocities, in both norms. O(rows), allocates nothing.
LcpResidualReport lcpResidualReport(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies);

// The same, one norm.
Real lcpResidual(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies,
                 ResidualNorm norm = ResidualNorm::Max);

// Relative distance between two impulse vectors:
//     |a - b|_2 / max(|a|_2, |b|_2),
// 0 when both are zero and +inf when the sizes differ. Symmetric; 1e-9
// means "agree to nine digits" whatever the impulses' magnitude.
double lambdaDistance(const std::vector<double>& a, const std::vector<double>& b);

// The rows' impulses as a vector (for lambdaDistance).
std::vector<double> rowLambdas(std::span<const ConstraintRow> rows);

}  // namespace cairn
