// The nonlinear position pass: after the velocity solve and the position
// update, project the bodies back onto the joints' constraint manifold
// C(x) = 0 by Newton's method (docs/extremes.md, "Heavy chains").
//
// Why: the velocity solve makes J(x_n) v_{n+1} = 0 with the Jacobian of the
// step's start, and x_{n+1} = x_n + h v_{n+1} then leaves the manifold by
// O(h^2 |v|^2 / L) per joint. Under a large tension T the transverse mode
// of a light link (mass m, length L) has the rate sqrt(T / (m L)); when h
// times that rate nears 1 the linearization lags the force's direction by
// a finite angle every step and the drift feeds itself: a 100 kg weight on
// 1 kg links falls at nearly g while its joints open by metres. A pass on
// positions that relinearizes at the moved pose removes the drift wherever
// it came from (Cline and Pai, "Post-Stabilization for Rigid Body
// Simulation with Contact and Constraints", ICRA 2003; Box2D v2's
// SolvePositionConstraints and Jolt's position iterations do the same
// with Gauss-Seidel sweeps, which at a 1:10,000 mass ratio converge no
// better than PGS does on velocities, so here each Newton step is one
// sparse direct solve).
//
// One Newton step, with the rows built at the current pose x and the
// position feedback at ERP = 1 (rhs = -C / h):
//
//   (J M^-1 J^T) lambda = -C / h,   dx = h M^-1 J^T lambda
//
// so J dx = -C: the linearized constraint is met exactly. Repeated from
// the moved pose it converges quadratically (a few steps from the
// millimetres one velocity step leaves); a step that would raise the
// largest error is taken back and halved (backtracking). The caller's
// `move` also moves the velocities by dx / h, so they stay those of the
// corrected positions, v = (x_{n+1} - x_n) / h, as position-based
// dynamics updates them (Macklin, Mueller and Chentanez, "XPBD", MIG 2016).
#pragma once

#include "constraints/row.hpp"
#include "solver/direct_solver.hpp"
#include "solver/solver_body.hpp"

#include <functional>
#include <span>
#include <vector>

namespace cairn {

struct PositionPassOptions {
  int max_iterations = 4;       // Newton steps at most
  Real tolerance = Real(1e-9);  // stop when every row's |C| (m or rad) is below this
  Real h = Real(1) / 60;        // the (sub)step the rows' rhs = -C/h was built with
  int max_halvings = 4;         // backtracking: a step that does not lower the error is halved this often
};

struct PositionPassStats {
  int iterations = 0;     // Newton steps taken
  Real error_before = 0;  // largest |C| of the rows before the first step
  Real error_after = 0;   // after the last step (as the last rebuild measured it)
};

// `build` fills `rows` (cleared by the caller's callback) at the current
// poses; `move` applies the displacements dx = h M^-1 J^T lambda per solver
// body (index 0, the world, is always zero) and updates the poses.
// `bodies` is scratch of the solver-body count.
PositionPassStats solvePositionPass(DirectSolver& solver, std::vector<ConstraintRow>& rows,
                                    std::vector<SolverBody>& bodies,
                                    const std::function<void(std::vector<ConstraintRow>&)>& build,
                                    const std::function<void(std::span<const SolverBody>)>& move,
                                    const PositionPassOptions& options);

// The largest position error |C| = h |rhs| of rows built with ERP = 1.
Real largestPositionError(std::span<const ConstraintRow> rows, Real h);

}  // namespace cairn
