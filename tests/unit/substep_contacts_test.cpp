// Contacts over substeps (SolverSettings::prepare_contacts_each_substep,
// docs/performance.md "Earlier: contacts over substeps"). Collision runs once
// per step, so the constraint graph's layout is made once per step; with
// the option off, each manifold is also prepared once, and later substeps
// only measure each point's separation again at the bodies' new poses, as
// Box2D v3 does.
#include "test_helpers.hpp"
#include "world/world_access.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace cairn {
namespace {

// Two columns of `n` unit boxes over a static plane, each box dropped from
// 2 cm above the one below; the second column's lowest box starts sliding
// sideways at 1.1 m/s (the boxes above it keep still until they land).
// Frictionless, or with friction 0.5.
World columns(int n, int substeps, bool prepare_each, Real friction, bool lock_rotation) {
  World w(Vec3(0, -9.81, 0));
  SolverSettings s;
  s.sleeping = false;
  s.substeps = substeps;
  s.prepare_contacts_each_substep = prepare_each;
  w.setSettings(s);
  BodyDef g;
  g.name = "ground";
  g.type = BodyType::Static;
  g.friction = friction;
  g.shapes.push_back(ShapeDesc::plane(Vec3::UnitY(), 0));
  w.createBody(g);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 2; ++c) {
      BodyDef b = test::boxDef("box" + std::to_string(c) + "_" + std::to_string(i), Vec3(2.0 * c, 0.52 + 1.02 * i, 0));
      b.friction = friction;
      if (c == 1 && i == 0) b.linear_velocity = Vec3(1, 0, 0.5);
      if (lock_rotation) b.lock_rotation = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
      w.createBody(b);
    }
  return w;
}

std::vector<Transform> run(World& w, int steps) {
  std::vector<Transform> out;
  for (int k = 0; k < steps; ++k) {
    w.step(Real(1) / 60);
    for (const Body& b : detail::internals(w).bodies_) out.push_back(Transform{b.position, b.orientation});
  }
  return out;
}

bool same(const std::vector<Transform>& a, const std::vector<Transform>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].p != b[i].p || a[i].q.coeffs() != b[i].q.coeffs()) return false;
  return true;
}

// Without rotation and friction nothing a refresh keeps can go stale: the
// anchors (R r_local), the masses and the normal block are what a fresh
// preparation would compute, the separations are measured the same way,
// and the carried impulses are those the contacts would hand back. So the
// two ways give the same bits; a refresh that measured a separation at the
// wrong pose, or warm-started twice, would not.
TEST(SubstepContacts, RefreshGivesThePreparedBitsWhenNothingTurnsOrRubs) {
  World a = columns(5, 4, true, 0, true);
  World b = columns(5, 4, false, 0, true);
  const auto ta = run(a, 120), tb = run(b, 120);
  EXPECT_TRUE(same(ta, tb));
  // The columns have landed and rest on the ground: the refresh did work.
  EXPECT_GT(detail::internals(b).contacts_.size(), 5u);
}

// The refreshed lanes carry their impulses from substep to substep and
// hand them to the contact cache only after the last one. A joint that
// breaks within a step makes the next substep lay the graph out again and
// prepare every lane anew from the cache, so the cache must catch up
// first. Three 1 kg pendulums, released level and far from the columns,
// break at 0.3, 0.5 and 0.7 times their weight (a released pendulum's
// joint force grows from zero as it swings down), in the steps where the
// columns land on one another, at substeps within a step. The two ways
// must still give the same bits. Without the catch-up a re-prepared lane
// warm-starts from the step's first impulses and the bits differ (they
// did; with the breaks later, at 1.25 to 1.75 times the weight, the
// columns had come to rest, each substep's impulses were the same, and the
// missing catch-up went unseen).
TEST(SubstepContacts, RefreshHandsItsImpulsesOnWhenAJointBreaksWithinAStep) {
  const auto withPendulums = [](World w) {
    for (int k = 0; k < 3; ++k) {
      const Vec3 anchor(20 + 3 * k, 10, 0);  // 9 m over the ground: no landing within the run
      const BodyId bob = w.createBody(test::sphereDef("bob" + std::to_string(k), anchor - Vec3(1, 0, 0), 1, 0.1));
      JointDef j = scenarios::joint("hook" + std::to_string(k), JointType::Ball, kWorldBody, bob, anchor);
      j.break_force = (0.3 + 0.2 * k) * 9.81;
      w.createJoint(j);
    }
    return w;
  };
  World a = withPendulums(columns(5, 4, true, 0, true));
  World b = withPendulums(columns(5, 4, false, 0, true));
  std::vector<Transform> ta, tb;
  int breaks = 0;
  for (int k = 0; k < 60; ++k) {
    const auto sa = run(a, 1), sb = run(b, 1);
    ta.insert(ta.end(), sa.begin(), sa.end());
    tb.insert(tb.end(), sb.begin(), sb.end());
    if (!b.jointBreakEvents().empty()) {
      // The columns touch: the break remakes lanes that carry impulses.
      EXPECT_GT(detail::internals(b).contacts_.size(), 5u) << "step " << k;
      breaks += static_cast<int>(b.jointBreakEvents().size());
    }
  }
  EXPECT_EQ(breaks, 3);
  EXPECT_TRUE(same(ta, tb));
}

// With rotation and friction the refresh keeps anchors and tangents a
// substep old, so the bits differ; the stacks must still come to rest
// where preparing each substep leaves them. The sliding box stops under
// friction (1.1 m/s at mu g: 0.13 m, in 0.23 s) with the column on it
// landing on its top; after 3 s every box is within 5 mm of the prepared
// run's (the slop, the penetration either run may settle at) and below
// 1 cm/s (gravity alone adds 16 cm/s a step).
TEST(SubstepContacts, RefreshHoldsAStackAsPreparingEachSubstepDoes) {
  World a = columns(8, 4, true, 0.5, false);
  World b = columns(8, 4, false, 0.5, false);
  const auto ta = run(a, 180), tb = run(b, 180);
  EXPECT_FALSE(same(ta, tb));
  const auto& ba = detail::internals(a).bodies_;
  const auto& bb = detail::internals(b).bodies_;
  ASSERT_EQ(ba.size(), bb.size());
  for (size_t i = 1; i < ba.size(); ++i) {
    EXPECT_LT((ba[i].position - bb[i].position).norm(), 5e-3) << "body " << i << " prepared " << ba[i].position.transpose() << " refreshed " << bb[i].position.transpose() << " v " << ba[i].linear_velocity.norm();
    EXPECT_LT(bb[i].linear_velocity.norm(), 1e-2) << "body " << i;
  }
}

}  // namespace
}  // namespace cairn
