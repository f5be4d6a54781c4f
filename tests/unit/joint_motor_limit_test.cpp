// Sign conventions, locked and soft limits, servos and soft velocity motors
// against closed forms.
//
// Most tests turn one body about (or slide it along) an axis through its
// center of mass, attached to the world, with no gravity: every row of the
// joint is then decoupled from the others (the point rows act at the
// center, the inertia is diagonal in the joint's axes), PGS solves each
// exactly in its first sweep, and the coordinate follows the implicit-Euler
// recurrence of the row's spring-damper (docs/constraints.md, section 1):
//
//     v+ = (v - h (k/m) x + h (c/m) v_target) / (1 + h c/m + h^2 k/m),   x+ = x + h v+
//
// to round-off; 1e-9 (rad, m) is ~1e6 ulps of the unit scale and far below
// any modelling difference these tests guard against.
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace cairn {
namespace {

constexpr Real kH = Real(1) / 60;

// Worlds without gravity, awake throughout (test::awakeWorld): these tests
// follow motions that slow to below the sleep threshold.
using test::awakeWorld;

// A solid cylinder of 2 kg, radius 0.5 m, its axis along world z:
// I_zz = m r^2 / 2 = 0.25 kg m^2.
constexpr Real kWheelInertia = 0.25;
BodyDef wheel(const std::string& name, const Vec3& p) {
  BodyDef d;
  d.name = name;
  d.mass = 2;
  d.position = p;
  d.shapes.push_back(ShapeDesc::cylinder(0.5, 0.1));
  d.orientation = Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitX()));  // cylinder y axis -> world z
  return d;
}

JointDef hingeZ(BodyId a, BodyId b, const Vec3& anchor = Vec3::Zero()) {
  JointDef j;
  j.type = JointType::Hinge;
  j.body_a = a;
  j.body_b = b;
  j.anchor = anchor;
  j.axis = Vec3::UnitZ();
  return j;
}

JointDef sliderX(BodyId a, BodyId b, const Vec3& anchor = Vec3::Zero()) {
  JointDef j = hingeZ(a, b, anchor);
  j.type = JointType::Slider;
  j.axis = Vec3::UnitX();
  return j;
}

// A wheel at the origin, listed first on a hinge about +z to the world,
// driven by `motor`.
BodyId motorizedWheel(World& w, const MotorDef& motor) {
  const BodyId id = w.createBody(wheel("wheel", Vec3::Zero()));
  JointDef j = hingeZ(id, kWorldBody);
  j.motor = motor;
  w.createJoint(j);
  return id;
}

MotorDef velocityMotor(Real target, Real max_force) { return MotorDef{true, target, max_force, {}, {}}; }
MotorDef servo(Real target, Real max_force) { return MotorDef{true, 0, max_force, target, {}}; }

// Rotation of q about world z (q turns about z only).
Real turnZ(const Quat& q) { return 2 * std::atan2(q.z(), q.w()); }

// One implicit-Euler step of x'' = -(k/m) x - (c/m) (x' - v_target).
struct Recurrence {
  Real k_over_m = 0, c_over_m = 0, h = kH, v_target = 0;
  void step(Real& x, Real& v) const {
    v = (v - h * k_over_m * x + h * c_over_m * v_target) / (1 + h * c_over_m + h * h * k_over_m);
    x += h * v;
  }
};

// ---------------------------------------------------------------- signs

// ODE and Bullet turn the first body at +target relative to the second
// (docs/constraints.md, "Sign conventions"): wheel listed first, world
// second, +3 rad/s about +z turns the wheel at +3 rad/s; the world listed
// first turns it at -3. Between two wheels the motor sets the relative rate
// and momentum stays zero.
TEST(JointSigns, HingeMotorTurnsTheFirstBodyAtPlusTargetRelativeToTheSecond) {
  World w = awakeWorld();
  const BodyId first = w.createBody(wheel("first", Vec3(0, 0, 0)));
  const BodyId second = w.createBody(wheel("second", Vec3(3, 0, 0)));
  const BodyId a = w.createBody(wheel("a", Vec3(6, 0, 0)));
  const BodyId b = w.createBody(wheel("b", Vec3(6, 0, 1)));
  JointDef j1 = hingeZ(first, kWorldBody);
  j1.motor = velocityMotor(3, 100);
  JointDef j2 = hingeZ(kWorldBody, second, Vec3(3, 0, 0));
  j2.motor = velocityMotor(3, 100);
  JointDef j3 = hingeZ(a, b, Vec3(6, 0, 0.5));
  j3.motor = velocityMotor(3, 100);
  w.createJoint(j1);
  w.createJoint(j2);
  w.createJoint(j3);
  for (int s = 0; s < 30; ++s) w.step(kH);
  EXPECT_NEAR(w.angularVelocity(first).z(), 3, 1e-9);
  EXPECT_NEAR(w.angularVelocity(second).z(), -3, 1e-9);
  EXPECT_NEAR(w.angularVelocity(a).z() - w.angularVelocity(b).z(), 3, 1e-9);
  EXPECT_NEAR(w.angularVelocity(a).z() + w.angularVelocity(b).z(), 0, 1e-9);
}

