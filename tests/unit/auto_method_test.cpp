// solver.method = "auto", the default (world/method_choice.cpp;
// docs/extremes.md, "auto"): the islands PGS carries stay PGS, bit for bit,
// and the ill-conditioned ones get the solve they need and hold.
#include "test_helpers.hpp"
#include "validation/scenarios.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace cairn {
namespace {

struct AutoRun {
  int steps_by_reason[kMethodReasonCount] = {};  // island-steps
  int steps_by_method[kSolverMethodCount] = {};
  Real worst_joint = 0;            // largest anchor separation over the run (m)
  Real worst_penetration = 0;      // deepest contact over the run (m)
  Real worst_displacement = 0;     // largest distance of a dynamic body from its start (m)
};

// Sleeping off, as in docs/scenarios.md's conditions: every step is solved.
AutoRun runAuto(SceneDesc s, int steps) {
  s.solver.sleeping = false;
  World w = buildWorld(s);
  auto& in = cairn::detail::internals(w);
  std::vector<Vec3> start;
  for (int i = 0; i < w.bodyCount(); ++i) start.push_back(in.body(BodyId{i}).position);
  AutoRun r;
  for (int k = 0; k < steps; ++k) {
    w.step(s.dt);
    const StepStats& st = w.lastStepStats();
    for (int m = 0; m < kMethodReasonCount; ++m) r.steps_by_reason[m] += st.islands_by_reason[m];
    for (int m = 0; m < kSolverMethodCount; ++m) r.steps_by_method[m] += st.islands_by_method[m];
    r.worst_penetration = std::max(r.worst_penetration, Real(st.max_penetration));
    for (int j = 0; j < in.jointSlots(); ++j) r.worst_joint = std::max(r.worst_joint, w.jointError(JointId{j}).linear);
    for (int i = 0; i < w.bodyCount(); ++i)
      if (in.body(BodyId{i}).inv_mass > 0)
        r.worst_displacement = std::max(r.worst_displacement, (in.body(BodyId{i}).position - start[i]).norm());
  }
  return r;
}

int reasonSteps(const AutoRun& r, MethodReason m) { return r.steps_by_reason[static_cast<int>(m)]; }
int methodSteps(const AutoRun& r, SolverMethod m) { return r.steps_by_method[static_cast<int>(m)]; }
int allSteps(const AutoRun& r) {
  int n = 0;
  for (int k : r.steps_by_reason) n += k;
  return n;
}

TEST(AutoMethod, IsTheDefault) { EXPECT_EQ(SolverSettings{}.method, SolverMethod::Auto); }

// The standard scenes PGS holds are well-conditioned for it (unit mass
// ratios, at most 10 joints, no joint left open): auto leaves every island
// on PGS, and then the step is PGS's, bit for bit. The ragdoll's landing
// opens its joints by 1.3 cm for a few steps, a transient PGS closes, not
// the joint drift that makes auto leave PGS.
TEST(AutoMethod, WellConditionedScenesStayPgsBitForBit) {
  for (SceneDesc s : {scenarios::pyramid(10), scenarios::column(20), scenarios::ragdoll(), scenarios::hangingChain(20)}) {
    s.solver.method = SolverMethod::Auto;
    s.solver.sleeping = false;
    SceneDesc pgs_scene = s;
    pgs_scene.solver.method = SolverMethod::PGS;
    const AutoRun r = runAuto(s, s.steps);
    EXPECT_EQ(reasonSteps(r, MethodReason::WellConditioned), allSteps(r));
    EXPECT_EQ(methodSteps(r, SolverMethod::PGS), allSteps(r));
    World a = buildWorld(s), p = buildWorld(pgs_scene);
    for (int k = 0; k < s.steps; ++k) {
      a.step(s.dt);
      p.step(s.dt);
    }
    for (int i = 0; i < a.bodyCount(); ++i) {
      EXPECT_EQ(detail::internals(a).body(BodyId{i}).position, detail::internals(p).body(BodyId{i}).position) << i;
      EXPECT_EQ(detail::internals(a).body(BodyId{i}).linear_velocity,
                detail::internals(p).body(BodyId{i}).linear_velocity)
          << i;
    }
  }
}

// A 1000 kg box on a 1 kg box (docs/scenarios.md mass-ratio-1000): PGS at
// 10 sweeps lets it sink 10 cm into the light box (docs/extremes.md). Auto
// gives the two-box island the exact solve (mass_ratio): no contact
// deeper than the slop (the push-out holds contacts at the slop, 5 mm;
// 1% of it for the push-out's last step, the sleep rule's tolerance) and
// neither box moves by more than 1 mm (the light box is not squirted out).
TEST(AutoMethod, ThousandToOneBoxOnBoxHoldsWithinTheSlop) {
  const SceneDesc s = scenarios::massRatio(1000);
  const AutoRun r = runAuto(s, s.steps);
  EXPECT_EQ(reasonSteps(r, MethodReason::MassRatio), allSteps(r));
  EXPECT_EQ(methodSteps(r, SolverMethod::LCP), allSteps(r));
  EXPECT_LT(r.worst_penetration, s.solver.slop * 1.01);
  EXPECT_LT(r.worst_displacement, 1e-3);
  SceneDesc pgs = s;
  pgs.solver.method = SolverMethod::PGS;
  EXPECT_GT(runAuto(pgs, s.steps).worst_penetration, s.solver.slop * 1.01);
}

// Five boxes whose edge doubles upward (1:4096 top to bottom): PGS lets the
// stack collapse; auto's exact solve keeps it standing for the 10 s, every
// box within 5 cm of its start (the extremes' stack limit, a tenth of the
// 0.5 m collapse criterion) and no contact deeper than the slop.
TEST(AutoMethod, DoublingStackStandsTenSeconds) {
  const SceneDesc s = scenarios::doublingStack(5);
  const AutoRun r = runAuto(s, 600);
  EXPECT_EQ(reasonSteps(r, MethodReason::MassRatio), allSteps(r));
  EXPECT_LT(r.worst_displacement, 0.05);
  EXPECT_LT(r.worst_penetration, s.solver.slop * 1.01);
  SceneDesc pgs = s;
  pgs.solver.method = SolverMethod::PGS;
  EXPECT_GT(runAuto(pgs, 600).worst_displacement, 0.05);
}

// 40 links of 1 kg holding 1000 kg (heavy-chain-40-1000): PGS opens the
// joints by 37 m; auto sends it to the direct solve with geometric
// stiffness and the position pass (mass_ratio), which hold every joint
// under 1 mm for the 10 s (tests/unit/heavy_chain_test.cpp: the pass
// takes the error to nanometres, so 1 mm is loose by orders of magnitude).
TEST(AutoMethod, FortyLinkChainHoldsAThousandToOneWeightUnderOneMillimetre) {
  const SceneDesc s = scenarios::heavyHangingChain(40, 1000);
  const AutoRun r = runAuto(s, 600);
  EXPECT_EQ(reasonSteps(r, MethodReason::MassRatio), allSteps(r));
  EXPECT_EQ(methodSteps(r, SolverMethod::Direct), allSteps(r));
  EXPECT_LT(r.worst_joint, 1e-3);
}

// chain-20 released horizontally whips: on PGS its joints open steadily
// (3.2 m over 10 s). Auto sees an error above 1 cm that does not fall for
// 5 steps, sends the island to the direct solve and keeps it there; the
// joints then stay within the extremes' 5 cm limit for swinging chains
// (5% of a 1 m link), where PGS alone is past it within 40 steps.
TEST(AutoMethod, WhippingChainLeavesPgsForJointDriftAndHolds) {
  SceneDesc s = scenarios::chain(20);
  const AutoRun r = runAuto(s, s.steps);
  EXPECT_GT(reasonSteps(r, MethodReason::JointDrift), allSteps(r) * 9 / 10);
  EXPECT_LT(r.worst_joint, 0.05);
  s.solver.method = SolverMethod::PGS;
  EXPECT_GT(runAuto(s, 60).worst_joint, 0.05);
}

// More joints than 4 x the sweeps (chain-100: 100 joints, 40 at 10 sweeps)
// is long_chain from the first step.
TEST(AutoMethod, HundredLinkChainIsALongChainFromTheFirstStep) {
  const SceneDesc s = scenarios::chain(100);
  const AutoRun r = runAuto(s, 5);
  EXPECT_EQ(reasonSteps(r, MethodReason::LongChain), 5);
  EXPECT_EQ(methodSteps(r, SolverMethod::Direct), 5);
}

}  // namespace
}  // namespace cairn
