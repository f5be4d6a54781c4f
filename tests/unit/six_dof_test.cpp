// The six_dof joint: its coordinates name the motion they measure, its rows
// are their exact rates, and each kind of axis (free, limited, locked,
// spring, velocity motor, servo) behaves as its closed form says.
#include "constraints/joint.hpp"
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cairn {
namespace {

constexpr Real kH = Real(1) / 60;

Quat about(Real angle, const Vec3& axis) { return Quat(Eigen::AngleAxis<Real>(angle, axis.normalized())); }

BodyView bodyView(int index, const Vec3& x, const Quat& q) {
  BodyView v;
  v.solver_index = index;
  v.x = x;
  v.q = q.normalized();
  v.rot = v.q.toRotationMatrix();
  v.inv_mass = 1;
  v.inv_inertia = Mat3::Identity();
  return v;
}

// A six_dof between two bodies in general poses, its frame x = axis,
// y = axis2 not the world's.
struct Pair {
  JointDef def;
  Joint joint;
  BodyView a, b;
};

Pair makePair() {
  Pair p;
  p.a = bodyView(1, Vec3(0.3, -0.2, 0.5), about(0.4, Vec3(1, 2, 3)));
  p.b = bodyView(2, Vec3(-0.4, 0.1, 0.2), about(-0.9, Vec3(-2, 1, 1)));
  p.def.type = JointType::SixDof;
  p.def.anchor = Vec3(0.1, 0.05, 0.3);
  p.def.axis = Vec3(0, 1, 0);
  p.def.axis2 = Vec3(0, 0, -1);
  for (DofDef& d : p.def.dofs) d.mode = DofMode::Locked;
  p.joint = makeJoint(p.def, p.a, p.b);
  return p;
}

// Puts a so that its frame sits at `d` (in b's frame) turned by `q` relative
// to b's frame.
void placeA(Pair& p, const Vec3& d, const Quat& q) {
  const Quat qb = p.b.q * p.joint.local_frame_b;
  const Vec3 pb = worldPoint(p.b, p.joint.local_anchor_b);
  p.a.q = (qb * q * p.joint.local_frame_a.conjugate()).normalized();
  p.a.rot = p.a.q.toRotationMatrix();
  p.a.x = pb + qb * d - p.a.q * p.joint.local_anchor_a;
}

// Translations are a's anchor in b's frame; the twist is the angle about x,
// the swings the angles about y and z, each when the others are zero, and
// nearly 90 degrees is no special case.
TEST(SixDof, CoordinatesNameTheMotionTheyMeasure) {
  Pair p = makePair();
  const auto coords = [&](const Vec3& d, const Quat& q) {
    placeA(p, d, q);
    return sixDofCoordinates(p.joint, p.a, p.b);
  };
  std::array<Real, kDofCount> c = coords(Vec3(0.1, -0.2, 0.3), Quat::Identity());
  EXPECT_NEAR(c[0], 0.1, 1e-12);
  EXPECT_NEAR(c[1], -0.2, 1e-12);
  EXPECT_NEAR(c[2], 0.3, 1e-12);
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(c[i], 0, 1e-12);
  for (const Real angle : {0.7, -1.4, 1.5, 2.5}) {
    for (int axis = 0; axis < 3; ++axis) {
      c = coords(Vec3::Zero(), about(angle, Vec3::Unit(axis)));
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(c[i], 0, 1e-12);
        EXPECT_NEAR(c[3 + i], i == axis ? angle : 0, 1e-12) << "angle " << angle << " axis " << axis;
      }
    }
  }
  // Twist after swing: the twist is the innermost rotation.
  c = coords(Vec3::Zero(), about(1.5, Vec3::UnitY()) * about(0.3, Vec3::UnitX()));
  EXPECT_NEAR(c[3], 0.3, 1e-12);
  EXPECT_NEAR(c[4], 1.5, 1e-12);
  EXPECT_NEAR(c[5], 0, 1e-12);
}

// Each row's J v is the time derivative of its coordinate, at general poses
// (swings up to 80 degrees) and velocities: central differences over
// +-1e-5 s agree to O(dt^2) ~ 1e-10 plus round-off 1e-16 / 1e-5; 1e-7
// leaves room for both.
TEST(SixDof, RowsAreTheExactRatesOfTheirCoordinates) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  const auto vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  for (int trial = 0; trial < 20; ++trial) {
    Pair p = makePair();
    placeA(p, 0.2 * vec(), about(1.4 * u(rng), vec()) * about(2 * u(rng), Vec3::UnitX()));
    p.a.v = vec();
    p.a.w = 2 * vec();
    p.b.v = vec();
    p.b.w = 2 * vec();
    std::vector<ConstraintRow> rows;
    const Softness none;
    RowContext ctx;
    ctx.joint_softness = &none;
    ctx.rows = &rows;
    buildSixDofRows(p.joint, p.a, p.b, ctx, JointRowSettings{});
    ASSERT_EQ(rows.size(), 6u);
    const Real dt = 1e-5;
    const auto advanced = [&](Real t) {
      Pair q = p;
      for (BodyView* v : {&q.a, &q.b}) {
        v->x += t * v->v;
        v->q = (quatFromRotationVector(t * v->w) * v->q).normalized();
      }
      return sixDofCoordinates(q.joint, q.a, q.b);
    };
    const std::array<Real, kDofCount> ahead = advanced(dt), behind = advanced(-dt);
    for (const ConstraintRow& r : rows) {
      const int i = r.owner_row;
      const Real jv = r.j_lin_a.dot(p.a.v) + r.j_ang_a.dot(p.a.w) + r.j_lin_b.dot(p.b.v) + r.j_ang_b.dot(p.b.w);
      EXPECT_NEAR(jv, (ahead[i] - behind[i]) / (2 * dt), 1e-7) << "trial " << trial << " " << dofName(i);
    }
  }
}