TEST(JointSigns, SliderMotorMovesTheFirstBodyAtPlusTargetRelativeToTheSecond) {
  World w = awakeWorld();
  const BodyId first = w.createBody(test::boxDef("first", Vec3(0, 0, 0)));
  const BodyId second = w.createBody(test::boxDef("second", Vec3(0, 3, 0)));
  JointDef j1 = sliderX(first, kWorldBody);
  j1.motor = velocityMotor(0.5, 100);
  JointDef j2 = sliderX(kWorldBody, second, Vec3(0, 3, 0));
  j2.motor = velocityMotor(0.5, 100);
  w.createJoint(j1);
  w.createJoint(j2);
  for (int s = 0; s < 30; ++s) w.step(kH);
  EXPECT_NEAR(w.linearVelocity(first).x(), 0.5, 1e-9);
  EXPECT_NEAR(w.linearVelocity(second).x(), -0.5, 1e-9);
}

// The hinge angle, slider travel and cone-twist twist are the first body's
// relative to the second, and so are their limits: each body (listed
// first) is thrown at 1 rad/s or m/s against one of its asymmetric bounds
// and stops there. The speculative limit row closes the gap within the
// step and no more, so the bound is met to the solver's precision; 1e-6
// allows for the twist row, whose axis tilts a little as the box turns.
TEST(JointSigns, LimitsBoundTheFirstBodyRelativeToTheSecond) {
  for (const Real dir : {1.0, -1.0}) {
    SCOPED_TRACE(dir);
    World w = awakeWorld();
    BodyDef hinged = wheel("hinged", Vec3::Zero());
    hinged.angular_velocity = Vec3(0, 0, dir);
    BodyDef slid = test::boxDef("slid", Vec3(3, 0, 0));
    slid.linear_velocity = Vec3(dir, 0, 0);
    BodyDef twisted = test::boxDef("twisted", Vec3(6, 0, 0));
    twisted.angular_velocity = Vec3(0, 0, dir);
    const BodyId h = w.createBody(hinged), s = w.createBody(slid), t = w.createBody(twisted);
    JointDef hinge = hingeZ(h, kWorldBody);
    hinge.limit = LimitDef{true, -0.2, 0.3, 0, {}};
    JointDef slider = sliderX(s, kWorldBody, Vec3(3, 0, 0));
    slider.limit = LimitDef{true, -0.25, 0.15, 0, {}};
    JointDef cone = hingeZ(t, kWorldBody, Vec3(6, 0, 0));
    cone.type = JointType::ConeTwist;
    cone.limit = LimitDef{true, -0.1, 0.4, 0, {}};
    w.createJoint(hinge);
    w.createJoint(slider);
    w.createJoint(cone);
    for (int n = 0; n < 60; ++n) w.step(kH);
    EXPECT_NEAR(turnZ(w.transform(h).q), dir > 0 ? 0.3 : -0.2, 1e-6);
    EXPECT_NEAR(w.transform(s).p.x() - 3, dir > 0 ? 0.15 : -0.25, 1e-6);
    EXPECT_NEAR(turnZ(w.transform(t).q), dir > 0 ? 0.4 : -0.1, 1e-6);
  }
}

// ---------------------------------------------------------------- limits

