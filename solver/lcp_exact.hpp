// Exact solution of the constraint rows' mixed LCP for small systems (up to
// a few hundred rows): the ground truth that PGS and the direct solver are
// measured against (docs/solvers-exact.md).
//
// Problem (constraints/row.hpp): with A = J M^-1 J^T (solver/dense_system.hpp)
// and b = J v* - rhs, v* the velocities on entry, find lambda with
//
//     w = (A + diag(cfm)) lambda + b,   lo <= lambda <= hi,
//     lambda_i = lo_i and w_i >= 0,  or  lambda_i = hi_i and w_i <= 0,
//     or  lo_i < lambda_i < hi_i and w_i = 0,
//
// where a friction row (normal_row >= 0) has lo = -hi = -mu |lambda_normal|.
//
// Method: Dantzig's principal pivoting for box-bounded LCPs, as in ODE's
// dSolveLCP (lcp.cpp). Rows are driven one at a time into the solution,
// unbounded rows first (solved as equalities), then bounded rows, then
// friction rows; while row d is driven, the rows already placed keep their
// complementarity, moving between the clamped set C (w = 0) and the bound
// set N (lambda at lo or hi) when the ratio test says so. A Cholesky factor
// of A[C, C] is updated per pivot (bordering on insertion, a rank-one
// update on deletion), so a pivot costs O(n |C|) and a solve O(n^3) for
// the usual O(n) pivots.
//
// Friction: the first pass is ODE's: the friction bounds are set from the
// normal impulses when the first friction row is reached (after every
// non-friction row is placed). Later friction pivots change the normal
// impulses, so ODE's answer can violate the cone of the final normals.
// After each pass, the pass's index sets are taken as a guess of the
// coupled problem's: clamped rows w_i = 0, bound rows at their bound, and
// a friction row at its bound tied linearly to its normal
// (lambda_f = -+ mu lambda_n). That linear system (one LU) is Newton's step
// on the piecewise-linear natural map; its solution is accepted when its
// coupled residual is at round-off level; if not, up to 8 further Newton
// steps use the index sets the natural map selects at the new point.
// Otherwise the next pass fixes the friction bounds at the average of the
// previous bounds' source and this pass's impulses (a damped fixed-point
// iteration). Coulomb friction's LCP may have no or many solutions: if
// neither converges within max_friction_iterations passes, the result is
// the candidate with the smallest residual and converged = false.
//
// Singular A: redundant rows with cfm = 0 make A[C, C] singular. When a row
// entering C has a Schur complement below `singular_pivot` times its
// diagonal, the solve restarts on A + r I with r = regularization *
// max_i(A_ii + cfm_i) and reports it; lambda then satisfies the LCP of the
// regularized matrix exactly, i.e. the original one up to r |lambda|.
#pragma once

#include "constraints/row.hpp"
#include "solver/solver_body.hpp"

#include <Eigen/Core>

#include <memory>
#include <span>

namespace cairn {

struct ExactLcpOptions {
  int max_pivots = 0;                 // per pass; 0 = 20 n + 100 (guards against degenerate cycling)
  int max_friction_iterations = 100;  // passes for friction coupling
  bool polish_active_set = true;      // the Newton step after each pass; false with 1 pass = ODE exactly
  // Friction coupling is solved when a pass's friction bounds match its own
  // normal impulses to tolerance * L, or a Newton candidate's natural-map
  // residual is at most tolerance * max(|b|, max A_ii L, L), where L is
  // max |lambda| after the first (ODE) pass; norms are max norms.
  double tolerance = 1e-12;
  double singular_pivot = 1e-11;      // Schur complement / diagonal below this = linearly dependent row
  double regularization = 1e-10;      // diagonal shift when singular, relative to max(A_ii + cfm_i)
  // solveLcpExact only: true when the velocities on entry already contain
  // M^-1 J^T rows[i].lambda (the caller warm-started them, as before PGS);
  // that impulse is removed first so that v* is the impulse-free velocity.
  bool velocities_include_lambda = false;
};

struct ExactLcpResult {
  bool converged = false;      // pivoting finished and the friction coupling reached its fixed point
  int pivots = 0;              // ratio-test steps over all passes
  double residual = 0;         // natural-map max norm at the returned lambda (solver/lcp_residual.hpp)
  bool regularized = false;    // A was singular; `regularization` was added to its diagonal
  double regularization = 0;   // absolute diagonal shift (0 when none)
  int friction_iterations = 0; // passes run (1 without friction rows)
};

// The solver with its workspace (the dense problem, the factor of the
// clamped set, the pass's and the Newton step's vectors) kept from solve to
// solve: once it has solved a problem of a size, another of that size
// allocates nothing (the step's exact islands, every substep). The same
// arithmetic as a fresh solver, so the same answer to the bit.
class ExactLcpSolver {
 public:
  ExactLcpSolver();
  ~ExactLcpSolver();
  ExactLcpSolver(ExactLcpSolver&&) noexcept;
  ExactLcpSolver& operator=(ExactLcpSolver&&) noexcept;

  // Solves the rows' LCP exactly, writes rows[i].lambda (the entry value
  // is not used as a guess) and sets the velocities to
  // v* + M^-1 J^T lambda. The residual is lcpResidual(rows, bodies,
  // ResidualNorm::Max) afterwards. O(n^2) memory, O(n^3) time: for a few
  // hundred rows at most.
  ExactLcpResult solve(std::span<ConstraintRow> rows, std::span<SolverBody> bodies,
                       const ExactLcpOptions& options = {});
  // solveLcpExactDense's problem (below); the answer stays valid until the
  // next solve.
  const Eigen::VectorXd& solveDense(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lo,
                                    const Eigen::VectorXd& hi, std::span<const int> findex,
                                    const ExactLcpOptions& options = {}, ExactLcpResult* result = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ExactLcpSolver::solve with a solver of its own.
ExactLcpResult solveLcpExact(std::span<ConstraintRow> rows, std::span<SolverBody> bodies,
                             const ExactLcpOptions& options = {});

// The same on a dense problem, w = A lambda + b (A symmetric positive
// semidefinite, cfm already on its diagonal). findex follows ODE: for a
// friction row (findex[i] >= 0) hi[i] holds the friction coefficient mu and
// lo[i] is ignored; the bounds are -+ mu |lambda[findex[i]]|. findex may be
// empty (no friction). The residual reported is the natural map's max norm
// with w = A lambda + b. Never returns NaN: on failure the best finite
// iterate, projected on the bounds, with converged = false.
Eigen::VectorXd solveLcpExactDense(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lo,
                                   const Eigen::VectorXd& hi, std::span<const int> findex,
                                   const ExactLcpOptions& options = {}, ExactLcpResult* result = nullptr);

}  // namespace cairn
