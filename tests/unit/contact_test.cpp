// Contacts against closed forms and conservation laws (section 12.4).
#include "test_helpers.hpp"
#include "validation/scenarios.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <set>
#include <tuple>

namespace cairn {
namespace {

constexpr Real kH = Real(1) / 60;

BodyId addGroundPlane(World& w, const Vec3& n = Vec3::UnitY(), Real friction = 0.5) {
  BodyDef g;
  g.name = "ground";
  g.type = BodyType::Static;
  g.friction = friction;
  g.shapes.push_back(ShapeDesc::plane(n.normalized(), 0));
  return w.createBody(g);
}

SolverSettings noSleep(int iterations = 10) {
  SolverSettings s;
  s.sleeping = false;
  s.iterations = iterations;
  return s;
}

// Section 12.4.2's SuperBall, in 3D: a 50 g sphere moving at (-4, -4, 0) m/s
// hits a static frictionless plane with normal (1, 3, 0)/sqrt(10). Newton's
// law with e = 0.9 gives (-0.96, 5.12, 0) m/s; e = 0.01 gives the beanbag's
// (-2.384, 0.848, 0). No gravity, so the impulse is the only change: 1%.
TEST(Restitution, SuperBallAndBeanbagLeaveAtTheTextbookVelocities) {
  for (const auto& [e, vx, vy] : {std::tuple{0.9, -0.96, 5.12}, std::tuple{0.01, -2.384, 0.848}}) {
    World w(Vec3::Zero());
    const Vec3 n = Vec3(1, 3, 0).normalized();
    addGroundPlane(w, n, 0);
    BodyDef b = test::sphereDef("ball", n * 0.2, 0.05, 0.1);  // 10 cm above the plane
    b.linear_velocity = Vec3(-4, -4, 0);
    b.friction = 0;
    b.restitution = e;
    const BodyId id = w.createBody(b);
    for (int s = 0; s < 30; ++s) w.step(kH);
    const Vec3 v = cairn::detail::internals(w).body(id).linear_velocity;
    EXPECT_NEAR(v.x(), vx, 0.01 * std::abs(vy)) << "e = " << e;
    EXPECT_NEAR(v.y(), vy, 0.01 * std::abs(vy)) << "e = " << e;
    EXPECT_NEAR(v.z(), 0, 1e-9);
  }
}

// Dropped on the ground, successive bounce apexes fall by e^2 (section
// 12.4.2: the rebound speed is e times the impact speed, and height goes as
// speed squared). At h = 1/600 the contact resolves within ~1 mm of the
// surface, so the ratio holds within 3%.
TEST(Restitution, BounceApexHeightsFallByESquared) {
  World w;
  w.setSettings(noSleep());
  addGroundPlane(w);
  const Real e = 0.8;
  BodyDef b = test::sphereDef("ball", Vec3(0, 2.1, 0), 1, 0.1);
  b.restitution = e;
  const BodyId id = w.createBody(b);
  std::vector<Real> apex;
  Real prev_v = 0;
  for (int s = 0; s < 600 * 5; ++s) {
    w.step(Real(1) / 600);
    const Real v = cairn::detail::internals(w).body(id).linear_velocity.y();
    if (prev_v > 0 && v <= 0) apex.push_back(cairn::detail::internals(w).body(id).position.y() - 0.1);
    prev_v = v;
  }
  ASSERT_GE(apex.size(), 3u);
  for (size_t i = 1; i < 3; ++i) EXPECT_NEAR(apex[i] / apex[i - 1], e * e, 0.03 * e * e) << i;
}

// A unit box on a static ramp tilted by `deg` degrees, mu = 0.5 on both.
World ramp(Real deg, BodyId& box) {
  World w;
  w.setSettings(noSleep());
  const Quat tilt(Eigen::AngleAxis<Real>(deg * kPi / 180, Vec3::UnitZ()));
  BodyDef r;
  r.name = "ramp";
  r.type = BodyType::Static;
  r.orientation = tilt;
  r.position = tilt * Vec3(0, -0.5, 0);
  r.shapes.push_back(ShapeDesc::box(Vec3(20, 0.5, 5)));
  w.createBody(r);
  BodyDef b = test::boxDef("box", tilt * Vec3(0, 0.5, 0));
  b.orientation = tilt;
  box = w.createBody(b);
  return w;
}

// Coulomb (section 12.2.2): tan 20 deg = 0.36 < mu = 0.5, so the box sticks
// (under 1 mm of creep in 5 s); tan 35 deg = 0.70 > 0.5, so it slides with
// a = g (sin 35 - 0.5 cos 35) = 1.609 m/s^2, within 3%.
TEST(Friction, BoxOnRampSticksAtTwentyAndSlidesAtThirtyFiveDegrees) {
  BodyId id;
  World stick = ramp(20, id);
  const Vec3 p0 = cairn::detail::internals(stick).body(id).position;
  for (int s = 0; s < 300; ++s) stick.step(kH);
  EXPECT_LT((cairn::detail::internals(stick).body(id).position - p0).norm(), 1e-3);

  World slide = ramp(35, id);
  const Vec3 down = Quat(Eigen::AngleAxis<Real>(35 * kPi / 180, Vec3::UnitZ())) * Vec3(-1, 0, 0);
  for (int s = 0; s < 30; ++s) slide.step(kH);  // settle into sliding
  const Real v0 = cairn::detail::internals(slide).body(id).linear_velocity.dot(down);
  for (int s = 0; s < 60; ++s) slide.step(kH);
  const Real a = (cairn::detail::internals(slide).body(id).linear_velocity.dot(down) - v0) / 1.0;
  const Real expected = 9.81 * (std::sin(35 * kPi / 180) - 0.5 * std::cos(35 * kPi / 180));
  EXPECT_NEAR(a, expected, 0.03 * expected);
}

Real maxDisplacement(World& w, int steps, Real h, std::vector<Vec3>* start = nullptr) {
  std::vector<Vec3> p0;
  for (const Body& b : cairn::detail::internals(w).bodies()) p0.push_back(b.position);
  Real worst = 0;
  for (int s = 0; s < steps; ++s) {
    w.step(h);
    for (size_t i = 0; i < p0.size(); ++i) worst = std::max(worst, (cairn::detail::internals(w).bodies()[i].position - p0[i]).norm());
  }
  if (start) *start = p0;
  return worst;
}

// docs/scenarios.md column-10 at the default 10 iterations and one substep
// stands for 10 s with the top box moving under 1 cm (the requirement cairn set itself):
// sideways under 1 mm (manifold blocks remove the per-point ordering bias
// that makes columns rock; solver/pgs.hpp) and vertically 3 mm (NNCG's
// momentum carries the boxes' weight down the column from the cold start;
// plain PGS lets it settle 1.6 cm in its first 5 steps: docs/contacts.md).
TEST(Stacking, ColumnOfTenStandsTenSecondsAtTenIterations) {
  SceneDesc s = scenarios::column(10);
  s.solver.sleeping = false;
  ASSERT_EQ(s.solver.iterations, 10);
  ASSERT_EQ(s.solver.substeps, 1);
  World w = buildWorld(s);
  const Vec3 top0 = cairn::detail::internals(w).bodies().back().position;
  Real lateral = 0, total = 0;
  for (int k = 0; k < 600; ++k) {
    w.step(s.dt);
    const Vec3 d = cairn::detail::internals(w).bodies().back().position - top0;
    lateral = std::max(lateral, Vec3(d.x(), 0, d.z()).norm());
    total = std::max(total, d.norm());
  }
  EXPECT_LT(lateral, 1e-3);
  EXPECT_LT(total, 0.01);
}

// docs/scenarios.md pyramid-20 (210 boxes) for 10 s at 20 iterations and one
// substep: every box within 2 cm of its start (measured 0.95 cm; plain PGS
// reaches 2.02 cm in the cold-start settling, docs/contacts.md).
TEST(Stacking, PyramidOfTwentyStandsTenSecondsAtTwentyIterations) {
  SceneDesc s = scenarios::pyramid(20);
  s.solver.sleeping = false;
  s.solver.iterations = 20;
  ASSERT_EQ(s.solver.substeps, 1);
  World w = buildWorld(s);
  EXPECT_LT(maxDisplacement(w, 600, s.dt), 0.02);
}

// A 1 kg box under a 100 kg box holds at the default 10 iterations: the
// penetration stays under 1 cm through the landing and at rest (the slop is
// 5 mm; split impulse pushes out the rest), and the heavy box rests where
// it should. Plain PGS sinks 4 cm on landing (it removes about 1% of the
// heavy box's velocity per sweep at a 1:100 ratio); NNCG's momentum does not.
TEST(Stacking, LightBoxUnderHeavyBoxHoldsWithUnderOneCentimetrePenetration) {
  SceneDesc s = scenarios::massRatio(100);
  s.solver.sleeping = false;
  ASSERT_EQ(s.solver.iterations, 10);
  World w = buildWorld(s);
  Real worst = 0;
  for (int k = 0; k < 600; ++k) {
    w.step(s.dt);
    worst = std::max(worst, w.lastStepStats().max_penetration);
  }
  EXPECT_LT(worst, 0.01);
  EXPECT_NEAR(cairn::detail::internals(w).bodies()[2].position.y(), 1.5, 0.01);  // the heavy box rests where it should
}

// Two frictionless spheres collide head-on-ish in zero gravity: linear
// momentum is conserved to round-off whatever the restitution.
TEST(Collision, FrictionlessTwoBodyCollisionConservesMomentum) {
  World w(Vec3::Zero());
  BodyDef a = test::sphereDef("a", Vec3(0, 0, 0), 2, 0.5);
  a.linear_velocity = Vec3(3, 0.5, 0);
  a.friction = 0;
  a.restitution = 0.5;
  BodyDef b = test::sphereDef("b", Vec3(3, 0.3, 0), 5, 0.5);
  b.linear_velocity = Vec3(-1, 0, 0.2);
  b.friction = 0;
  const BodyId ia = w.createBody(a), ib = w.createBody(b);
  const Vec3 p0 = w.linearMomentum();
  bool touched = false;
  for (int s = 0; s < 120; ++s) {
    w.step(kH);
    touched = touched || !w.contactEvents().empty();
    EXPECT_LT((w.linearMomentum() - p0).norm(), 1e-12);
  }
  EXPECT_TRUE(touched);
  EXPECT_GT((cairn::detail::internals(w).body(ib).linear_velocity - b.linear_velocity).norm(), 0.5);  // they did interact
  (void)ia;
}

// A box at rest falls asleep; a ball thrown at it wakes it.
TEST(Sleeping, RestingBodySleepsAndWakesWhenHit) {
  World w;
  addGroundPlane(w);
  const BodyId box = w.createBody(test::boxDef("box", Vec3(0, 0.5, 0)));
  for (int s = 0; s < 120; ++s) w.step(kH);
  ASSERT_TRUE(w.isAsleep(box));
  EXPECT_EQ(w.lastStepStats().rows, 0);  // a sleeping island costs nothing
  BodyDef ball = test::sphereDef("ball", Vec3(-3, 0.5, 0), 1, 0.2);
  ball.linear_velocity = Vec3(10, 0, 0);
  w.createBody(ball);
  bool woke = false;
  for (int s = 0; s < 60 && !woke; ++s) {
    w.step(kH);
    woke = !w.isAsleep(box);
  }
  EXPECT_TRUE(woke);
  for (int s = 0; s < 10; ++s) w.step(kH);
  EXPECT_GT(cairn::detail::internals(w).body(box).position.x(), 0.01);  // it was pushed
}

// A world at rest keeps its contacts as they were, impulses and all, and
// reports no event however long it sleeps (collide leaves them in place
// instead of rebuilding the list); taking a body away still ends its
// contacts, and the stack below wakes and steps on.
TEST(Sleeping, AWorldAtRestKeepsItsContactsAndEndsThemWhenABodyGoes) {
  World w;
  addGroundPlane(w);
  w.createBody(test::boxDef("bottom", Vec3(0, 0.5, 0)));
  const BodyId top = w.createBody(test::boxDef("top", Vec3(0, 1.5, 0)));
  for (int s = 0; s < 240 && w.lastStepStats().sleeping_bodies < 2; ++s) w.step(kH);
  ASSERT_EQ(w.lastStepStats().sleeping_bodies, 2);
  w.step(kH);
  const std::vector<cairn::Contact> resting = cairn::detail::internals(w).contacts_;
  ASSERT_EQ(resting.size(), 2u);  // ground-bottom, bottom-top
  for (int s = 0; s < 120; ++s) {
    w.step(kH);
    EXPECT_TRUE(w.contactEvents().empty());
  }
  const std::vector<cairn::Contact>& now = cairn::detail::internals(w).contacts_;
  ASSERT_EQ(now.size(), resting.size());
  for (size_t k = 0; k < now.size(); ++k) {
    EXPECT_EQ(now[k].key(), resting[k].key());
    for (int i = 0; i < now[k].count; ++i) {
      EXPECT_EQ(now[k].points[i].normal_impulse, resting[k].points[i].normal_impulse);
      EXPECT_EQ(now[k].points[i].local_a, resting[k].points[i].local_a);
    }
  }
  w.destroyBody(top);
  w.step(kH);
  int ends = 0;
  for (const auto& e : w.contactEvents()) ends += e.type == ContactEvent::Type::End;
  EXPECT_EQ(ends, 1);  // the top box's contact with the bottom one
  EXPECT_EQ(cairn::detail::internals(w).contacts_.size(), 1u);
}

// Events: a dropped box begins one contact with the ground, with the
// landing impulse; lifting it off ends it.
TEST(Events, BeginWithImpulseAndEnd) {
  World w;
  w.setSettings(noSleep());
  addGroundPlane(w);
  w.createBody(test::boxDef("box", Vec3(0, 1.5, 0)));
  int begins = 0, ends = 0;
  Real impulse = 0;
  for (int s = 0; s < 120; ++s) {
    w.step(kH);
    for (const auto& e : w.contactEvents()) {
      if (e.type == ContactEvent::Type::Begin) {
        ++begins;
        impulse = e.impulse;
      } else {
        ++ends;
      }
    }
  }
  EXPECT_EQ(begins, 1);
  EXPECT_EQ(ends, 0);
  // Falling 1 m: v = sqrt(2 g) = 4.43 m/s stopped by the landing impulse (>= m v minus a step's gravity).
  EXPECT_GT(impulse, std::sqrt(2 * 9.81) - 9.81 * kH - 0.1);
}

// Each step's events are exactly the difference of the contact lists:
// Begin for every enabled contact whose key had no touching contact the
// step before, End for every touching, enabled contact of the step before
// whose key is gone (collide tells the events when a list has nothing to
// walk for; this holds it to the definition). Balls bounce on the stack
// and the ground, leaving and touching again (begins and ends in the same
// steps as continuing contacts), the stack sleeps and a ball is taken
// away; on one thread and on two (the pyramid's 590 pairs are past the
// pool's threshold).
TEST(Events, EachStepsEventsAreTheContactsThatBeganAndEnded) {
  using Key = std::tuple<std::int32_t, std::int32_t>;  // one shape a body here: the body pair names the contact
  const auto keys = [](const World& w, bool touching_only) {
    std::multiset<Key> k;
    for (const Contact& c : cairn::detail::internals(w).contacts_)
      if (c.enabled && (!touching_only || c.touching)) k.insert({c.body_a.index, c.body_b.index});
    return k;
  };
  for (const int threads : {1, 2}) {
    SceneDesc scene = scenarios::byName("pyramid-20");
    scene.solver.threads = threads;
    scene.solver.sleeping = true;
    for (int i = 0; i < 12; ++i) {
      BodyDef ball = test::sphereDef("ball" + std::to_string(i), Vec3(-14 + 2.5 * i, 3 + (i % 4), 1.5 * (i % 3) - 1.5), 1, 0.3);
      ball.restitution = 0.7;
      scene.bodies.push_back(ball);
    }
    World w = buildWorld(scene);
    cairn::detail::internals(w).pool_rules_ = PoolRules::None;  // every step on its threads
    int begins = 0, ends = 0;
    for (int s = 0; s < 300; ++s) {
      if (s == 200) w.destroyBody(w.findBody("ball5"));
      std::multiset<Key> before = keys(w, true);
      std::multiset<Key> removed;  // contacts of the destroyed ball end too
      for (const Contact& c : cairn::detail::internals(w).ended_contacts_)
        if (c.touching && c.enabled) removed.insert({c.body_a.index, c.body_b.index});
      w.step(scene.dt);
      const std::multiset<Key> after = keys(w, false);
      std::multiset<Key> began, ended, got_began, got_ended;
      std::set_difference(after.begin(), after.end(), before.begin(), before.end(), std::inserter(began, began.end()));
      std::set_difference(before.begin(), before.end(), after.begin(), after.end(), std::inserter(ended, ended.end()));
      ended.insert(removed.begin(), removed.end());
      for (const ContactEvent& e : w.contactEvents())
        (e.type == ContactEvent::Type::Begin ? got_began : got_ended).insert({e.body_a.index, e.body_b.index});
      ASSERT_EQ(got_began, began) << threads << " threads, step " << s;
      ASSERT_EQ(got_ended, ended) << threads << " threads, step " << s;
      begins += static_cast<int>(began.size());
      ends += static_cast<int>(ended.size());
    }
    EXPECT_GT(ends, 12) << "the balls bounce: contacts end while others continue";
    EXPECT_GE(begins, 590 + 12) << "each of the pyramid's contacts and each ball's first landing";
  }
}

// Only what the scene needs: no friction rows when mu = 0; a jointed pair
// does not collide; groups and masks filter.
TEST(Filtering, FrictionlessContactsMakeNoFrictionRowsAndFiltersApply) {
  {
    World w;
    w.setSettings(noSleep());
    addGroundPlane(w, Vec3::UnitY(), 0);
    BodyDef b = test::boxDef("box", Vec3(0, 0.5, 0));
    b.friction = 0;
    w.createBody(b);
    w.step(kH);
    EXPECT_EQ(w.lastStepStats().rows_by_kind[static_cast<int>(RowKind::ContactFriction)], 0);
    EXPECT_EQ(w.lastStepStats().rows_by_kind[static_cast<int>(RowKind::ContactNormal)], 4);
  }
  {
    World w(Vec3::Zero());
    const BodyId a = w.createBody(test::boxDef("a", Vec3(0, 0, 0)));
    const BodyId b = w.createBody(test::boxDef("b", Vec3(0.9, 0, 0)));  // overlapping
    JointDef j;
    j.type = JointType::Ball;
    j.body_a = a;
    j.body_b = b;
    j.anchor = Vec3(0.45, 0, 0);
    w.createJoint(j);
    w.step(kH);
    EXPECT_EQ(w.lastStepStats().contacts, 0);
  }
  {
    World w(Vec3::Zero());
    BodyDef a = test::boxDef("a", Vec3(0, 0, 0));
    BodyDef b = test::boxDef("b", Vec3(0.9, 0, 0));
    a.collision_group = 1;
    a.collision_mask = ~2u;
    b.collision_group = 2;
    const BodyId ia = w.createBody(a);
    w.createBody(b);
    w.step(kH);
    EXPECT_EQ(w.lastStepStats().contacts, 0);
    // Filters changed between steps take effect at the next one, both ways.
    w.setCollisionFilter(ia, 1, ~0u);
    w.step(kH);
    EXPECT_EQ(w.lastStepStats().contacts, 1);
    w.setCollisionFilter(ia, 1, ~2u);
    w.step(kH);
    EXPECT_EQ(w.lastStepStats().contacts, 0);
  }
}

// A contact callback makes a one-way platform: a ball thrown up from below
// passes through, then lands on it from above.
TEST(Callback, OneWayPlatform) {
  World w;
  w.setSettings(noSleep());
  BodyDef p = test::boxDef("platform", Vec3(0, 2, 0), 1, Vec3(2, 0.1, 2));
  p.type = BodyType::Static;
  const BodyId platform = w.createBody(p);
  BodyDef ball = test::sphereDef("ball", Vec3(0, 1, 0), 1, 0.2);
  ball.linear_velocity = Vec3(0, 8, 0);
  ball.ccd = true;  // falling 11 cm a step: contacts must be made before it arrives
  const BodyId id = w.createBody(ball);
  w.setPreSolveCallback([&](ContactInfo& c) {
    // Veto while the ball is below the platform top or moving up.
    const BodyId other = c.body_a == platform ? c.body_b : c.body_a;
    if (cairn::detail::internals(w).body(other).position.y() - 0.2 < 2.1 - 0.02 || cairn::detail::internals(w).body(other).linear_velocity.y() > 0) c.enabled = false;
  });
  Real highest = 0;
  for (int s = 0; s < 240; ++s) {
    w.step(kH);
    highest = std::max(highest, cairn::detail::internals(w).body(id).position.y());
  }
  EXPECT_GT(highest, 2.3);  // it passed through from below
  EXPECT_NEAR(cairn::detail::internals(w).body(id).position.y(), 2.1 + 0.2, 0.02);  // and rests on top
}

// A velocity set between steps reaches the broadphase at the next step:
// the step skips refitting a proxy whose body has the pose and velocity
// it was last fitted with, so the velocity is part of what it compares.
// A CCD ball at rest, then thrown at 200 m/s (3.3 m a step) at a 2 cm
// wall 1 m away: its box must stretch along v h before the step's pairs
// are found, or it is through the wall before a contact exists.
TEST(Collision, VelocitySetBetweenStepsStretchesACcdBodysBoxAtTheNextStep) {
  World w(Vec3::Zero());
  w.setSettings(noSleep());
  BodyDef wall = test::boxDef("wall", Vec3(1, 0, 0), 1, Vec3(0.01, 1, 1));
  wall.type = BodyType::Static;
  w.createBody(wall);
  BodyDef ball = test::sphereDef("ball", Vec3::Zero(), 1, 0.05);
  ball.ccd = true;
  const BodyId id = w.createBody(ball);
  w.step(kH);  // fitted at rest
  w.setLinearVelocity(id, Vec3(200, 0, 0));
  for (int s = 0; s < 3; ++s) w.step(kH);
  // Stopped at the wall's near face (0.99 m) less its radius, to the slop.
  EXPECT_LT(cairn::detail::internals(w).body(id).position.x(), 0.99 - 0.05 + 0.01);
}

// Two boxes created in exactly the same place separate without a NaN.
TEST(Collision, CoincidentBodiesSeparateWithoutNan) {
  World w(Vec3::Zero());
  w.setSettings(noSleep());
  const BodyId a = w.createBody(test::boxDef("a", Vec3::Zero()));
  const BodyId b = w.createBody(test::boxDef("b", Vec3::Zero()));
  for (int s = 0; s < 300; ++s) w.step(kH);
  EXPECT_TRUE(w.numericalEvents().empty());
  EXPECT_TRUE(cairn::detail::internals(w).body(a).position.allFinite() && cairn::detail::internals(w).body(b).position.allFinite());
  EXPECT_GT((cairn::detail::internals(w).body(a).position - cairn::detail::internals(w).body(b).position).norm(), 0.9);  // pushed apart
}

}  // namespace
}  // namespace cairn