// Scenes: one box (listed first) on a six_dof to the world, at the box's
// center, its frame the world's, no gravity unless stated.
struct Rig {
  World w{Vec3::Zero()};
  BodyId box;
  JointDef j;
  explicit Rig(const Vec3& gravity = Vec3::Zero(), const Vec3& v0 = Vec3::Zero(), const Vec3& w0 = Vec3::Zero())
      : w(gravity) {
    SolverSettings s;
    s.sleeping = false;  // the motions followed slow below the sleep threshold
    w.setSettings(s);
    BodyDef d = test::boxDef("box", Vec3::Zero(), 1, Vec3(0.25, 0.25, 0.25));
    d.linear_velocity = v0;
    d.angular_velocity = w0;
    box = w.createBody(d);
    j.type = JointType::SixDof;
    j.body_a = box;
    j.body_b = kWorldBody;
    j.axis = Vec3::UnitX();
    j.axis2 = Vec3::UnitY();
    for (DofDef& d : j.dofs) d.mode = DofMode::Locked;
  }
  void create() { w.createJoint(j); }
  void run(int steps) {
    for (int n = 0; n < steps; ++n) w.step(kH);
  }
  Transform pose() const { return w.transform(box); }
};

// The swing-twist coordinates of an orientation relative to the world
// (constraints/six_dof_joint.cpp, with frame = world axes).
std::array<Real, 3> angles(const Quat& q) {
  const Real w = q.w(), x = q.x(), y = q.y(), z = q.z(), d = w * w + x * x;
  return {wrapAngle(2 * std::atan2(x, w)), 2 * std::atan2(w * y - x * z, d), 2 * std::atan2(w * z + x * y, d)};
}

// Solved exactly (the direct solver, ERP in the one solve), an all-locked
// six_dof holds a box hanging off an anchor 0.5 m away under gravity: each
// step's rows are met to round-off, leaving only the tangent drift of
// velocity-level rows, zero for a body at rest.
TEST(SixDof, AllLockedHoldsLikeAWeldWhenSolvedExactly) {
  Rig r(Vec3(0, -9.81, 0));
  SolverSettings s = r.w.settings();
  s.method = SolverMethod::Direct;
  r.w.setSettings(s);
  r.j.anchor = Vec3(-0.5, 0.2, 0.1);
  r.create();
  r.run(120);
  EXPECT_LT(r.pose().p.norm(), 1e-9);
  EXPECT_LT(rotationVectorFromQuat(r.pose().q).norm(), 1e-9);
  EXPECT_LT(r.w.jointError(JointId{0}).linear, 1e-9);
}

// Positive motor targets move the first body positively along and about
// the frame's axes.
TEST(SixDof, MotorsDriveTheFirstBodyRelativeToTheSecond) {
  Rig r;
  r.j.dofs[0].mode = DofMode::Free;
  r.j.dofs[0].motor = MotorDef{true, 0.5, 100, {}, {}};
  r.j.dofs[5].mode = DofMode::Free;
  r.j.dofs[5].motor = MotorDef{true, -1.5, 100, {}, {}};
  r.create();
  r.run(30);
  EXPECT_LT((r.w.linearVelocity(r.box) - Vec3(0.5, 0, 0)).norm(), 1e-9);
  EXPECT_LT((r.w.angularVelocity(r.box) - Vec3(0, 0, -1.5)).norm(), 1e-9);
}

