// Direct sparse solve of the bilateral rows, PGS on the others
// (docs/solvers-exact.md, "Direct solver").
//
// Rows split into bilateral B (lo = -inf, hi = +inf, not friction) and
// unilateral U (every bounded row and every friction row). With
// w = (A + diag(cfm)) lambda + b as in constraints/row.hpp, one outer
// iteration of this block Gauss-Seidel is
//
//   1. B exactly, U fixed:  (A_BB + C_B) delta = -w_B(current),
//      lambda_B += delta, v += M^-1 J_B^T delta  (tree factor or CHOLMOD)
//   2. U by `inner_pgs_iterations` projected Gauss-Seidel sweeps, B fixed:
//      lambda_i = clamp(lambda_i - w_i / (A_ii + cfm_i), lo_i, hi_i),
//      friction bounds -+ mu |lambda_normal| from the current normal.
//
// and after the last outer iteration step 1 runs once more, so the joints
// hold exactly for the final unilateral impulses.
//
// w is always computed from the velocities (v = v* + M^-1 J^T lambda), so
// step 1 needs only A_BB, never the coupling A_BU. When the bilateral
// rows' bodies form a forest (chains, ragdolls, any tree of joints), A_BB
// is factored in linear time by solver/tree_factor.hpp with no fill;
// otherwise (closed loops) it is assembled sparsely (solver/
// dense_system.hpp) and factored with CHOLMOD. Either analysis (the tree's
// elimination order; CHOLMOD's fill-reducing ordering, elimination tree and
// supernodes) depends only on which bilateral rows share which bodies, so
// it is kept and reused while that pattern (the rows' coupling bodies,
// compared exactly) is unchanged; only the numeric factorization runs
// each call.
//
// If A_BB is not numerically positive definite (redundant bilateral rows
// with cfm = 0, e.g. a closed loop of joints), it is refactored with
// regularization * max(diag A_BB) added to its diagonal and the stats say
// so. The outer loop then also acts as a proximal-point iteration: each
// solve uses the true (unshifted) residual, so consistent redundant rows
// still converge to w_B = 0.
#pragma once

#include "constraints/row.hpp"
#include "solver/solver_body.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace cairn {

struct DirectSolverOptions {
  int outer_iterations = 8;       // block Gauss-Seidel iterations (one suffices without unilateral rows)
  int inner_pgs_iterations = 8;   // PGS sweeps over the unilateral rows per outer iteration
  double regularization = 1e-10;  // diagonal shift, relative to max(A_ii + cfm_i) over B, used only when
                                  // A_BB is not numerically positive definite
  bool warm_start = true;         // start from rows[i].lambda instead of 0
  // True when the entry velocities already contain M^-1 J^T rows[i].lambda
  // (PGS's applyWarmStart ran). Otherwise the solver adds the warm-start
  // impulse itself. Either way the result is v = v* + M^-1 J^T lambda.
  bool velocities_include_lambda = false;
  // Fill DirectSolveStats::residual and residual_history (a pass over the
  // rows each; the step's callers measure what they need themselves).
  bool report_residual = true;
};

struct DirectSolveStats {
  int bilateral_rows = 0;
  int unilateral_rows = 0;
  int inert_rows = 0;              // move no body and have cfm = 0: lambda left at clamp(0, lo, hi)
  int outer_iterations = 0;        // performed
  bool analysed = false;           // this call analysed the structure (tree factor's ordering or CHOLMOD's)
  bool tree_factor = false;        // A_BB was factored by the tree factor, not CHOLMOD
  int analysis_count = 0;          // symbolic analyses over the solver's life
  int factorizations = 0;          // numeric factorizations in this call (2 when regularized)
  bool regularized = false;        // A_BB was not positive definite; `regularization` was added
  double regularization = 0;       // absolute diagonal shift (0 when none)
  bool factorization_failed = false;  // even the shifted A_BB failed (non-finite rows): B was not solved
  std::uint64_t structure_hash = 0;   // FNV-1a of the bilateral rows' coupling bodies, in order
  double residual = 0;                // natural-map max norm on return (solver/lcp_residual.hpp)
  std::vector<double> residual_history;  // the same after each outer iteration (before the final step 1)
};

// Holds the structure's analysis (the tree factor's or CHOLMOD's) between calls (one per island or scene
// that keeps its structure). Not copyable; movable.
class DirectSolver {
 public:
  DirectSolver();
  ~DirectSolver();
  DirectSolver(DirectSolver&&) noexcept;
  DirectSolver& operator=(DirectSolver&&) noexcept;
  DirectSolver(const DirectSolver&) = delete;
  DirectSolver& operator=(const DirectSolver&) = delete;

  // Solves the rows' LCP as above, writes rows[i].lambda and updates the
  // velocities to v* + M^-1 J^T lambda.
  DirectSolveStats solve(std::span<ConstraintRow> rows, std::span<SolverBody> bodies,
                         const DirectSolverOptions& options = {});

  int analysisCount() const;
  std::uint64_t structureHash() const;
  void reset();  // forget the analysis (the next solve analyses again)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cairn
