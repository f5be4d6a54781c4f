// Joints, limits, motors, softness and breaking against closed forms and
// invariants.
#include "constraints/softness.hpp"
#include "cairn/error.hpp"
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace cairn {
namespace {

constexpr Real kH = Real(1) / 60;

// A chain of n links (boxes 0.1 x 0.5 x 0.1 m, 1 kg) hanging straight down
// from the origin, ball joints at the link ends.
World hangingChain(int n, int iterations) {
  World w;
  SolverSettings s;
  s.iterations = iterations;
  s.sleeping = false;  // these tests watch the solver on a chain at rest
  w.setSettings(s);
  for (int k = 0; k < n; ++k) {
    const BodyId id = w.createBody(test::boxDef("l" + std::to_string(k), Vec3(0, -0.25 - 0.5 * k, 0), 1, Vec3(0.05, 0.25, 0.05)));
    JointDef j;
    j.type = JointType::Ball;
    j.body_a = k == 0 ? kWorldBody : BodyId{k - 1};
    j.body_b = id;
    j.anchor = Vec3(0, -0.5 * k, 0);
    w.createJoint(j);
  }
  return w;
}

Real worstJointError(const World& w) {
  Real worst = 0;
  for (int j = 0; j < cairn::detail::internals(w).jointSlots(); ++j) worst = std::max(worst, w.jointError(JointId{j}).linear);
  return worst;
}

// At rest the chain's only error is PGS's incomplete convergence under the
// 20 kg load. Starting from zero impulses, loading the chain takes a
// transient (about 5 mm at the default 10 iterations, 0.8 mm at 40: a chain
// needs ~N^2 sweeps in all to carry its weight to the top); after it, warm
// starting carries the impulses over and from 3 s on the error stays below
// 1 mm, falling geometrically (docs/constraints.md).
TEST(BallChain, HangingChainOfTwentyStaysWithinOneMillimetre) {
  {
    World w = hangingChain(20, 10);
    Real settled = 0;
    for (int s = 0; s < 600; ++s) {
      w.step(kH);
      if (s >= 180) settled = std::max(settled, worstJointError(w));
    }
    EXPECT_LT(settled, 1e-3);
    // The top joint carries the weight of all 20 links.
    EXPECT_NEAR(w.jointFeedback(JointId{0}).force_b.y(), 20 * 9.81, 1e-3 * 20 * 9.81);
  }
  World w = hangingChain(20, 40);
  Real worst = 0;
  for (int s = 0; s < 600; ++s) {
    w.step(kH);
    worst = std::max(worst, worstJointError(w));
  }
  EXPECT_LT(worst, 1e-3);
}

// ODE's single-pass Baumgarte warm-starts last step's position correction
// along with the holding impulse; at 10 plain PGS iterations on this chain
// the re-applied correction grows without bound. The default two-pass
// Baumgarte (correction never warm-started) and split impulse settle.
// NNCG's momentum (the default) converges far enough in 10 sweeps that the
// single pass settles too: the growth is a symptom of unconverged sweeps.
TEST(BallChain, SinglePassBaumgarteGrowsUnderPlainPgsWhereTwoPassSettles) {
  struct Result {
    Real worst = 0, end = 0;
  };
  const auto run = [](Correction c, bool nncg) {
    World w = hangingChain(20, 10);
    SolverSettings s = w.settings();
    s.method = SolverMethod::PGS;  // the PGS correction modes themselves
    s.position_correction = c;
    s.nncg = nncg;
    w.setSettings(s);
    Result r;
    for (int st = 0; st < 600; ++st) {
      w.step(kH);
      r.worst = std::max(r.worst, worstJointError(w));
    }
    r.end = worstJointError(w);
    return r;
  };
  // Once grown, the links fold and hit each other, so the end value is
  // chaotic; the largest error over the run is what grows.
  EXPECT_GT(run(Correction::InRhs, false).worst, 0.1);
  EXPECT_LT(run(Correction::VelocityBias, false).end, 1e-4);
  EXPECT_LT(run(Correction::PseudoVelocity, false).end, 1e-4);
  EXPECT_LT(run(Correction::InRhs, true).end, 1e-4);
  EXPECT_LT(run(Correction::VelocityBias, true).end, 1e-4);
}

// Chain of 20 spheres released horizontally (docs/scenarios.md chain-20): a whip
// whose tip passes 20 m/s. More iterations must shrink the largest anchor
// separation; the figures go in docs/constraints.md.
TEST(BallChain, HorizontalWhipErrorFallsWithIterations) {
  Real prev = kInf;
  for (int it : {4, 20, 100}) {
    World w;
    SolverSettings s;
    s.method = SolverMethod::PGS;  // PGS's convergence in its sweeps
    s.iterations = it;
    w.setSettings(s);
    for (int k = 0; k < 20; ++k) {
      w.createBody(test::sphereDef("s" + std::to_string(k), Vec3(0.5 + k, 0, 0), 1, 0.1));
      JointDef j;
      j.type = JointType::Ball;
      j.body_a = k == 0 ? kWorldBody : BodyId{k - 1};
      j.body_b = BodyId{k};
      j.anchor = Vec3(k, 0, 0);
      w.createJoint(j);
    }
    Real worst = 0, tip_speed = 0;
    for (int st = 0; st < 600; ++st) {
      w.step(kH);
      worst = std::max(worst, worstJointError(w));
      tip_speed = std::max(tip_speed, cairn::detail::internals(w).body(BodyId{19}).linear_velocity.norm());
    }
    EXPECT_GT(tip_speed, 20) << it;  // it is a whip
    EXPECT_LT(worst, prev) << it;
    prev = worst;
  }
}

// Hinge motor on a free-spinning wheel (solid cylinder about its axis),
// listed first so that the motor turns it at +target: with enough torque it
// reaches the target speed; with too little it accelerates at exactly
// tau / I (the motor row saturates at tau h).
TEST(HingeMotor, ReachesTargetOrAcceleratesAtTorqueOverInertia) {
  const auto run = [](Real max_torque, int steps) {
    World w(Vec3::Zero());
    BodyDef d;
    d.name = "wheel";
    d.mass = 2;
    d.shapes.push_back(ShapeDesc::cylinder(0.5, 0.1));
    d.orientation = Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitX()));  // cylinder y axis -> world z
    const BodyId id = w.createBody(d);
    JointDef j;
    j.type = JointType::Hinge;
    j.body_a = id;
    j.body_b = kWorldBody;
    j.axis = Vec3::UnitZ();
    j.motor.enabled = true;
    j.motor.target_velocity = 10;
    j.motor.max_force = max_torque;
    w.createJoint(j);
    for (int s = 0; s < steps; ++s) w.step(kH);
    return cairn::detail::internals(w).body(id).angular_velocity.z();
  };
  EXPECT_NEAR(run(1000, 60), 10, 1e-6);
  // I = 1/2 m r^2 = 0.25 kg m^2; 0.1 N m for 1 s gives 0.4 rad/s.
  EXPECT_NEAR(run(0.1, 60), 0.1 / 0.25 * 1.0, 1e-9);
}

