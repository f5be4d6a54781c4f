// Contact recycling (world/world_contacts.cpp, SolverSettings::
// recycle_distance and recycle_angle): a pair whose relative pose stays
// within the bounds of the pose its manifold was made at keeps the manifold
// without running the narrowphase; one that moves further gets a fresh one.
#include "test_helpers.hpp"

#include "collision/manifold.hpp"
#include "validation/scenarios.hpp"
#include "world/world_access.hpp"
#include "world/world_impl.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace cairn {
namespace {

constexpr Real kDt = Real(1) / 60;

World groundWorld(const SolverSettings& s = SolverSettings{}) {
  WorldDef def;
  def.settings = s;
  World w(def);
  BodyDef g = test::boxDef("ground", Vec3(0, -0.5, 0), 1, Vec3(20, 0.5, 20));
  g.type = BodyType::Static;
  w.createBody(g);
  return w;
}

// A box settled on the ground moves far less than 1 mm a step: once settled
// its manifold is recycled every step. With recycling off, never.
TEST(ContactRecycling, RestingBoxKeepsItsManifoldWithoutTheNarrowphase) {
  for (const Real distance : {Real(0.001), Real(0)}) {
    SolverSettings s;
    s.recycle_distance = distance;
    s.sleeping = false;  // a sleeping pair keeps its contacts on another path
    World w = groundWorld(s);
    w.createBody(test::boxDef("box", Vec3(0, 0.5, 0)));
    for (int i = 0; i < 60; ++i) w.step(kDt);
    ASSERT_EQ(w.lastStepStats().contacts, 1);
    EXPECT_EQ(w.lastStepStats().recycled_contacts, distance > 0 ? 1 : 0) << distance;
  }
}

// Adding a shape moves the body's centre of mass, the origin of the frame
// its contact points are fixed in: the next step makes a fresh manifold
// (no recycling), even for a shift far under recycle_distance; the step
// after recycles again. A 1 cm sphere inside the 1 kg box, 0.4 m off its
// centre, takes its volume's share of the mass (4.2e-6) and moves the
// centre of mass 1.7 micrometres.
TEST(ContactRecycling, AddingAShapeMakesTheBodysManifoldsFresh) {
  SolverSettings s;
  s.sleeping = false;
  World w = groundWorld(s);
  const BodyId box = w.createBody(test::boxDef("box", Vec3(0, 0.5, 0)));
  for (int i = 0; i < 30; ++i) w.step(kDt);
  ASSERT_EQ(w.lastStepStats().recycled_contacts, 1);
  ShapeDesc pebble = ShapeDesc::sphere(0.01);
  pebble.local.p = Vec3(0.4, 0, 0);
  w.addShape(box, pebble);
  w.step(kDt);
  EXPECT_EQ(w.lastStepStats().recycled_contacts, 0);
  w.step(kDt);
  EXPECT_EQ(w.lastStepStats().recycled_contacts, 1);
}

// A box sliding at 2 m/s without friction moves 33 mm a step, far past the
// 1 mm bound: every step runs the narrowphase, and the ground-side points of
// the manifold stay under the box (within its 0.5 m half extent plus the
// 33 mm it moves in the step) instead of being left where it started.
TEST(ContactRecycling, SlidingBoxGetsAFreshManifoldEveryStep) {
  World w = groundWorld();
  BodyDef b = test::boxDef("box", Vec3(0, 0.5, 0));
  b.linear_velocity = Vec3(2, 0, 0);
  b.friction = 0;
  const BodyId box = w.createBody(b);
  for (int i = 0; i < 60; ++i) {
    w.step(kDt);
    EXPECT_EQ(w.lastStepStats().recycled_contacts, 0) << "step " << i;
  }
  const Real x = w.transform(box).p.x();
  ASSERT_GT(x, 1.9);  // it did slide (2 m/s for 1 s)
  const detail::WorldImpl& impl = detail::internals(w);
  ASSERT_EQ(impl.contacts_.size(), 1u);
  const Contact& c = impl.contacts_[0];
  const Transform ground = impl.body(c.body_a).transform();
  for (int i = 0; i < c.count; ++i)
    EXPECT_LE(std::abs(ground.apply(c.points[i].local_a).x() - x), 0.5 + 2 * kDt + 1e-9) << "point " << i;
}

// Every recycled manifold of a settled pyramid stays within the bounds of
// the one the narrowphase makes now from the same poses: the normals within
// recycle_angle of each other (a turn of B relative to A of at most that
// angle turns the face normal by as much), and the deepest penetration
// within recycle_distance + recycle_angle * r, r = 0.87 m the half diagonal
// of a unit box (a point at lever r moves at most that much under the
// bounded relative motion).
TEST(ContactRecycling, RecycledManifoldsStayWithinTheBoundsOfAFreshOne) {
  SceneDesc scene = scenarios::pyramid(10);
  WorldDef def;
  def.gravity = scene.gravity;
  def.settings = scene.solver;
  World w(def);
  for (const BodyDef& b : scene.bodies) w.createBody(b);
  int recycled = 0;
  for (int i = 0; i < 120; ++i) {
    w.step(scene.dt);
    recycled += w.lastStepStats().recycled_contacts;
  }
  ASSERT_GT(recycled, 1000);  // the settled pyramid recycles most of its ~150 manifolds a step
  const detail::WorldImpl& impl = detail::internals(w);
  const SolverSettings& s = impl.settings_;
  const Real depth_bound = s.recycle_distance + s.recycle_angle * std::sqrt(3 * 0.25);
  int compared = 0;
  for (const Contact& c : impl.contacts_) {
    const Body& a = impl.body(c.body_a);
    const Body& b = impl.body(c.body_b);
    std::vector<Manifold> fresh;
    collide(a.shapes[0], a.transform() * a.shapes[0].local, b.shapes[0], b.transform() * b.shapes[0].local,
            s.contact_margin, fresh);
    ASSERT_EQ(fresh.size(), 1u);
    EXPECT_GE(fresh[0].normal.dot(c.normal), std::cos(s.recycle_angle) - 1e-12);
    Real fresh_depth = -kInf, kept_depth = -kInf;
    for (int i = 0; i < fresh[0].count; ++i) fresh_depth = std::max(fresh_depth, fresh[0].points[i].depth);
    for (int i = 0; i < c.count; ++i) kept_depth = std::max(kept_depth, c.points[i].depth);
    EXPECT_NEAR(kept_depth, fresh_depth, depth_bound);
    ++compared;
  }
  EXPECT_GT(compared, 100);
}

}  // namespace
}  // namespace cairn
