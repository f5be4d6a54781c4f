// SolverSettings::patch_friction: a manifold's friction as one patch (two
// tangent rows at the points' centre, bounded together by the Coulomb cone
// of the total normal impulse, and a twist row about the normal) instead of
// rows at each point. The patch obeys Coulomb's law for sliding and for
// spinning, holds below the friction angle and slides above it, makes three
// friction rows for a four-point manifold, and reports per point friction
// impulses that carry exactly the force and the twist the solve applied.
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace cairn {
namespace {

constexpr Real kDt = Real(1) / 60;
constexpr Real kG = Real(9.81);
constexpr Real kMu = Real(0.5);  // both bodies' default friction, combined: 0.5

struct Box {
  World world;
  BodyId box;
};

// A unit box (1 kg) resting on a static ground slab tilted by `slope`
// radians about z, both mu = 0.5, given velocities v0 and w0.
Box boxOnGround(Real slope, const Vec3& v0, const Vec3& w0, bool patch = true, int directions = 2) {
  WorldDef def;
  def.settings.patch_friction = patch;
  def.settings.friction_directions = directions;
  def.settings.sleeping = false;
  def.settings.recycle_distance = 0;  // the narrowphase every step: reported points at the step's pose
  Box out{World(def), BodyId{}};
  const Quat tilt(Eigen::AngleAxis<Real>(slope, Vec3::UnitZ()));
  const Vec3 up = tilt * Vec3::UnitY();
  BodyDef g = test::boxDef("ground", -Real(0.5) * up, 1, Vec3(20, 0.5, 20));
  g.type = BodyType::Static;
  g.orientation = tilt;
  out.world.createBody(g);
  BodyDef b = test::boxDef("box", Real(0.5) * up);
  b.orientation = tilt;
  b.linear_velocity = v0;
  b.angular_velocity = w0;
  out.box = out.world.createBody(b);
  return out;
}

// Coulomb: the box decelerates at mu g and stops after v0^2 / (2 mu g) =
// 0.408 m at 2 m/s, along any direction (the disc has no corners).
// Semi-implicit Euler sums the velocities after each step's friction, so
// the discrete distance differs from the continuous one by less than one
// step's travel, h v0 = 3.3 cm.
TEST(PatchFriction, SlidingBoxStopsAtTheCoulombDistanceInAnyDirection) {
  const Real v0 = 2;
  for (const Vec3& dir : {Vec3(1, 0, 0), Vec3(1, 0, 1).normalized(), Vec3(Real(0.3), 0, -1).normalized()}) {
    Box s = boxOnGround(0, v0 * dir, Vec3::Zero());
    for (int i = 0; i < 120; ++i) s.world.step(kDt);
    const Vec3 p = s.world.transform(s.box).p;
    EXPECT_NEAR(p.x() * dir.x() + p.z() * dir.z(), v0 * v0 / (2 * kMu * kG), kDt * v0) << dir.transpose();
    // Across the motion: round-off only (the face manifold's singular
    // normal block is regularised at 1e-12 of its diagonal).
    EXPECT_NEAR(p.x() * dir.z() - p.z() * dir.x(), 0, 1e-6) << dir.transpose();
  }
}

// Twist: a unit box spinning about the vertical on its face, its load
// shared by the four corners at d = sqrt(2) / 2 from the centre, feels
// the friction torque mu m g d and, with I = m / 6, decelerates at
// alpha = 6 mu g d = 20.8 rad/s^2: it turns w0^2 / (2 alpha) = 0.60 rad
// from 5 rad/s. Semi-implicit Euler: within one step's turn, h w0.
TEST(PatchFriction, SpinningBoxStopsAtTheCoulombAngle) {
  const Real w0 = 5, alpha = 6 * kMu * kG * std::sqrt(Real(0.5));
  Box s = boxOnGround(0, Vec3::Zero(), Vec3(0, w0, 0));
  for (int i = 0; i < 60; ++i) s.world.step(kDt);
  const Vec3 turn = rotationVectorFromQuat(s.world.transform(s.box).q);
  EXPECT_NEAR(turn.y(), w0 * w0 / (2 * alpha), kDt * w0);
  EXPECT_NEAR(s.world.angularVelocity(s.box).y(), 0, 1e-9);  // stopped: static friction holds it
  EXPECT_NEAR(s.world.transform(s.box).p.x(), 0, 1e-6);     // the spin does not push it off its spot
}

// Below the friction angle (tan 20 deg = 0.36 < mu) the box stays; above it
// (tan 30 deg = 0.58) it slides at a = g (sin 30 - mu cos 30) = 0.657 m/s^2,
// 1.31 m in 2 s (within one step's travel at the end, h a t = 2.2 cm).
// Holding: the creep is what the push-out settles, under a millimetre.
TEST(PatchFriction, HoldsBelowTheFrictionAngleAndSlidesAbove) {
  const Real deg = std::acos(Real(-1)) / 180;
  Box hold = boxOnGround(20 * deg, Vec3::Zero(), Vec3::Zero());
  const Vec3 p0 = hold.world.transform(hold.box).p;
  for (int i = 0; i < 120; ++i) hold.world.step(kDt);
  EXPECT_LT((hold.world.transform(hold.box).p - p0).norm(), 1e-3);

  const Real a = kG * (std::sin(30 * deg) - kMu * std::cos(30 * deg)), t = 2;
  Box slide = boxOnGround(30 * deg, Vec3::Zero(), Vec3::Zero());
  const Vec3 q0 = slide.world.transform(slide.box).p;
  for (int i = 0; i < 120; ++i) slide.world.step(kDt);
  EXPECT_NEAR((slide.world.transform(slide.box).p - q0).norm(), a * t * t / 2, kDt * a * t);
}

// A four-point manifold: three friction rows (the pair and the twist),
// against four with one direction per point and eight with two.
TEST(PatchFriction, AFourPointManifoldMakesThreeFrictionRows) {
  const auto frictionRows = [](bool patch, int directions) {
    Box s = boxOnGround(0, Vec3::Zero(), Vec3::Zero(), patch, directions);
    s.world.step(kDt);
    return s.world.lastStepStats().rows_by_kind[static_cast<int>(RowKind::ContactFriction)];
  };
  EXPECT_EQ(frictionRows(true, 2), 3);
  EXPECT_EQ(frictionRows(true, 1), 3);  // friction_directions is not read
  EXPECT_EQ(frictionRows(false, 1), 4);
  EXPECT_EQ(frictionRows(false, 2), 8);
}

// The impulses one step applied to the box through its contacts, as they
// report them: sum (lambda_i n + f_i), and its moment about the vertical
// through c, sum ((x_i - c) x f_i)_y (the normal impulses of a level
// contact have none, and a point's offset along the normal drops out).
struct Reported {
  Vec3 impulse = Vec3::Zero();
  Real moment = 0;
};
Reported reported(const Box& s, const Vec3& c) {
  Reported r;
  for (const ContactData& k : s.world.contacts(s.box)) {
    const Real sign = k.body_b == s.box ? 1 : -1;  // impulses act on b along +n
    for (int j = 0; j < k.count; ++j) {
      r.impulse += sign * (k.normal * k.normal_impulses[j] + k.friction_impulses[j]);
      r.moment += sign * (k.points[j] - c).cross(k.friction_impulses[j]).y();
    }
  }
  return r;
}

// The per-point friction impulses a contact reports are the patch's force
// shared out over its points: a box sliding and spinning on the ground
// changes its momentum by exactly gravity's impulse and the reported
// impulses, m dv = m g h + sum (lambda_i n + f_i), to round-off (impulses
// of order m g h = 0.16 N s). Split impulse moves positions only, so
// nothing else changes the velocity.
TEST(PatchFriction, ReportedImpulsesCarryThePatchForce) {
  Box s = boxOnGround(0, Vec3(2, 0, 1), Vec3(0, 4, 0));
  const Real m = s.world.mass(s.box);
  for (int i = 0; i < 20; ++i) {
    const Vec3 v = s.world.linearVelocity(s.box);
    s.world.step(kDt);
    const Vec3 dv = s.world.linearVelocity(s.box) - v;
    const Reported r = reported(s, s.world.transform(s.box).p);
    EXPECT_NEAR((m * dv - m * Vec3(0, -kG, 0) * kDt - r.impulse).norm(), 0, 1e-9) << "step " << i;
  }
}

// ... and their moment is the patch's twist: a box held by static friction
// against a push F = mu m g / 2 and a torque tau = mu m g d / 2 about the
// vertical (half the patch's limits, d = sqrt(2) / 2 as above) stays put,
// and every step I_yy dw_y = tau h + the reported moment (and m dv = (m g +
// F) h + the reported impulse), to round-off. The box does not move, so
// the reported points (at the step's end pose) are where the solve's
// anchors were. Statics: the reported friction holds F h and tau h.
TEST(PatchFriction, ReportedImpulsesCarryThePatchTwist) {
  Box s = boxOnGround(0, Vec3::Zero(), Vec3::Zero());
  const Real m = s.world.mass(s.box), d = std::sqrt(Real(0.5));
  const Vec3 force(kMu * m * kG / 2, 0, 0), torque(0, kMu * m * kG * d / 2, 0);
  const Vec3 p0 = s.world.transform(s.box).p;
  for (int i = 0; i < 60; ++i) {
    const Vec3 v = s.world.linearVelocity(s.box), w = s.world.angularVelocity(s.box);
    s.world.applyCentralForce(s.box, force);
    s.world.applyTorque(s.box, torque);
    s.world.step(kDt);
    const Vec3 dv = s.world.linearVelocity(s.box) - v;
    const Real dw = s.world.angularVelocity(s.box).y() - w.y();
    const Reported r = reported(s, s.world.transform(s.box).p);
    EXPECT_NEAR((m * dv - (m * Vec3(0, -kG, 0) + force) * kDt - r.impulse).norm(), 0, 1e-9) << "step " << i;
    EXPECT_NEAR(s.world.inertia(s.box)(1, 1) * dw - torque.y() * kDt, r.moment, 1e-9) << "step " << i;
    if (i < 59) continue;
    // Holding: the friction's share of the balance, to the solve's
    // velocity left over (1e-6 of the impulses).
    EXPECT_NEAR(r.impulse.x(), -force.x() * kDt, 1e-6);
    EXPECT_NEAR(r.moment, -torque.y() * kDt, 1e-6);
  }
  EXPECT_LT((s.world.transform(s.box).p - p0).norm(), 1e-3);
  EXPECT_LT(std::abs(rotationVectorFromQuat(s.world.transform(s.box).q).y()), 1e-3);
}

}  // namespace
}  // namespace cairn