// A hinge limit holds a pendulum (the standard 1 m cube, center 1 m from the
// axis) released at 90 degrees inside [-0.5, 0.5] rad: the speculative limit
// row stops it at the bound, and what PGS leaves unconverged at impact
// (10 iterations) stays under 0.01 rad.
TEST(HingeLimit, PendulumStaysInsideItsLimits) {
  World w;
  const BodyId id = w.createBody(test::boxDef("bob", Vec3(1, 0, 0)));
  JointDef j;
  j.type = JointType::Hinge;
  j.body_a = kWorldBody;
  j.body_b = id;
  j.axis = Vec3::UnitZ();
  j.limit.enabled = true;
  j.limit.lower = -0.5;
  j.limit.upper = 0.5;
  const JointId jid = w.createJoint(j);
  Real lowest = 0;
  for (int s = 0; s < 600; ++s) {
    w.step(kH);
    const Vec3 p = cairn::detail::internals(w).body(id).position;
    lowest = std::min(lowest, std::atan2(p.y(), p.x()));
    EXPECT_LT(w.jointError(jid).angular, 0.01) << s;
  }
  EXPECT_NEAR(lowest, -0.5, 0.01);  // it reached the bound and stopped there
}

// Slider with limits: a box (listed first, so the travel is its own) on a
// slider pushed by gravity along a tilted axis stops at the upper limit.
TEST(SliderLimit, StopsAtTheBoundAndKeepsOrientation) {
  World w;
  const BodyId id = w.createBody(test::boxDef("carriage", Vec3::Zero(), 1, Vec3(0.2, 0.1, 0.1)));
  JointDef j;
  j.type = JointType::Slider;
  j.body_a = id;
  j.body_b = kWorldBody;
  j.axis = Vec3(1, -1, 0).normalized();
  j.limit.enabled = true;
  j.limit.lower = -1;
  j.limit.upper = 0.5;
  const JointId jid = w.createJoint(j);
  for (int s = 0; s < 300; ++s) w.step(kH);
  const Real travel = cairn::detail::internals(w).body(id).position.dot(Vec3(1, -1, 0).normalized());
  EXPECT_NEAR(travel, 0.5, 0.005);
  EXPECT_LT(w.jointError(jid).angular, 1e-3);
  EXPECT_LT(cairn::detail::internals(w).body(id).position.dot(Vec3(1, 1, 0).normalized()), 1e-3);  // stays on the rail
}

