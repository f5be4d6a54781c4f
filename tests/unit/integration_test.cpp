// Semi-implicit Euler against its exact discrete solution.
#include "test_helpers.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

// Semi-implicit Euler under constant gravity has the exact discrete
// solution v_n = v0 + n h g, x_n = x0 + n h v0 + h^2 g n (n + 1) / 2.
// Only round-off separates the engine from it: 600 additions of ~1e-1 m
// accumulate well under 1e-9 m.
TEST(Projectile, MatchesExactDiscreteSemiImplicitEuler) {
  World w;
  BodyDef d = test::sphereDef("ball", Vec3(0, 10, 0));
  d.linear_velocity = Vec3(3, 4, -1);
  const BodyId id = w.createBody(d);
  const Real h = Real(1) / 60;
  const Vec3 g = w.gravity();
  for (int n = 1; n <= 600; ++n) {
    w.step(h);
    const Vec3 v = d.linear_velocity + n * h * g;
    const Vec3 x = d.position + n * h * d.linear_velocity + h * h * g * (n * (n + 1) / 2.0);
    ASSERT_LT((cairn::detail::internals(w).body(id).linear_velocity - v).norm(), 1e-10) << "step " << n;
    ASSERT_LT((cairn::detail::internals(w).body(id).position - x).norm(), 1e-9) << "step " << n;
  }
}

}  // namespace
}  // namespace cairn
