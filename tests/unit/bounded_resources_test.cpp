// What one step may allocate is bounded whatever the scene
// (docs/reliability.md, "Bounded resources"): a body's own shapes never
// pair, the pairs of coincident bodies grow linearly with their number, and
// an exact-LCP island too large to solve quickly goes to PGS with a
// diagnostic instead of a dense system of its size squared.
#include "collision/broadphase.hpp"
#include "test_helpers.hpp"
#include "validation/scenarios.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

namespace cairn {
namespace {

using detail::internals;

int diagnosticsOfKind(const World& w, const std::string& kind) {
  int n = 0;
  for (const Diagnostic& d : w.diagnostics()) n += d.kind == kind ? 1 : 0;
  return n;
}

// One body with 2,000 coincident spheres, floating: its shapes overlap each
// other 1,999,000 times and none of those overlaps may reach the pair list.
// (10,000 such shapes once took 1.19 GB in pairs that were filtered later.)
TEST(BoundedResources, ABodysOwnShapesNeverEnterThePairList) {
  World w(Vec3::Zero());
  BodyDef d;
  d.name = "clump";
  d.mass = 1;
  for (int i = 0; i < 2000; ++i) d.shapes.push_back(ShapeDesc::sphere(0.1));
  const BodyId id = w.createBody(d);
  w.setLinearVelocity(id, Vec3(1, 0, 0));  // moving: every proxy is re-queried
  for (int s = 0; s < 3; ++s) w.step(Real(1) / 60);
  EXPECT_EQ(internals(w).pairs_.size(), 0u);
  EXPECT_EQ(w.lastStepStats().contacts, 0);
  EXPECT_EQ(diagnosticsOfKind(w, "contact pairs capped"), 0);  // same-body overlaps do not count toward the cap
}

// N boxes at one spot: N (N - 1) / 2 pairs without a bound. With the bound
// each shape's query keeps at most max_pairs_per_shape others, so the pair
// list holds at most N * max; with the bound at N or more, every pair is
// there (the bound, not something else, is what limits it).
TEST(BoundedResources, CoincidentBodiesMakeLinearlyManyPairs) {
  const int n = 120;
  const auto run = [&](int max_pairs) {
    SolverSettings s;
    s.max_pairs_per_shape = max_pairs;
    World w(WorldDef{Vec3(0, -9.81, 0), s});
    for (int i = 0; i < n; ++i) w.createBody(test::boxDef("b" + std::to_string(i), Vec3(0, 5, 0)));
    w.step(Real(1) / 60);
    return std::pair{internals(w).pairs_.size(), diagnosticsOfKind(w, "contact pairs capped")};
  };
  const auto [capped, capped_diags] = run(8);
  EXPECT_LE(capped, size_t(n) * 8);
  EXPECT_GT(capped, 0u);
  EXPECT_GT(capped_diags, 0);
  const auto [all, all_diags] = run(n);
  EXPECT_EQ(all, size_t(n) * (n - 1) / 2);
  EXPECT_EQ(all_diags, 0);
}

// A ground box under 900 boxes: its own query is cut short at 64, but each
// box's query finds it, so every box rests on it: one manifold per box, and
// all 900 asleep once still (each box its own island). Keeping a pair from
// one side's query only once left 836 boxes without their ground.
TEST(BoundedResources, AGroundBoxUnderManyBodiesPairsWithEveryOne) {
  World w;
  w.createBody(scenarios::ground());
  for (int i = 0; i < 30; ++i)
    for (int k = 0; k < 30; ++k)
      w.createBody(test::boxDef("b" + std::to_string(i) + "_" + std::to_string(k), Vec3(1.5 * i, 0.5, 1.5 * k)));
  for (int s = 0; s < 60; ++s) w.step(Real(1) / 60);
  EXPECT_EQ(w.lastStepStats().contacts, 900);
  EXPECT_EQ(w.lastStepStats().sleeping_bodies, 900);
  EXPECT_EQ(diagnosticsOfKind(w, "contact pairs capped"), 0);
}

// The bound holds across incremental updates (pairs are kept between
// updates and re-found only for proxies that moved): random boxes moving in
// a small region, at most N * max pairs after every update, each pair a
// real overlap of fat boxes, never one of two proxies of the same owner.
TEST(BoundedResources, BroadphasePairBoundHoldsAcrossUpdates) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> c(-1, 1);
  BroadPhase bp(0.05);
  bp.setMaxPairsPerProxy(5);
  const int n = 200;
  std::vector<int> handles;
  for (int i = 0; i < n; ++i)
    handles.push_back(bp.createProxy(Aabb::fromCenterHalf(Vec3(c(rng), c(rng), c(rng)), Vec3::Constant(0.4)), i,
                                     Vec3::Zero(), i / 4));  // four proxies per owner
  std::vector<std::pair<int, int>> pairs;
  for (int round = 0; round < 50; ++round) {
    for (int k = 0; k < 20; ++k) {
      const int h = handles[std::uniform_int_distribution<int>(0, n - 1)(rng)];
      bp.moveProxy(h, Aabb::fromCenterHalf(Vec3(c(rng), c(rng), c(rng)), Vec3::Constant(0.4)));
    }
    bp.updatePairs(pairs);
    ASSERT_LE(pairs.size(), size_t(n) * 5) << "round " << round;
    for (const auto& [a, b] : pairs) {
      ASSERT_TRUE(bp.fatAabb(a).overlaps(bp.fatAabb(b)));
      ASSERT_NE(bp.user(a) / 4, bp.user(b) / 4) << "proxies of one owner paired";
    }
  }
}

// pyramid-10 with method lcp: one island of about 1,300 rows, which took
// 30 s a step as one dense exact solve. Over max_exact_rows it is solved by
// PGS and reported; a three-box pyramid (about 50 rows) is solved exactly,
// and its generic rows are there to show it.
TEST(BoundedResources, ExactIslandOverTheLimitGoesToPgsWithADiagnostic) {
  SceneDesc big = scenarios::pyramid(10);
  big.solver.method = SolverMethod::LCP;
  World wb = buildWorld(big);
  wb.step(big.dt);
  EXPECT_EQ(diagnosticsOfKind(wb, "exact solve too large"), 1);
  EXPECT_TRUE(internals(wb).rows().empty());  // no dense rows were built

  SceneDesc small = scenarios::pyramid(2);
  small.solver.method = SolverMethod::LCP;
  World ws = buildWorld(small);
  for (int s = 0; s < 10; ++s) ws.step(small.dt);
  EXPECT_EQ(diagnosticsOfKind(ws, "exact solve too large"), 0);
  EXPECT_FALSE(internals(ws).rows().empty());
}

TEST(BoundedResources, LimitsAreCheckedWhenSet) {
  World w;
  SolverSettings s;
  s.max_pairs_per_shape = 0;
  EXPECT_THROW(w.setSettings(s), InputError);
  s = {};
  s.max_exact_rows = -1;
  EXPECT_THROW(w.setSettings(s), InputError);
  s = {};
  s.energy_rise = 0;
  EXPECT_THROW(w.setSettings(s), InputError);
}

}  // namespace
}  // namespace cairn