// Soft distance joint from k and c: a 2 kg ball on a zero-gravity "spring"
// oscillates at sqrt(k/m) within 2% and decays with zeta = c / (2 sqrt(k m))
// within 5%. ERP/CFM is an implicit-Euler spring-damper, which adds about
// omega h / 2 to the damping ratio: 0.0017 at h = 1/3000, under 2% of 0.1.
TEST(SoftDistance, OscillatesAtSpringFrequencyAndDecaysWithDampingRatio) {
  const Real k = 200, c = 4, m = 2, h = Real(1) / 3000;
  World w(Vec3::Zero());
  const BodyId id = w.createBody(test::sphereDef("ball", Vec3(1.1, 0, 0), m, 0.05));
  JointDef j;
  j.type = JointType::Distance;
  j.body_a = kWorldBody;
  j.body_b = id;
  j.anchor_a = Vec3::Zero();
  j.anchor_b = Vec3(1.1, 0, 0);
  j.length = 1.0;
  j.softness.stiffness = k;
  j.softness.damping = c;
  w.createJoint(j);
  std::vector<Real> peaks_t, peaks_x;
  Real x_prev2 = 0.1, x_prev = 0.1;
  for (int s = 0; s < 3000 * 6; ++s) {
    w.step(h);
    const Real x = cairn::detail::internals(w).body(id).position.x() - 1;
    if (s > 1 && x_prev > x_prev2 && x_prev >= x && x_prev > 0) {
      peaks_t.push_back(w.time() - h);
      peaks_x.push_back(x_prev);
    }
    x_prev2 = x_prev;
    x_prev = x;
  }
  ASSERT_GE(peaks_t.size(), 4u);
  const Real omega_d = 2 * kPi * (peaks_t.size() - 1) / (peaks_t.back() - peaks_t.front());
  const Real zeta = c / (2 * std::sqrt(k * m));
  const Real omega_n = std::sqrt(k / m);
  EXPECT_NEAR(omega_d, omega_n * std::sqrt(1 - zeta * zeta), 0.02 * omega_n);
  // Log decrement: ln(x_i / x_{i+1}) = 2 pi zeta / sqrt(1 - zeta^2).
  const Real delta = std::log(peaks_x.front() / peaks_x.back()) / (peaks_x.size() - 1);
  const Real zeta_measured = delta / std::sqrt(4 * kPi * kPi + delta * delta);
  EXPECT_NEAR(zeta_measured, zeta, 0.05 * zeta);
}

// The ERP/CFM <-> spring mapping round-trips exactly.
TEST(Softness, ErpCfmAndSpringSpellingsRoundTrip) {
  const Real h = 0.01, k = 1234, c = 56, m = 3;
  const ErpCfm ec = erpCfmFromSpring(k, c, h);
  EXPECT_NEAR(ec.erp, h * k / (h * k + c), 1e-15);
  EXPECT_NEAR(ec.cfm, 1 / (h * k + c), 1e-15);
  const SpringEquivalent s = springFromErpCfm(ec.erp, ec.cfm, h, m);
  EXPECT_NEAR(s.stiffness, k, 1e-9 * k);
  EXPECT_NEAR(s.damping, c, 1e-9 * c);
  EXPECT_NEAR(s.frequency, std::sqrt(k / m) / (2 * kPi), 1e-12);
  EXPECT_NEAR(s.damping_ratio, c / (2 * std::sqrt(k * m)), 1e-12);
  const ErpCfm ef = erpCfmFromFrequency(s.frequency, s.damping_ratio, m, h);
  EXPECT_NEAR(ef.erp, ec.erp, 1e-12);
  EXPECT_NEAR(ef.cfm, ec.cfm, 1e-12);
}

