// What the step keeps for bodies it does not read: after the islands stage
// it skips a sleeping body (StepContext::moves), so what such a body
// contributes to the step's statistics comes from the state saved at the
// step's start, and the force accumulators it could hold are cleared
// without walking every body (world/world_step.cpp, clearForces).
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace cairn {
namespace {

// A box resting on the ground (asleep after sleep_time) and one falling
// from 20 m far from it (awake): the step's energy statistic must be the
// kinetic plus potential energy of all bodies, the sleeping one included,
// and its count of sleeping bodies the number World::isAsleep reports.
// The statistic sums the same terms as kineticEnergy() + potentialEnergy()
// in another order, so they agree to round-off of the sum (|E| ~ 200 J,
// 1e-12 J).
TEST(SleepBookkeeping, EnergyAndSleeperCountIncludeBodiesTheStepDoesNotRead) {
  World w(Vec3(0, -9.81, 0));
  w.createBody(scenarios::ground());
  const BodyId resting = w.createBody(test::boxDef("resting", Vec3(0, 0.5, 0)));
  bool seen_mixed = false;
  BodyId falling;
  for (int k = 0; k < 120; ++k) {
    if (k == 60) falling = w.createBody(test::boxDef("falling", Vec3(10, 20, 0)));
    w.step(Real(1) / 60);
    const StepStats& s = w.lastStepStats();
    EXPECT_NEAR(s.energy, w.kineticEnergy() + w.potentialEnergy(), 1e-12 * (1 + std::abs(s.energy))) << "step " << k;
    int asleep = w.isAsleep(resting) ? 1 : 0;
    if (k >= 60 && w.isAsleep(falling)) ++asleep;
    EXPECT_EQ(s.sleeping_bodies, asleep) << "step " << k;
    seen_mixed = seen_mixed || (k >= 60 && w.isAsleep(resting) && !w.isAsleep(falling));
  }
  EXPECT_TRUE(seen_mixed);  // the case in question happened: one asleep, one awake
}

// A box on the ground pulled sideways by a spring of 1 N, less than the
// 4.9 N static friction can hold (mu m g = 0.5 * 1 * 9.81): it comes to
// rest and sleeps while the spring still pulls. The spring's force reaches
// the sleeping box every step and must be spent every step: were it kept,
// 300 steps of it (300 N) would throw the box at 5 m/s in the first step
// after it wakes. Woken, friction must hold it as before (below 1 mm/s).
TEST(SleepBookkeeping, SpringForceOnASleepingBodyDoesNotPileUp) {
  World w(Vec3(0, -9.81, 0));
  w.createBody(scenarios::ground());
  const BodyId box = w.createBody(test::boxDef("box", Vec3(0, 0.5, 0)));
  SpringDef spring;
  spring.body_b = box;
  spring.anchor_a = Vec3(-3, 0.5, 0);
  spring.anchor_b = Vec3(0, 0.5, 0);
  spring.rest_length = Real(2);  // 1 m stretched
  spring.stiffness = 1;          // N/m: 1 N toward the anchor
  w.createSpring(spring);
  for (int k = 0; k < 120; ++k) w.step(Real(1) / 60);
  ASSERT_TRUE(w.isAsleep(box));
  for (int k = 0; k < 300; ++k) w.step(Real(1) / 60);
  ASSERT_TRUE(w.isAsleep(box));
  w.setLinearVelocity(box, Vec3::Zero());  // wakes it
  w.step(Real(1) / 60);
  EXPECT_LT(w.linearVelocity(box).norm(), 1e-3);
}

// A force applied through the API to a body that never moves (the static
// ground) acts on nothing and must not outlive the step it was meant for.
TEST(SleepBookkeeping, ForceAppliedToAStaticBodyIsClearedAfterTheStep) {
  World w(Vec3(0, -9.81, 0));
  const BodyId ground = w.createBody(scenarios::ground());
  w.applyCentralForce(ground, Vec3(5, 0, 0));
  w.applyTorque(ground, Vec3(0, 2, 0));
  w.step(Real(1) / 60);
  const auto& in = cairn::detail::internals(w);
  EXPECT_EQ(in.body(ground).force, Vec3::Zero());
  EXPECT_EQ(in.body(ground).torque, Vec3::Zero());
}

// A world all asleep: the step skips its walks over the contacts (nothing
// wakes, no island forms, no depth changes), yet reports what is there.
// Nothing moves, so each later step's contact count, point count and
// deepest penetration are those of the step the stack fell asleep in, to
// the bit.
TEST(SleepBookkeeping, AWorldAllAsleepReportsTheContactsAndDepthOfTheStepItFellAsleepIn) {
  World w(Vec3(0, -9.81, 0));
  w.createBody(scenarios::ground());
  w.createBody(test::boxDef("bottom", Vec3(0, 0.5, 0)));
  w.createBody(test::boxDef("top", Vec3(0.1, 1.5, 0)));
  for (int k = 0; k < 600 && w.lastStepStats().sleeping_bodies < 2; ++k) w.step(Real(1) / 60);
  const StepStats fell = w.lastStepStats();
  ASSERT_EQ(fell.sleeping_bodies, 2);
  ASSERT_EQ(fell.contacts, 2);  // ground-bottom, bottom-top
  ASSERT_GT(fell.max_penetration, 0);
  for (int k = 0; k < 30; ++k) {
    w.step(Real(1) / 60);
    const StepStats& s = w.lastStepStats();
    EXPECT_EQ(s.islands, 0);
    EXPECT_EQ(s.contacts, fell.contacts);
    EXPECT_EQ(s.contact_points, fell.contact_points);
    EXPECT_EQ(s.max_penetration, fell.max_penetration);
  }
}

// A kinematic body moving into a sleeping box wakes it (the one thing that
// moves in an otherwise sleeping world), and pushes it: the box, 1 m
// wide, ends more than 10 cm from where it slept.
TEST(SleepBookkeeping, AMovingKinematicBodyWakesTheSleepingBoxItReaches) {
  World w(Vec3(0, -9.81, 0));
  w.createBody(scenarios::ground());
  const BodyId box = w.createBody(test::boxDef("box", Vec3(0, 0.5, 0)));
  for (int k = 0; k < 120; ++k) w.step(Real(1) / 60);
  ASSERT_TRUE(w.isAsleep(box));
  const Vec3 slept = cairn::detail::internals(w).body(box).position;
  BodyDef pusher = test::boxDef("pusher", Vec3(-2, 0.5, 0));
  pusher.type = BodyType::Kinematic;
  pusher.linear_velocity = Vec3(1, 0, 0);  // reaches the box after about 1 s
  w.createBody(pusher);
  bool woke = false;
  for (int k = 0; k < 120; ++k) {
    w.step(Real(1) / 60);
    woke = woke || !w.isAsleep(box);
  }
  EXPECT_TRUE(woke);
  EXPECT_GT((cairn::detail::internals(w).body(box).position - slept).norm(), 0.1);
}

}  // namespace
}  // namespace cairn