// Limits near 90 degrees: rotation_y in [-0.2, 1.5] (86 degrees), rotation_z
// in [-0.4, 0.4], twist free; the box spun about y and z at once runs into
// both. Euler angles would lock at 90 degrees in the middle axis; the swing
// coordinates hold. The speculative rows stop each coordinate at its bound
// up to the change of the rows' gradients within a step, second order in
// h w: (h w)^2 = 1.3e-3 rad at w = 2.2 rad/s; 2e-3 allows for it.
TEST(SixDof, SwingLimitsHoldNearNinetyDegrees) {
  Rig r(Vec3::Zero(), Vec3::Zero(), Vec3(0, 2, 1));
  r.j.dofs[3].mode = DofMode::Free;
  r.j.dofs[4].mode = DofMode::Limited;
  r.j.dofs[4].limit = LimitDef{true, -0.2, 1.5, 0, {}};
  r.j.dofs[5].mode = DofMode::Limited;
  r.j.dofs[5].limit = LimitDef{true, -0.4, 0.4, 0, {}};
  r.create();
  Real top_y = -1, top_z = -1;
  for (int n = 0; n < 120; ++n) {
    r.w.step(kH);
    const std::array<Real, 3> a = angles(r.pose().q);
    ASSERT_LE(a[1], 1.5 + 2e-3) << n;
    ASSERT_GE(a[1], -0.2 - 2e-3) << n;
    ASSERT_LE(std::abs(a[2]), 0.4 + 2e-3) << n;
    top_y = std::max(top_y, a[1]);
    top_z = std::max(top_z, a[2]);
  }
  EXPECT_GT(top_y, 1.5 - 2e-3);  // it reached both bounds
  EXPECT_GT(top_z, 0.4 - 2e-3);
}

// A spring on a translation (stiffness/damping) and one on a rotation
// (frequency/damping_ratio, k and c from the box's inertia about z, the
// row's effective mass) are the implicit-Euler damped oscillator about
// their rest values, to round-off: every row is decoupled (docs of
// joint_motor_limit_test.cpp).
TEST(SixDof, SpringsAreTheImplicitEulerOscillator) {
  Rig r;
  const Real k = 80, c = 3, f = 1.5, zeta = 0.2;
  r.j.dofs[1].mode = DofMode::Free;
  r.j.dofs[1].spring = DofSpringDef{true, 0.1, {}};
  r.j.dofs[1].spring.softness.stiffness = k;
  r.j.dofs[1].spring.softness.damping = c;
  r.j.dofs[5].mode = DofMode::Free;
  r.j.dofs[5].spring = DofSpringDef{true, -0.6, {}};
  r.j.dofs[5].spring.softness.frequency = f;
  r.j.dofs[5].spring.softness.damping_ratio = zeta;
  r.create();
  const Real omega = 2 * kPi * f;
  Real y = -0.1, vy = 0, a = 0.6, va = 0;
  for (int n = 0; n < 120; ++n) {
    vy = (vy - kH * k * y) / (1 + kH * c + kH * kH * k);  // m = 1 kg
    y += kH * vy;
    va = (va - kH * omega * omega * a) / (1 + kH * 2 * zeta * omega + kH * kH * omega * omega);
    a += kH * va;
    r.w.step(kH);
    ASSERT_NEAR(r.pose().p.y() - 0.1, y, 1e-9) << n;
    ASSERT_NEAR(angles(r.pose().q)[2] + 0.6, a, 1e-9) << n;
  }
}

// A servo on rotation_y with the default softness (2 Hz, critically damped)
// follows the discrete closed form of joint_motor_limit_test.cpp's hinge
// servo: the other rotations' rows have no y component at a pure y swing,
// so the servo row is decoupled here too.
TEST(SixDof, ServoOnASwingAxisIsCriticallyDamped) {
  Rig r;
  r.j.dofs[4].mode = DofMode::Free;
  r.j.dofs[4].motor = MotorDef{true, 0, 1000, 1.2, {}};
  r.create();
  const Real hw = kH * 2 * kPi * 2;
  for (int n = 1; n <= 120; ++n) {
    r.w.step(kH);
    const Real x = -1.2 * (1 + n * hw / (1 + hw)) * std::pow(1 + hw, -n);
    ASSERT_NEAR(angles(r.pose().q)[1] - 1.2, x, 1e-9) << n;
  }
}

// A free axis is free: translation_x and the twist left free carry the
// box's initial velocities unchanged while everything else is locked.
TEST(SixDof, FreeAxesCarryTheirMotion) {
  Rig r(Vec3::Zero(), Vec3(0.7, 0, 0), Vec3(1.3, 0, 0));
  r.j.dofs[0].mode = DofMode::Free;
  r.j.dofs[3].mode = DofMode::Free;
  r.create();
  r.run(60);
  EXPECT_LT((r.w.linearVelocity(r.box) - Vec3(0.7, 0, 0)).norm(), 1e-12);
  EXPECT_LT((r.w.angularVelocity(r.box) - Vec3(1.3, 0, 0)).norm(), 1e-12);
  EXPECT_NEAR(r.pose().p.x(), 0.7, 1e-12);
}

}  // namespace
}  // namespace cairn