// A joint holding a 10 kg weight (98.1 N) breaks when its threshold is
// below the load and holds when above; the event names it.
TEST(JointBreaking, BreaksAtItsThresholdAndSaysSo) {
  for (Real threshold : {90.0, 110.0}) {
    World w;
    const BodyId id = w.createBody(test::sphereDef("weight", Vec3(0, -1, 0), 10, 0.1));
    JointDef j;
    j.name = "hook";
    j.type = JointType::Ball;
    j.body_a = kWorldBody;
    j.body_b = id;
    j.anchor = Vec3(0, -1, 0);
    j.break_force = threshold;
    const JointId jid = w.createJoint(j);
    bool broke = false;
    for (int s = 0; s < 60; ++s) {
      w.step(kH);
      for (const auto& e : w.jointBreakEvents()) {
        broke = true;
        EXPECT_EQ(e.name, "hook");
        EXPECT_GT(e.force, threshold);
      }
    }
    EXPECT_EQ(broke, threshold < 98.1) << threshold;
    EXPECT_EQ(cairn::detail::internals(w).joint(jid).broken, threshold < 98.1);
    if (broke) {
      EXPECT_LT(cairn::detail::internals(w).body(id).position.y(), -2);  // it fell
    }
  }
}

// The feedback is the force the joint puts on its body: over a step,
// force_b = m (dv/h - g) for a body held by that joint alone. A 1 kg
// sphere swings on a ball joint from level, solved by PGS with the
// position bias in the rows' own target (single_pass), so every change
// of its momentum but gravity's passes through the rows' impulses. The
// two sides agree to round-off: 1.3e-13 N at most on loads up to 28 N,
// so 1e-9 of the load leaves room for another compiler's rounding and
// none for a missing impulse. With `baumgarte` they differ by up to 10 N
// at every step (the check fails all 60), as they do with the direct
// solve's position pass: docs/constraints.md, "Breaking".
TEST(JointFeedback, EqualsTheBodysMomentumChangeWhenTheBiasIsInTheRows) {
  World w;
  SolverSettings s;
  s.method = SolverMethod::PGS;
  s.position_correction = Correction::InRhs;
  s.sleeping = false;
  w.setSettings(s);
  const Vec3 anchor(0, 10, 0);
  const BodyId id = w.createBody(test::sphereDef("bob", anchor - Vec3(1, 0, 0), 1, 0.1));
  const JointId jid = w.createJoint(scenarios::joint("pivot", JointType::Ball, kWorldBody, id, anchor));
  Real largest = 0;
  for (int k = 0; k < 60; ++k) {
    const Vec3 v0 = w.linearVelocity(id);
    w.step(kH);
    const Vec3 momentum_force = (w.linearVelocity(id) - v0) / kH - w.gravity();
    const Vec3 feedback = w.jointFeedback(jid).force_b;
    EXPECT_LT((feedback - momentum_force).norm(), 1e-9 * std::max(Real(1), momentum_force.norm())) << "step " << k;
    largest = std::max(largest, feedback.norm());
  }
  // The swing passed its bottom (t = 0.6 s), where the load is about
  // 3 m g: the check saw a joint under its largest load.
  EXPECT_GT(largest, 2.5 * 9.81);
}

// Warm starting: on a hanging chain at rest, PGS with a tolerance exit
// reaches the same residual in fewer sweeps when started from last step's
// impulses than from zero.
TEST(WarmStart, ReachesToleranceInFewerIterations) {
  const auto sweeps = [](bool warm) {
    World w = hangingChain(10, 500);
    SolverSettings s = w.settings();
    s.warm_start = warm;
    s.tolerance = 1e-6;
    w.setSettings(s);
    int total = 0;
    for (int st = 0; st < 120; ++st) {
      w.step(kH);
      if (st >= 60) total += w.lastStepStats().iterations;
    }
    return total;
  };
  const int cold = sweeps(false), warm = sweeps(true);
  EXPECT_LT(warm, cold / 2) << "warm " << warm << " cold " << cold;
}

