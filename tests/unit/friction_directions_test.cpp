// SolverSettings::friction_directions: two tangent rows per contact point
// (a friction box) or one along the sliding direction (Bullet's default).
// A sliding box stops where Coulomb's law puts it with either, one tangent
// makes a third fewer rows, and a box sliding along a diagonal keeps to it.
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace cairn {
namespace {

constexpr Real kDt = Real(1) / 60;
constexpr Real kG = Real(9.81);

struct Slide {
  Vec3 position;
  int friction_rows = 0;  // tangent rows of the first step
};

// A unit box on a static ground box, both mu = 0.5 (combined: 0.5), pushed
// with velocity v0 along the ground; runs 2 s, long enough to stop.
Slide slide(int directions, const Vec3& v0) {
  WorldDef def;
  def.settings.friction_directions = directions;
  def.settings.sleeping = false;
  World w(def);
  BodyDef g = test::boxDef("ground", Vec3(0, -0.5, 0), 1, Vec3(20, 0.5, 20));
  g.type = BodyType::Static;
  w.createBody(g);
  BodyDef b = test::boxDef("box", Vec3(0, 0.5, 0));
  b.linear_velocity = v0;
  const BodyId box = w.createBody(b);
  Slide out;
  for (int i = 0; i < 120; ++i) {
    w.step(kDt);
    if (i == 0) out.friction_rows = w.lastStepStats().rows_by_kind[static_cast<int>(RowKind::ContactFriction)];
  }
  out.position = w.transform(box).p;
  return out;
}

// Coulomb: the box decelerates at mu g and stops after v0^2 / (2 mu g) =
// 0.408 m at 2 m/s. Semi-implicit Euler sums the velocities after each
// step's friction, so the discrete distance differs from the continuous one
// by less than one step's travel, h v0 = 3.3 cm.
TEST(FrictionDirections, SlidingBoxStopsAtTheCoulombDistanceWithOneOrTwoTangents) {
  const Real v0 = 2, mu = 0.5;
  for (const int directions : {1, 2}) {
    const Slide s = slide(directions, Vec3(v0, 0, 0));
    EXPECT_NEAR(s.position.x(), v0 * v0 / (2 * mu * kG), kDt * v0) << directions << " tangent rows";
    // Sideways: only round-off (the face manifold's singular normal block
    // is regularised at 1e-12 of its diagonal), well under a micrometre.
    EXPECT_NEAR(s.position.z(), 0, 1e-6) << directions;
  }
}

// Four points touch: four tangent rows with one direction, eight with two.
TEST(FrictionDirections, OneTangentMakesOneFrictionRowPerPoint) {
  EXPECT_EQ(slide(1, Vec3(2, 0, 0)).friction_rows, 4);
  EXPECT_EQ(slide(2, Vec3(2, 0, 0)).friction_rows, 8);
}

// The one tangent follows the sliding direction, so friction opposes the
// motion exactly: a box sliding along the diagonal x = z stops on it, at
// the Coulomb distance along it (tolerance as above).
TEST(FrictionDirections, OneTangentOpposesTheSlidingDirection) {
  const Real v0 = 2, mu = 0.5;
  const Slide s = slide(1, Vec3(v0, 0, v0) / std::sqrt(Real(2)));
  EXPECT_NEAR(s.position.x(), s.position.z(), 1e-6);  // round-off only, as above
  EXPECT_NEAR(std::hypot(s.position.x(), s.position.z()), v0 * v0 / (2 * mu * kG), kDt * v0);
}

}  // namespace
}  // namespace cairn