// lower == upper holds the coordinate from both sides: two bars on hinges
// at the origin, one reaching along +x (gravity turns it by -z), one along
// -x (turned by +z), both locked at 0 by a rigid limit. A one-sided row
// would hold one and let the other swing down. Both stay put to the
// solver's precision: the six rows of each hinge converge to round-off
// within the 10 sweeps (measured 6e-23 rad), so 1e-9 rad is far above it
// and far below any swing.
TEST(LockedLimit, HoldsFromBothSides) {
  World w = awakeWorld(Vec3(0, -9.81, 0));
  const BodyId right = w.createBody(test::boxDef("right", Vec3(0.5, 0, 0), 1, Vec3(0.5, 0.05, 0.05)));
  const BodyId left = w.createBody(test::boxDef("left", Vec3(-0.5, 0, 2), 1, Vec3(0.5, 0.05, 0.05)));
  for (const auto& [id, z] : {std::pair{right, 0.0}, std::pair{left, 2.0}}) {
    JointDef j = hingeZ(id, kWorldBody, Vec3(0, 0, z));
    j.limit = LimitDef{true, 0, 0, 0, {}};
    w.createJoint(j);
  }
  for (int n = 0; n < 120; ++n) {
    w.step(kH);
    ASSERT_LT(std::abs(turnZ(w.transform(right).q)), 1e-9) << n;
    ASSERT_LT(std::abs(turnZ(w.transform(left).q)), 1e-9) << n;
  }
}

// Jolt's TestHingeSpring (HingeConstraintTests.cpp): a sphere on a hinge
// whose limits are both at the rest angle, with a spring softness of 2 Hz
// and damping ratio 0.1, released 100 degrees away, is the damped
// oscillator stepped by implicit Euler, in both spellings. cairn's rest
// angle is -100 degrees (the body starts at 0), the same motion.
// (With the old one-sided lock the braking side was clipped: 0.531 rad
// where the recurrence gives 0.481 at the same step.)
TEST(SoftLimit, LockedHingeSpringIsTheImplicitEulerOscillator) {
  const Real f = 2, zeta = 0.1, rest = -100 * kPi / 180;
  for (const bool by_frequency : {false, true}) {
    SCOPED_TRACE(by_frequency ? "frequency/damping_ratio" : "stiffness/damping");
    World w = awakeWorld();
    const BodyId id = w.createBody(test::sphereDef("ball", Vec3::Zero(), 1, 0.5));
    const Real inertia = Real(0.4) * 1 * 0.25;  // 2/5 m r^2
    const Real omega = 2 * kPi * f;
    JointDef j = hingeZ(id, kWorldBody);
    j.axis = Vec3::UnitY();
    j.limit = LimitDef{true, rest, rest, 0, {}};
    if (by_frequency) {
      j.limit.softness.frequency = f;
      j.limit.softness.damping_ratio = zeta;
    } else {
      j.limit.softness.stiffness = inertia * omega * omega;
      j.limit.softness.damping = 2 * inertia * zeta * omega;
    }
    w.createJoint(j);
    const Recurrence r{omega * omega, 2 * zeta * omega};
    Real x = -rest, v = 0;
    for (int n = 0; n < 120; ++n) {
      r.step(x, v);
      w.step(kH);
      const Quat& q = w.transform(id).q;
      const Real angle = 2 * std::atan2(q.y(), q.w());
      ASSERT_NEAR(wrapAngle(angle - rest), x, 1e-9) << n;
    }
  }
}

// The slider's counterpart: a locked soft limit (lower == upper = 0.3 m,
// 2 Hz, zeta = 0.1) on a 1 kg box released at travel 0 is the damped
// oscillator about 0.3 m, stepped by implicit Euler (k and c from the
// row's effective mass, the box's 1 kg), on both sides of its rest point:
// it overshoots past 0.3 m and is pulled back, then pushed again.
TEST(SoftLimit, LockedSliderSpringIsTheImplicitEulerOscillatorOnBothSides) {
  const Real f = 2, zeta = 0.1, rest = 0.3;
  World w = awakeWorld();
  const BodyId id = w.createBody(test::boxDef("box", Vec3::Zero(), 1, Vec3(0.1, 0.1, 0.1)));
  JointDef j = sliderX(id, kWorldBody);
  j.limit = LimitDef{true, rest, rest, 0, {}};
  j.limit.softness.frequency = f;
  j.limit.softness.damping_ratio = zeta;
  w.createJoint(j);
  const Real omega = 2 * kPi * f;
  const Recurrence r{omega * omega, 2 * zeta * omega};
  Real x = -rest, v = 0, highest = -rest;
  int sign_changes = 0;
  for (int n = 0; n < 120; ++n) {
    const Real before = x;
    r.step(x, v);
    if ((before < 0) != (x < 0)) ++sign_changes;
    highest = std::max(highest, x);
    w.step(kH);
    ASSERT_NEAR(w.transform(id).p.x() - rest, x, 1e-9) << n;
  }
  EXPECT_GT(highest, 0.1);       // well past the rest point, and back
  EXPECT_GE(sign_changes, 3);
}

