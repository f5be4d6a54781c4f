// Heavy weights on light chains (docs/extremes.md, "Heavy chains"): 40
// rods of 0.5 m and 1 kg on ball joints hanging from the world, the last
// rod R kg, nudged sideways at 5 cm/s, h = 1/60, 10 s. Without geometric
// stiffness (world/geometric_stiffness.cpp) and the joint position pass
// (solver/position_pass.hpp) the direct solver lets the joints open by
// metres (the linearization at the step's start lags the tension's
// direction); with them every joint stays closed.
#include "test_helpers.hpp"
#include "validation/scenarios.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace cairn {
namespace {

struct ChainRun {
  Real worst_joint = 0;  // largest anchor separation over the run (m)
  Real energy_rise = 0;  // largest E(t) - E(0) over the run (J)
  Real energy0 = 0;
  Real reported_position_error = 0;  // StepStats::position_error, largest
};

ChainRun runChain(Real ratio, SolverMethod method, int position_iterations, bool geometric_stiffness = true,
                  int steps = 600) {
  SceneDesc s = scenarios::heavyHangingChain(40, ratio);
  s.solver.method = method;
  s.solver.position_iterations = position_iterations;
  s.solver.geometric_stiffness = geometric_stiffness;
  s.solver.sleeping = false;
  World w = buildWorld(s);
  auto& in = cairn::detail::internals(w);
  ChainRun r;
  r.energy0 = in.kineticEnergy() + in.potentialEnergy();
  for (int k = 0; k < steps; ++k) {
    w.step(s.dt);
    for (int j = 0; j < in.jointSlots(); ++j) r.worst_joint = std::max(r.worst_joint, w.jointError(JointId{j}).linear);
    r.energy_rise = std::max(r.energy_rise, in.kineticEnergy() + in.potentialEnergy() - r.energy0);
    r.reported_position_error = std::max(r.reported_position_error, w.lastStepStats().position_error);
  }
  return r;
}

// The requirement's figure: under 1 mm of joint error at 1:100, 1:1000 and
// 1:10,000 over 10 s. The pass stops at 1e-9 m of row error or after its
// Newton steps; each step divides the millimetres one velocity step leaves
// by far more than 1000, so 1 mm is loose by orders of magnitude and still
// three orders below the metres the velocity solve alone leaves. The
// chain swings from a 5 cm/s nudge: its energy must not grow (geometric
// stiffness only damps; the pass's velocity update follows corrections of
// nanometres), bounded by 1e-6 of the weight's potential over the 20 m
// chain (m g L): 2 J at 1:100, far below the kilojoules a tearing chain
// releases and far above the micro-joules of round-off.
TEST(HeavyChain, DirectSolveWithPositionPassHoldsEveryRatioUnderOneMillimetre) {
  for (const Real ratio : {Real(100), Real(1000), Real(10000)}) {
    const ChainRun r = runChain(ratio, SolverMethod::Direct, 4);
    EXPECT_LT(r.worst_joint, 1e-3) << "1:" << ratio;
    EXPECT_LT(r.energy_rise, 1e-6 * ratio * 9.81 * 20) << "1:" << ratio;
  }
}

// The failure, measured on the same scene: the direct solve alone opens
// the 1:100 chain by metres (docs/extremes.md: 19.9 m), far beyond the 2%
// of a link (1 cm) the extremes call holding. The position pass alone
// holds 1:100 (the light links' stiff mode, h sqrt(6 T / (m L)) = 1.8, is
// still below the explicit limit of 2) but not 1:1000 (5.7): that takes
// the geometric stiffness.
TEST(HeavyChain, WithoutGeometricStiffnessTheVelocitySolveTearsTheChain) {
  EXPECT_GT(runChain(100, SolverMethod::Direct, 0, false).worst_joint, 0.01);
  EXPECT_LT(runChain(100, SolverMethod::Direct, 4, false).worst_joint, 1e-3);
  EXPECT_GT(runChain(1000, SolverMethod::Direct, 4, false).worst_joint, 0.01);
  EXPECT_LT(runChain(1000, SolverMethod::Direct, 0, true).worst_joint, 1e-3);
}

// PGS islands get no position pass: the joint error they report is the one
// their sweeps leave (here centimetres and more at 1:100), and the step
// statistics show no position correction for them.
TEST(HeavyChain, PgsReportsTheJointErrorItLeaves) {
  const ChainRun pgs = runChain(100, SolverMethod::PGS, 4, true, 300);
  EXPECT_GT(pgs.worst_joint, 0.01);
  EXPECT_EQ(pgs.reported_position_error, 0);
}

}  // namespace
}  // namespace cairn
