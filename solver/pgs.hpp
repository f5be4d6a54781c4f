// Projected Gauss-Seidel over constraint rows (ODE quickstep, Catto's
// sequential impulses). One sweep visits every row once:
//
//   delta  = (rhs - J v - cfm lambda) / (A_ii + cfm)
//   lambda' = clamp(lambda + sor * delta, lo, hi)      (friction: +-mu lambda_n)
//   v     += M^-1 J^T (lambda' - lambda)
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
};

struct PgsStats {
  int iterations = 0;
  Real last_max_delta = 0;  // largest impulse change in the last sweep
};

// Adds M^-1 J^T lambda of every row to the velocities.
void applyWarmStart(std::span<const ConstraintRow> rows, std::span<SolverBody> bodies);

// Runs the sweeps. `order` is scratch space for the randomized order (kept
// by the caller so nothing is allocated per step); `rng_state` advances so a
// run is reproducible from the seed.
PgsStats solvePgs(std::span<ConstraintRow> rows, std::span<SolverBody> bodies, const PgsSettings& s,
                  std::vector<std::int32_t>& order, std::uint64_t& rng_state);

// The position-correction pass: solves the rows whose correction is `which`
// for the targets bias_rhs, from zero impulses, adding the result to
// `bodies` (the real velocities for VelocityBias, a zeroed pseudo-velocity
// array for PseudoVelocity). Impulses go to the `lambda` scratch so the
// velocity impulses (warm start, friction bounds) are untouched. Returns
// false when no row of that kind had an error to correct.
bool solvePgsCorrection(std::span<const ConstraintRow> rows, std::span<SolverBody> bodies, Correction which,
                        const PgsSettings& s, std::vector<Real>& lambda);

// Natural-map residual of the mixed LCP at the current impulses and
// velocities (solver/lcp_residual.hpp has the definition); max norm.
Real pgsResidual(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies);

}  // namespace cairn
