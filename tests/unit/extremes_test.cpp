// The fast cases of the extremes suite (docs/extremes.md): a sphere at
// 1 km/s and a 10 cm wall, ERP and CFM at their ends, scenes 1e5 m from the
// origin. The long ones are in tests/long/extremes_test.cpp, with the
// criteria for "holds".
#include "validation/extremes.hpp"
#include "world/world_access.hpp"

#include <gtest/gtest.h>

namespace cairn::validation {
namespace {

// With ccd the sphere's speculative contact reaches as far as it moves in a
// step (16.7 m at 1000 m/s), so it stops at the wall's face: its leading
// point never gets deeper than the slop (5 mm).
TEST(ExtremesCcd, FastSphereDoesNotPassThroughThinWall) {
  const ExtremeCase c = extremeCase("ccd-sphere-1km/s");
  const ExtremeResult r = runCairn(c, c.scene.solver);
  EXPECT_TRUE(r.finite);
  EXPECT_EQ(r.numerical_events, 0);
  EXPECT_LE(r.drift, c.scene.solver.slop);
  EXPECT_TRUE(r.bounded);  // restitution 0: it stops, it does not gain energy
}

// Without ccd the same sphere jumps the wall in one step (16.7 m per step
// against 0.1 + 0.2 m of wall and sphere): the case ccd exists for.
TEST(ExtremesCcd, WithoutCcdTheSphereTunnels) {
  const ExtremeCase c = extremeCase("sphere-1km/s-no-ccd");
  EXPECT_GT(runCairn(c, c.scene.solver).drift, 100);
}

// A 1 m x 1 cm rod tumbling at 1000 rad/s (inertia ratio 5000). With 20
// substeps (h |w| = 0.83 rad) the implicit-midpoint step solves its equation
// and keeps the world angular momentum to round-off (relative drift under
// 1e-9 over the 600 steps; measured 2.4e-12). At one substep (h |w| = 16.7
// rad) Newton's method cannot solve it: the World says so in its
// diagnostics, for the rod, instead of passing an inaccurate step on
// silently, and the case is not counted as held.
TEST(ExtremesGyroscopic, SpinningRodHoldsWithSubstepsAndIsDiagnosedWithout) {
  const ExtremeCase c = extremeCase("rod-spin-1000");
  SolverSettings fine = c.scene.solver;
  fine.substeps = 20;
  const ExtremeResult held = runCairn(c, fine);
  EXPECT_TRUE(held.finite && held.bounded);
  EXPECT_EQ(held.diagnostics, 0);
  EXPECT_LT(held.drift, 1e-9);

  const ExtremeResult coarse = runCairn(c, c.scene.solver);
  EXPECT_TRUE(coarse.finite);
  EXPECT_GT(coarse.diagnostics, 0);
  SceneDesc s = c.scene;
  World w = buildWorld(s);
  w.step(s.dt);
  ASSERT_EQ(w.diagnostics().size(), 1u);
  EXPECT_EQ(w.diagnostics()[0].body_name, "rod");
  EXPECT_EQ(w.diagnostics()[0].kind, "gyroscopic solve");
}

// ERP 0 and 1, CFM 1e-12: the joints and contacts stay finite, bounded and
// within the cases' limits (hanging chain 1 cm, column 5 cm).
TEST(ExtremesSoftness, ErpAndCfmAtTheirEndsHold) {
  for (const char* s : {"erp-0", "erp-1", "cfm-1e-12"}) {
    for (const std::string& name : {std::string("hanging-chain-20-") + s, std::string("column-10-") + s}) {
      const ExtremeCase c = extremeCase(name);
      const ExtremeResult r = runCairn(c, c.scene.solver);
      EXPECT_TRUE(r.finite && r.numerical_events == 0) << name;
      EXPECT_TRUE(r.bounded) << name << " " << r.energy_excess;
      EXPECT_LT(r.drift, c.drift_limit) << name;
    }
  }
}


// CFM 1 (ODE units, m/(N s)) is a spring of ERP/(h CFM) = 12 N/m on every
// row: the user asked for jelly. It must stay finite and gain no energy.
TEST(ExtremesSoftness, CfmOneIsSoftButFiniteAndBounded) {
  for (const char* name : {"hanging-chain-20-cfm-1", "column-10-cfm-1"}) {
    const ExtremeCase c = extremeCase(name);
    const ExtremeResult r = runCairn(c, c.scene.solver);
    EXPECT_TRUE(r.finite && r.numerical_events == 0) << name;
    EXPECT_TRUE(r.bounded) << name;
  }
}

// 1e5 m from the origin a double keeps 1.5e-11 m resolution: the scene
// behaves as at the origin. The drift figures agree to 1e-6 m (a million
// times the resolution, far below the 5 mm slop).
TEST(ExtremesFarFromOrigin, ColumnAndChainBehaveAsAtTheOrigin) {
  for (const auto& [far, near] : {std::pair{"far-column-10", "column-10-dt-1/60"},
                                  std::pair{"far-hanging-chain-20", "hanging-chain-20-dt-1/60"}}) {
    ExtremeCase f = extremeCase(far), n = extremeCase(near);
    f.scene.steps = n.scene.steps = 180;
    const ExtremeResult rf = runCairn(f, f.scene.solver), rn = runCairn(n, n.scene.solver);
    EXPECT_TRUE(rf.finite && rf.numerical_events == 0 && rf.bounded) << far;
    EXPECT_NEAR(rf.drift, rn.drift, 1e-6) << far;
  }
}

}  // namespace
}  // namespace cairn::validation