// Two hinges on the same axis between the same bodies: A is singular.
// With CFM > 0 the solve stays finite and the pendulum still swings right.
TEST(RedundantConstraints, StayFiniteWithCfm) {
  World w;
  SolverSettings s;
  s.cfm = 1e-6;
  w.setSettings(s);
  const BodyId id = w.createBody(test::boxDef("bob", Vec3(1, 0, 0)));
  for (int k = 0; k < 2; ++k) {
    JointDef j;
    j.type = JointType::Hinge;
    j.body_a = kWorldBody;
    j.body_b = id;
    j.axis = Vec3::UnitZ();
    w.createJoint(j);
  }
  for (int st = 0; st < 600; ++st) {
    w.step(kH);
    ASSERT_TRUE(cairn::detail::internals(w).body(id).position.allFinite());
    ASSERT_LT(w.lastStepStats().residual, 1);
  }
  EXPECT_TRUE(w.numericalEvents().empty());
  EXPECT_LT(w.jointError(JointId{0}).linear, 0.05);
  EXPECT_NEAR(cairn::detail::internals(w).body(id).position.norm(), 1, 0.05);
}

// Every joint type runs: rows by kind are as documented, nothing goes NaN.
TEST(JointTypes, EachTypeBuildsItsDocumentedRows) {
  struct Case { JointType t; int rows; };
  for (const Case c : {Case{JointType::Ball, 3}, Case{JointType::Hinge, 5}, Case{JointType::Slider, 5},
                       Case{JointType::Fixed, 6}, Case{JointType::Universal, 4}, Case{JointType::ConeTwist, 3},
                       Case{JointType::Distance, 1}}) {
    World w;
    const BodyId a = w.createBody(test::boxDef("a", Vec3(0, 0, 0)));
    const BodyId b = w.createBody(test::boxDef("b", Vec3(1.5, 0, 0)));
    JointDef j;
    j.type = c.t;
    j.body_a = a;
    j.body_b = b;
    j.anchor = Vec3(0.75, 0, 0);
    j.axis = Vec3::UnitZ();
    j.axis2 = Vec3::UnitX();
    j.anchor_a = Vec3(0.5, 0, 0);
    j.anchor_b = Vec3(1, 0, 0);
    w.createJoint(j);
    w.step(kH);
    EXPECT_EQ(w.lastStepStats().rows, c.rows) << jointTypeName(c.t);
    for (int s = 0; s < 120; ++s) w.step(kH);
    EXPECT_TRUE(w.numericalEvents().empty()) << jointTypeName(c.t);
    // The pair falls freely together; the joint holds.
    EXPECT_LT(w.jointError(JointId{0}).linear, 1e-3) << jointTypeName(c.t);
  }
}

// Cone-twist: a rod hanging from a cone of 0.3 rad, kicked sideways, never
// swings past the cone by more than the limit's ERP slack.
TEST(ConeTwist, SwingStaysInsideTheCone) {
  World w;
  const BodyId id = w.createBody(test::boxDef("arm", Vec3(0, -0.5, 0), 1, Vec3(0.05, 0.5, 0.05)));
  JointDef j;
  j.type = JointType::ConeTwist;
  j.body_a = kWorldBody;
  j.body_b = id;
  j.anchor = Vec3::Zero();
  j.axis = Vec3(0, -1, 0);
  j.swing_span1 = j.swing_span2 = 0.3;
  j.limit.enabled = true;
  j.limit.lower = -0.2;
  j.limit.upper = 0.2;
  const JointId jid = w.createJoint(j);
  w.applyImpulse(id, Vec3(6, 0, 4), Vec3(0, -1, 0));
  Real worst_swing = 0;
  for (int s = 0; s < 300; ++s) {
    w.step(kH);
    const Vec3 dir = (cairn::detail::internals(w).body(id).position).normalized();
    worst_swing = std::max(worst_swing, std::acos(std::clamp(-dir.y(), Real(-1), Real(1))));
  }
  EXPECT_LT(worst_swing, 0.3 + 0.02);
  EXPECT_GT(worst_swing, 0.25);  // it did reach the cone
  EXPECT_LT(w.jointError(jid).linear, 0.01);
}

// Angular motor on three axes spins a free box (listed first) up to the
// target vector.
TEST(AngularMotor, DrivesAllThreeAxesToTarget) {
  World w(Vec3::Zero());
  const BodyId id = w.createBody(test::boxDef("box", Vec3::Zero()));
  JointDef j;
  j.type = JointType::AngularMotor;
  j.body_a = id;
  j.body_b = kWorldBody;
  j.motor_axes = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  j.motor_targets = {1, -2, 0.5};
  j.motor_max_torques = {100, 100, 100};
  w.createJoint(j);
  for (int s = 0; s < 30; ++s) w.step(kH);
  EXPECT_LT((cairn::detail::internals(w).body(id).angular_velocity - Vec3(1, -2, 0.5)).norm(), 1e-6);
}

}  // namespace
}  // namespace cairn