namespace cairn {
namespace {

// Rolling friction (coefficient c in metres: resisting torque <= c N): a
// solid sphere rolling without slipping decelerates at
// a = (c g / r) / (1 + I / (m r^2)) = (5/7) c g / r. Without it, it rolls on.
TEST(RollingFriction, SphereDeceleratesAtTheClosedFormRate) {
  const Real r = 0.5, c = 0.01;
  for (Real coeff : {Real(0), c}) {
    World w;
    w.setSettings(noSleep(20));
    addGroundPlane(w);
    BodyDef b = test::sphereDef("ball", Vec3(0, r, 0), 1, r);
    b.rolling_friction = coeff;
    b.linear_velocity = Vec3(2, 0, 0);
    b.angular_velocity = Vec3(0, 0, -2 / r);  // rolling: v = w r
    const BodyId id = w.createBody(b);
    for (int s = 0; s < 30; ++s) w.step(kH);
    const Real v0 = cairn::detail::internals(w).body(id).linear_velocity.x();
    for (int s = 0; s < 60; ++s) w.step(kH);
    const Real a = v0 - cairn::detail::internals(w).body(id).linear_velocity.x();  // over 1 s
    const Real expected = coeff * 9.81 / r * 5 / 7;
    EXPECT_NEAR(a, expected, 0.05 * c * 9.81 / r) << "coefficient " << coeff;
  }
}

}  // namespace
}  // namespace cairn
