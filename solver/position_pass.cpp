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
  while (st.iterations < options.max_iterations && st.error_after > options.tolerance) {
    std::fill(bodies.begin(), bodies.end(), SolverBody{});
    const DirectSolveStats ds = solver.solve(rows, bodies, d);
    if (ds.factorization_failed) break;  // non-finite rows: the guard reports them
    for (SolverBody& b : bodies) {
      b.v *= options.h;
      b.w *= options.h;
    }
    move(bodies);
    ++st.iterations;
    build(rows);
    st.error_after = largestPositionError(rows, options.h);
  }
  return st;
}

}  // namespace cairn