// A soft stop past its bound is a spring-damper that pulls as well as
// pushes. A 1 kg box on a slider with limits [0.2, 5] starts at travel 0,
// 0.2 m below the lower stop, at rest; the stop (k = 100 N/m, zeta = 0.8)
// brings it back along the implicit-Euler recurrence until it crosses 0.2,
// then it coasts. Near the crossing the damper outweighs the spring and
// the stop's impulse turns negative (checked on the recurrence itself, so
// the test can tell a one-sided row, which would clip it, from this one).
TEST(SoftLimit, SliderStopIsADampedSpringUntilTheJointLeavesIt) {
  const Real k = 100, m = 1, zeta = 0.8, lower = 0.2;
  World w = awakeWorld();
  const BodyId id = w.createBody(test::boxDef("box", Vec3::Zero(), m, Vec3(0.1, 0.1, 0.1)));
  JointDef j = sliderX(id, kWorldBody);
  j.limit = LimitDef{true, lower, 5, 0, {}};
  j.limit.softness.stiffness = k;
  j.limit.softness.damping = 2 * zeta * std::sqrt(k * m);
  w.createJoint(j);
  const Recurrence r{k / m, 2 * zeta * std::sqrt(k / m)};
  Real s = 0, v = 0;
  bool pulled = false, left = false;
  for (int n = 0; n < 120; ++n) {
    if (s <= lower) {  // engaged at the step's start, as the row is built
      Real x = s - lower;
      const Real v0 = v;
      r.step(x, v);
      s = x + lower;
      pulled = pulled || v < v0;
    } else {
      left = true;
      s += kH * v;
    }
    w.step(kH);
    ASSERT_NEAR(w.transform(id).p.x(), s, 1e-9) << n;
  }
  EXPECT_TRUE(pulled);
  EXPECT_TRUE(left);
}

// ---------------------------------------------------------------- motors

// A servo with the default softness (2 Hz, critically damped) turns the
// wheel (listed first) from 0 to 1 rad. Critical damping makes the
// recurrence's root a double 1 / (1 + h w): x_n = x0 (1 + n h w / (1 + h w))
// (1 + h w)^-n with x the error to the target, the discrete closed form.
// It reaches 1% of the step where the continuous (1 + w t) e^(-w t) does,
// t99 = 6.638 / w, stretched by the discrete rate w' = ln(1 + h w) / h:
// within a step of t99 w / w'.
TEST(Servo, CriticallyDampedByDefaultReachesItsTargetInTheClosedFormTime) {
  World w = awakeWorld();
  const BodyId id = motorizedWheel(w, servo(1, 1000));
  const Real omega = 2 * kPi * 2, hw = kH * omega;
  int n99 = -1;
  for (int n = 1; n <= 180; ++n) {
    w.step(kH);
    const Real x = -(1 + n * hw / (1 + hw)) * std::pow(1 + hw, -n);
    const Real angle = turnZ(w.transform(id).q);
    ASSERT_NEAR(angle - 1, x, 1e-9) << n;
    if (n99 < 0 && std::abs(angle - 1) < 0.01) n99 = n;
  }
  const Real t99 = 6.638352067 / omega;  // (1 + u) e^-u = 0.01
  const Real stretched = t99 * omega / (std::log(1 + hw) / kH);
  EXPECT_NEAR(n99 * kH, stretched, kH);
}

