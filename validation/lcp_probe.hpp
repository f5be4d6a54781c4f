// How far a step's impulses are from the exact solution of the LCP that
// step posed (docs/tradeoff.md, "Distance from the exact LCP"). lambda are
// the impulses the World's solver found for the rows of its last
// (sub)step (World::rows()), lambda* solves the same rows exactly
// (solver/lcp_exact.hpp, Dantzig pivoting), island by island. Two figures:
//
//   lambda    |lambda - lambda*|_2 / max(|lambda|_2, |lambda*|_2)
//             (solver/lcp_residual.hpp, lambdaDistance)
//   velocity  |J^T (lambda - lambda*)|_M^-1 / max(|J^T lambda|_M^-1, |J^T lambda*|_M^-1),
//             |p|_M^-1 = sqrt(p^T M^-1 p): the velocity change the impulses
//             make, compared in the kinetic-energy norm
//
// The first is the textbook one but assumes lambda* is unique. A box
// resting on four contact points is statically indeterminate: A is
// singular and any split of the weight among the points solves the LCP
// exactly (measured: the exact solver and the World's own lcp method
// picked splits 0.78 apart on column-3). The second ignores that freedom,
// since every exact solution moves the bodies the same way, and is the
// figure to read for stacks; on chains and hinges (A regular) both agree.
//
// The exact solve needs v*, the velocities the rows were solved from, which
// the World does not keep. They are recovered exactly in two cases:
//
//   1. No row carried a Baumgarte correction pass (Correction::VelocityBias
//      with something to correct): the velocities after the step are then
//      v* + M^-1 J^T lambda, so v* = v - M^-1 J^T lambda. This covers
//      contacts with split impulse, and every row under the direct and lcp
//      methods (their joints solve the ERP target in the one solve), for
//      any number of substeps.
//   2. Otherwise (PGS with joints, whose correction pass changes v after the
//      solve), with one substep and no springs: v* is integrateVelocity of
//      the state the step started from, as the World computes it.
//
// PGS with joints and several substeps is neither: the probe then reports
// nothing rather than a wrong figure. Nor does it when an island has more
// than `max_rows` rows (the exact solver is dense, O(n^3)) or the exact
// solver does not converge (it can cycle on a stack's redundant contacts).
#pragma once

#include "dynamics/body.hpp"
#include "world/world_access.hpp"

#include <optional>
#include <string>
#include <vector>

namespace cairn::validation {

class ExactLcpProbe {
 public:
  explicit ExactLcpProbe(int max_rows = 600) : max_rows_(max_rows) {}

  // Call before World::step(h) on a sampled step: keeps the bodies' state
  // for case 2.
  void beforeStep(const World& world);

  struct Distance {
    double lambda = 0, velocity = 0;
  };
  // Call after the step: the distances, or nullopt when the step solved no
  // rows or v* cannot be recovered (why() says which).
  std::optional<Distance> afterStep(const World& world, Real h);
  const std::string& why() const { return why_; }

 private:
  int max_rows_;
  std::vector<Body> before_;
  std::string why_;
};

}  // namespace cairn::validation
