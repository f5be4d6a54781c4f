// Newton's method on the joints' position constraints, each step one
// sparse direct solve (solver/position_pass.hpp derives it).
#include "solver/position_pass.hpp"

#include <algorithm>
#include <cmath>

namespace cairn {

Real largestPositionError(std::span<const ConstraintRow> rows, Real h) {
  Real worst = 0;
  for (const ConstraintRow& r : rows) worst = std::max(worst, h * std::abs(r.rhs));
  return worst;
}

PositionPassStats solvePositionPass(DirectSolver& solver, std::vector<ConstraintRow>& rows,
                                    std::vector<SolverBody>& bodies,
                                    const std::function<void(std::vector<ConstraintRow>&)>& build,
                                    const std::function<void(std::span<const SolverBody>)>& move,
                                    const PositionPassOptions& options) {
  PositionPassStats st;
  build(rows);
  st.error_before = st.error_after = largestPositionError(rows, options.h);
  DirectSolverOptions d;
  d.outer_iterations = 1;  // bilateral rows only: one exact solve
  d.warm_start = false;    // a correction from zero, never last step's
  d.report_residual = false;  // the pass measures its own error
  while (st.iterations < options.max_iterations && st.error_after > options.tolerance) {
    std::fill(bodies.begin(), bodies.end(), SolverBody{});
    const DirectSolveStats ds = solver.solve(rows, bodies, d);
    if (ds.factorization_failed) break;  // non-finite rows: the guard reports them
    // Backtracking (Nocedal and Wright, "Numerical Optimization", 2nd ed.,
    // section 3.1): far from the manifold the linearization can overshoot
    // (a whipping chain's links swing through large angles within a step),
    // so a step that does not lower the largest error is taken back
    // exactly (the same displacement negated) and halved.
    Real scale = options.h;
    bool accepted = false;
    for (int halving = 0; halving < options.max_halvings && !accepted; ++halving, scale /= 2) {
      for (SolverBody& b : bodies) {
        b.v *= scale;
        b.w *= scale;
      }
      move(bodies);
      build(rows);
      const Real error = largestPositionError(rows, options.h);
      if (error < st.error_after) {
        st.error_after = error;
        accepted = true;
        break;
      }
      // Taken back in place (negation is exact): a copy would allocate
      // in the step.
      for (SolverBody& b : bodies) {
        b.v = -b.v;
        b.w = -b.w;
      }
      move(bodies);
      for (SolverBody& b : bodies) {
        b.v = -b.v / scale;
        b.w = -b.w / scale;
      }
    }
    ++st.iterations;
    if (!accepted) {
      build(rows);  // the rows at the restored pose, for the caller
      break;
    }
  }
  return st;
}

}  // namespace cairn