// The continuous closed form. The discrete solution above is
// x0 (1 + a t) e^(-b t) with a = w / (1 + h w) = w - h w^2 and
// b = ln(1 + h w) / h = w - h w^2 / 2 to first order in h w, against
// x0 (1 + w t) e^(-w t): their difference is, with u = w t,
// x0 (h w / 2) u (u - 1) e^-u, at most 0.309 (h w / 2) x0 (at u = 2.618);
// second-order terms add a relative h w (0.8% here), covered by a 10%
// allowance. A slider servo given a stiffness only, so critically damped by
// c = 2 sqrt(k m), at h = 1/600 s.
TEST(Servo, SliderFollowsTheContinuousCriticallyDampedResponseWithinTheStepError) {
  const Real h = Real(1) / 600, m = 2, k = 50, target = 0.4;
  World w = awakeWorld();
  const BodyId id = w.createBody(test::boxDef("cart", Vec3::Zero(), m, Vec3(0.2, 0.2, 0.2)));
  JointDef j = sliderX(id, kWorldBody);
  j.motor = servo(target, 1000);
  j.motor.softness.stiffness = k;
  w.createJoint(j);
  const Real omega = std::sqrt(k / m);
  const Real bound = Real(1.1) * 0.309 * (h * omega / 2) * target;
  for (int n = 1; n <= 3000; ++n) {
    w.step(h);
    const Real t = n * h;
    const Real exact = target - target * (1 + omega * t) * std::exp(-omega * t);
    ASSERT_NEAR(w.transform(id).p.x(), exact, bound) << n;
  }
}

// Too little torque: the servo saturates at max_force and the wheel turns
// at the constant acceleration tau / I = 0.4 rad/s^2 (semi-implicit Euler:
// theta_n = a h^2 n (n + 1) / 2). The spring would ask for k x = 39 N m at
// the start and still 31 N m after 1 s (0.2 rad of the 1 rad), far above
// the 0.1 N m allowed.
TEST(Servo, TooSmallMaxForceTurnsAtTorqueOverInertia) {
  World w = awakeWorld();
  const BodyId id = motorizedWheel(w, servo(1, 0.1));
  const Real a = 0.1 / kWheelInertia;
  for (int n = 1; n <= 60; ++n) {
    w.step(kH);
    ASSERT_NEAR(turnZ(w.transform(id).q), a * kH * kH * n * (n + 1) / 2, 1e-12) << n;
  }
}

// An underdamped servo (1 Hz, zeta = 0.3) given by frequency: k and c come
// from the row's effective mass, the wheel's I, and the angle follows the
// recurrence, overshooting the target.
TEST(Servo, FrequencySpellingIsTheImplicitEulerOscillatorAboutTheTarget) {
  World w = awakeWorld();
  MotorDef m = servo(-0.5, 1000);
  m.softness.frequency = 1;
  m.softness.damping_ratio = 0.3;
  const BodyId id = motorizedWheel(w, m);
  const Real omega = 2 * kPi;
  const Recurrence r{omega * omega, 2 * 0.3 * omega};
  Real x = 0.5, v = 0, lowest = 0;
  for (int n = 1; n <= 120; ++n) {
    r.step(x, v);
    w.step(kH);
    const Real angle = turnZ(w.transform(id).q);
    ASSERT_NEAR(angle + 0.5, x, 1e-9) << n;
    lowest = std::min(lowest, angle);
  }
  EXPECT_LT(lowest, -0.5 - 0.1);  // it overshot
}

// A soft velocity motor: a damper c toward the target speed, force
// c (target - w) taken at the end of the step, so w_n = target (1 - (1 + h c / I)^-n);
// with the force bounded by max_force it first accelerates at tau / I.
TEST(SoftVelocityMotor, ApproachesItsTargetThroughItsDamper) {
  const Real c = 0.5, target = 4;
  MotorDef m = velocityMotor(target, 1000);
  m.softness.damping = c;
  World w = awakeWorld();
  const BodyId id = motorizedWheel(w, m);
  for (int n = 1; n <= 120; ++n) {
    w.step(kH);
    const Real expected = target * (1 - std::pow(1 + kH * c / kWheelInertia, -n));
    ASSERT_NEAR(w.angularVelocity(id).z(), expected, 1e-9) << n;
  }
  // Bounded: the damper asks c target = 2 N m at the start; 0.5 N m is allowed.
  m.max_force = 0.5;
  World w2 = awakeWorld();
  const BodyId id2 = motorizedWheel(w2, m);
  w2.step(kH);
  EXPECT_NEAR(w2.angularVelocity(id2).z(), 0.5 / kWheelInertia * kH, 1e-12);
}

}  // namespace
}  // namespace cairn
