// The three solver methods on the same scenes: the direct and exact
// solvers hold chains that PGS lets stretch, and all agree on a simple one.
#include "test_helpers.hpp"
#include "validation/scenarios.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

Real worstChainError(SolverMethod m, int iterations, Real heavy_ratio, bool nncg = true) {
  SceneDesc s = scenarios::hangingChain(20);
  s.solver.method = m;
  s.solver.nncg = nncg;
  s.solver.iterations = iterations;
  s.solver.sleeping = false;
  s.bodies.back().mass = heavy_ratio;  // a heavy weight at the end of light links
  s.bodies.back().linear_velocity.setZero();  // hanging still
  World w = buildWorld(s);
  Real worst = 0;
  for (int k = 0; k < 120; ++k) {
    w.step(s.dt);
    for (int j = 0; j < cairn::detail::internals(w).jointSlots(); ++j) worst = std::max(worst, w.jointError(JointId{j}).linear);
  }
  return worst;
}

// A 1000 kg weight hanging still from 20 links of 1 kg: plain PGS at 100
// iterations cannot carry the load down the chain (the joints open by
// centimetres within 2 s and the weight sinks); NNCG's momentum brings that
// under a few millimetres; CHOLMOD's exact bilateral solve holds every
// joint to round-off. (With the weight set swinging, even exact solves let
// the whipped light links drift: docs/extremes.md.)
TEST(SolverMethods, DirectHoldsMassRatioChainFarBetterThanPgs) {
  const Real plain = worstChainError(SolverMethod::PGS, 100, 1000, false);
  const Real nncg = worstChainError(SolverMethod::PGS, 100, 1000, true);
  const Real direct = worstChainError(SolverMethod::Direct, 10, 1000);
  EXPECT_LT(direct, 1e-9);
  EXPECT_GT(plain, 1e-2);
  EXPECT_LT(nncg, plain / 5);
  EXPECT_GT(nncg, 1e3 * direct);
}

// 100 links hanging still whose masses alternate 1 kg and 1000 kg (a 1:1000
// ratio at every joint), 2 s: the direct solve holds every joint to well
// under a micrometre; PGS at 100 iterations cannot pass the heavy links'
// load through the light ones and opens the chain by orders of magnitude
// more.
TEST(SolverMethods, DirectHoldsHundredLinkAlternatingMassChain) {
  const auto worst = [](SolverMethod m, int iterations) {
    SceneDesc s = scenarios::hangingChain(100);
    s.solver.method = m;
    s.solver.iterations = iterations;
    s.solver.sleeping = false;
    for (size_t i = 0; i < s.bodies.size(); ++i) {
      s.bodies[i].mass = i % 2 == 0 ? 1 : 1000;
      s.bodies[i].linear_velocity.setZero();
    }
    World w = buildWorld(s);
    Real e = 0;
    for (int k = 0; k < 120; ++k) {
      w.step(s.dt);
      for (int j = 0; j < cairn::detail::internals(w).jointSlots(); ++j) e = std::max(e, w.jointError(JointId{j}).linear);
    }
    return e;
  };
  const Real direct = worst(SolverMethod::Direct, 10);
  const Real pgs = worst(SolverMethod::PGS, 100);
  EXPECT_LT(direct, 1e-6);
  EXPECT_GT(pgs, 1e3 * direct);
}

// The exact LCP solver on a small stack gives a residual at round-off.
TEST(SolverMethods, ExactLcpSolvesAStackToRoundOff) {
  SceneDesc s = scenarios::column(3);
  s.solver.method = SolverMethod::LCP;
  s.solver.sleeping = false;
  World w = buildWorld(s);
  for (int k = 0; k < 60; ++k) w.step(s.dt);
  EXPECT_LT(w.lastStepStats().residual, 1e-9);
  EXPECT_NEAR(cairn::detail::internals(w).bodies().back().position.y(), 2.5, 0.01);
}

}  // namespace
}  // namespace cairn
