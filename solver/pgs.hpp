// Projected Gauss-Seidel over constraint rows (ODE quickstep, Catto's
// sequential impulses). One sweep visits every row once:
//
//   delta  = (rhs - J v - cfm lambda) / (A_ii + cfm)
//   lambda' = clamp(lambda + sor * delta, lo, hi)      (friction: +-mu lambda_n)
//   v     += M^-1 J^T (lambda' - lambda)
//
// Manifold blocks: the normal rows of one contact manifold (2 to 4 points
// between the same two bodies) are solved together, as one unit, on their
// small effective-mass matrix A_b = J_b M^-1 J_b^T -- by its Cholesky
// factor when every point pushes, else by local projected sweeps -- then
// applied to the bodies once. Visiting the
// points one after another instead leaves a bias toward the first point
// every sweep, a spurious torque that makes tall stacks rock (a 10-box
// column at 10 iterations sways by 12 cm without blocks, 0.04 mm with them;
// docs/constraints.md). This is Box2D's block solver idea, extended to 3
// and 4 points and singular blocks.
//
// Between sweeps, NNCG momentum (settings `nncg`, pgs.cpp momentumStep).
//
// Rows come with their warm-start impulse already in `lambda`; the caller
// applies it to the velocities first (applyWarmStart). The inner loop
// touches only the row and its two bodies' velocities: no allocation, no
// indirection beyond the two body indices.
#pragma once

#include "constraints/row.hpp"
#include "solver/solver_body.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace cairn {

struct PgsSettings {
  int iterations = 10;
  Real tolerance = 0;  // stop when no row's impulse changed by more than this in a sweep (N s); 0 = never
  Real sor = 1;
  bool randomize_order = false;
  std::uint64_t seed = 1;
  bool manifold_blocks = true;  // solve each manifold's normal rows as one block
  bool nncg = true;             // conjugate-gradient momentum between sweeps (pgs.cpp, momentumStep)
};

struct PgsStats {
  int iterations = 0;
  Real last_max_delta = 0;  // largest impulse change in the last sweep
};

// Buffers reused from step to step so that solving allocates nothing.
struct PgsScratch {
  std::vector<std::int32_t> unit_begin;  // first row of each unit (a row or a block)
  std::vector<std::int32_t> block_of;    // per unit: offset of its block matrix in `block`, or -1
  std::vector<Real> block;               // blocks' A_b, n x n row-major (n <= 4), each followed by its Cholesky factor
  std::vector<std::int32_t> order;       // unit visiting order (randomized)
  std::vector<Real> change;              // NNCG: each row's impulse change in the last sweep
  std::vector<Real> direction;           // NNCG: the momentum direction p
};

// Adds M^-1 J^T lambda of every row to the velocities.
void applyWarmStart(std::span<const ConstraintRow> rows, std::span<SolverBody> bodies);

// Runs the sweeps; `rng_state` advances so a run is reproducible from the seed.
PgsStats solvePgs(std::span<ConstraintRow> rows, std::span<SolverBody> bodies, const PgsSettings& s,
                  PgsScratch& scratch, std::uint64_t& rng_state);

// The position-correction pass: solves the rows whose correction is `which`
// for the targets bias_rhs, from zero impulses, adding the result to
// `bodies` (the real velocities for VelocityBias, a zeroed pseudo-velocity
// array for PseudoVelocity). Impulses go to the `lambda` scratch so the
// velocity impulses (warm start, friction bounds) are untouched. Returns
// false when no row of that kind had an error to correct.
bool solvePgsCorrection(std::span<const ConstraintRow> rows, std::span<SolverBody> bodies, Correction which,
                        const PgsSettings& s, std::vector<Real>& lambda);

// The residual is solver/lcp_residual.hpp's lcpResidual.

}  // namespace cairn
