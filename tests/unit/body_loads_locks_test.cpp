// A body's scripted loads (constant force and torque, timed impulses) and
// its degree-of-freedom locks, from a scene file and from the C++ API,
// against closed forms.
//
// Loads: under semi-implicit Euler (v += h F/m, then x += h v) a constant
// force from rest gives v_n = n h F/m and
//     x_n = x_0 + h sum_{k=1..n} v_k = x_0 + h^2 (F/m) n (n + 1) / 2,
// and a constant torque on a sphere (w x I w = 0) gives w_n = n h tau / I.
// Both are sums of n exact multiples, so they hold to round-off: 1e-12
// relative is ~1e4 ulps, room for the n additions of a few hundred steps.
//
// Locks: a locked axis has a zero row and column in the body's inverse
// mass matrix, so no impulse (contacts, pushes, gravity) ever gives it a
// velocity; positions along it stay equal to the last bit.
#include "cairn/error.hpp"
#include "test_helpers.hpp"
#include "world/scene_json.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace cairn {
namespace {

constexpr Real kH = Real(1) / 60;
constexpr Real kRoundOff = 1e-12;  // relative; see the file comment

// ---------------------------------------------------------------- loads

// A 2 kg ball of radius 0.5 m pushed by a constant force and turned by a
// constant torque, written in a scene file.
const char* kLoadedBall = R"({
  "gravity": [0, 0, 0], "dt": 0.016666666666666666,
  "solver": {"sleeping": false},
  "bodies": [
    {"name": "ball", "mass": 2, "position": [1, 2, 3], "shapes": [{"type": "sphere", "radius": 0.5}],
     "force": [3, -1, 0.5], "torque": [0, 0.2, -0.1],
     "impulses": [{"time": 0.5, "impulse": [0, 0, 4], "point": [1, 2.5, 3]}, {"time": 0.25, "impulse": [1, 0, 0]}]}
  ]
})";

TEST(BodyLoads, ConstantForceFollowsSemiImplicitEulerClosedForm) {
  BodyDef d = test::sphereDef("ball", Vec3(1, 2, 3), 2);
  d.force = Vec3(3, -1, 0.5);
  World w = test::awakeWorld();
  const BodyId id = w.createBody(d);
  const Vec3 x0 = w.centerOfMass(id);
  for (int n = 1; n <= 300; ++n) {
    w.step(kH);
    const Vec3 expect = x0 + kH * kH * (d.force / 2) * (Real(n) * (n + 1) / 2);
    ASSERT_LT((w.centerOfMass(id) - expect).norm(), kRoundOff * expect.norm()) << "step " << n;
    ASSERT_LT((w.linearVelocity(id) - n * kH * d.force / 2).norm(), kRoundOff * n * kH * d.force.norm()) << n;
  }
}

TEST(BodyLoads, ConstantTorqueOnASphereSpinsAtNhTauOverI) {
  BodyDef d = test::sphereDef("ball", Vec3::Zero(), 2);
  d.torque = Vec3(0, 0.2, -0.1);
  World w = test::awakeWorld();
  const BodyId id = w.createBody(d);
  const Real inertia = Real(2) / 5 * 2 * 0.25;  // 2/5 m r^2
  ASSERT_NEAR(w.inertia(id)(0, 0), inertia, kRoundOff);
  for (int n = 1; n <= 300; ++n) {
    w.step(kH);
    const Vec3 expect = n * kH * d.torque / inertia;
    ASSERT_LT((w.angularVelocity(id) - expect).norm(), kRoundOff * expect.norm()) << "step " << n;
  }
}

// An impulse p at point r acts once, at the start of the first step that
// begins at or after its time: v jumps by p/m and w by I^-1 (r - c) x p.
TEST(BodyLoads, TimedImpulsesActOnceAtTheirStep) {
  BodyDef d = test::sphereDef("ball", Vec3::Zero(), 2);
  const Vec3 p(0, 0, 4), r(0, 0.5, 0);
  d.impulses = {{0.5, p, r}, {0.25, Vec3(1, 0, 0), std::nullopt}};  // out of order on purpose
  World w = test::awakeWorld();
  const BodyId id = w.createBody(d);
  const Real inertia = Real(2) / 5 * 2 * 0.25;
  Vec3 v = Vec3::Zero(), omega = Vec3::Zero();
  for (int n = 0; n < 60; ++n) {
    const Real t = n * kH;  // the step's start
    // 0.25 s = step 15 exactly; 0.5 s = step 30 (the clock's round-off is
    // absorbed by the step's start-time tolerance).
    if (n == 15) v += Vec3(1, 0, 0) / 2;
    if (n == 30) {
      v += p / 2;
      omega += (r - w.centerOfMass(id)).cross(p) / inertia;  // the ball has moved since 0.25 s
    }
    w.step(kH);
    ASSERT_LT((w.linearVelocity(id) - v).norm(), kRoundOff) << "t = " << t;
    ASSERT_LT((w.angularVelocity(id) - omega).norm(), kRoundOff) << "t = " << t;
  }
}

// The scene file's force, torque and impulses are BodyDef's: the run is
// the C++ API's, bit for bit.
TEST(BodyLoads, SceneFileKeysAreTheApisFields) {
  const SceneDesc scene = parseScene(kLoadedBall, "loaded.json");
  const BodyDef& b = scene.bodies.at(0);
  EXPECT_EQ(b.force, Vec3(3, -1, 0.5));
  EXPECT_EQ(b.torque, Vec3(0, 0.2, -0.1));
  ASSERT_EQ(b.impulses.size(), 2u);
  EXPECT_EQ(b.impulses[0].point, Vec3(1, 2.5, 3));
  EXPECT_FALSE(b.impulses[1].point.has_value());
  World from_file = buildWorld(scene);

  BodyDef d = test::sphereDef("ball", Vec3(1, 2, 3), 2);
  d.force = b.force;
  d.torque = b.torque;
  d.impulses = {{0.5, Vec3(0, 0, 4), Vec3(1, 2.5, 3)}, {0.25, Vec3(1, 0, 0), std::nullopt}};
  World from_api = test::awakeWorld();
  const BodyId id = from_api.createBody(d);
  const BodyId fid = from_file.findBody("ball");
  for (int n = 0; n < 60; ++n) {
    from_file.step(scene.dt);
    from_api.step(kH);
  }
  EXPECT_EQ(from_file.centerOfMass(fid), from_api.centerOfMass(id));
  EXPECT_EQ(from_file.linearVelocity(fid), from_api.linearVelocity(id));
  EXPECT_EQ(from_file.angularVelocity(fid), from_api.angularVelocity(id));
}

// ---------------------------------------------------------------- locks

// World z of every corner of a box.
std::vector<Real> cornerZ(const World& w, BodyId id, const Vec3& he) {
  std::vector<Real> z;
  const Transform t = w.transform(id);
  for (int k = 0; k < 8; ++k) {
    const Vec3 c((k & 1) ? he.x() : -he.x(), (k & 2) ? he.y() : -he.y(), (k & 4) ? he.z() : -he.z());
    z.push_back(t.apply(c).z());
  }
  return z;
}

// A box on the ground, locked to the x-y plane (no translation along z, no
// rotation about x or y), is struck off-axis: an impulse with a z component
// at an off-center point, then a constant force with a z component, while
// it slides and tumbles on the ground. Its center never leaves z = 0 (the
// locked velocity is exactly zero) and its corners keep their z to
// round-off (it turns about z only).
TEST(DofLocks, BoxPushedOffAxisNeverLeavesItsPlane) {
  const Vec3 he(0.4, 0.25, 0.3);
  World w = test::awakeWorld(Vec3(0, -9.81, 0));
  w.createBody(scenarios::ground());
  BodyDef d = test::boxDef("box", Vec3(0, he.y(), 0), 3, he);
  d.lock_translation = {Vec3::UnitZ()};
  d.lock_rotation = {Vec3::UnitX(), Vec3::UnitY()};
  d.impulses = {{0.1, Vec3(12, 4, -9), Vec3(-0.4, 0.5, 0.3)}};
  d.force = Vec3(0, 0, 30);
  const BodyId id = w.createBody(d);
  const std::vector<Real> z0 = cornerZ(w, id, he);
  for (int n = 0; n < 240; ++n) {
    w.step(kH);
    ASSERT_EQ(w.centerOfMass(id).z(), 0) << "step " << n;
    ASSERT_EQ(w.linearVelocity(id).z(), 0) << "step " << n;
    const std::vector<Real> z = cornerZ(w, id, he);
    for (int k = 0; k < 8; ++k) ASSERT_NEAR(z[k], z0[k], kRoundOff) << "corner " << k << ", step " << n;
  }
  // The push did act in the plane: the box slid along +x.
  EXPECT_GT(w.centerOfMass(id).x(), 0.2);
  EXPECT_TRUE(w.numericalEvents().empty());
}

// A capsule standing on the ground, free to spin about the vertical only,
// is hit at its top by a fast ball. It slides away upright: its axis stays
// vertical to round-off. The same hit without the lock tips it over, so
// the test sees the lock and not a gentle hit.
Real capsuleTiltAfterSideHit(bool locked, Real* slid = nullptr) {
  World w = test::awakeWorld(Vec3(0, -9.81, 0));
  w.createBody(scenarios::ground());
  BodyDef cap = scenarios::solid("capsule", 5, Vec3(0, 0.8, 0), ShapeDesc::capsule(0.2, 0.6));
  if (locked) cap.lock_rotation = {Vec3::UnitX(), Vec3::UnitZ()};
  const BodyId id = w.createBody(cap);
  BodyDef ball = test::sphereDef("ball", Vec3(-1, 1.3, 0.05), 2, 0.15);
  ball.linear_velocity = Vec3(15, 0, 0);
  w.createBody(ball);
  Real tilt = 0;
  for (int n = 0; n < 120; ++n) {
    w.step(kH);
    const Vec3 axis = w.transform(id).q * Vec3::UnitY();
    tilt = std::max(tilt, std::acos(std::clamp(axis.y(), Real(-1), Real(1))));
  }
  if (slid) *slid = w.centerOfMass(id).x();
  return tilt;
}

TEST(DofLocks, LockedRotationCapsuleStaysUprightUnderASideHit) {
  Real slid = 0;
  // acos near 1 turns round-off e into sqrt(2 e): 1e-6 rad is (1e-12)-level
  // round-off in the axis components.
  EXPECT_LT(capsuleTiltAfterSideHit(true, &slid), 1e-6);
  EXPECT_GT(slid, 0.1);  // the hit did land
  EXPECT_GT(capsuleTiltAfterSideHit(false), 0.3);
}

// The lock is solved by the mass matrix, exactly: a box tilted about x
// whose rotation is locked except about world z turns under a torque tau
// about z at w_n = n h tau / I_zz, I_zz the world inertia about z. The
// locks' reaction takes the products of inertia that couple z to x and y
// (the naive projection P I^-1 P would turn it at (I^-1)_zz tau instead,
// four times faster for this rod-like box).
TEST(DofLocks, LockedRotationTurnsAtTorqueOverTheInertiaAboutTheFreeAxis) {
  BodyDef d = test::boxDef("box", Vec3::Zero(), 3, Vec3(0.1, 0.6, 0.1));
  d.orientation = Quat(Eigen::AngleAxis<Real>(0.5, Vec3::UnitX()));
  d.lock_rotation = {Vec3::UnitX(), Vec3::UnitY()};
  d.torque = Vec3(0, 0, 0.4);
  World w = test::awakeWorld();
  const BodyId id = w.createBody(d);
  const Mat3 inertia = w.inertia(id);
  ASSERT_GT(inertia.inverse()(2, 2), 2 / inertia(2, 2));  // the two differ
  for (int n = 1; n <= 120; ++n) {
    w.step(kH);
    const Vec3 omega = w.angularVelocity(id);
    const Real expect = n * kH * 0.4 / inertia(2, 2);
    ASSERT_NEAR(omega.z(), expect, kRoundOff * expect) << "step " << n;
    ASSERT_LT(omega.head<2>().norm(), kRoundOff * expect) << "step " << n;
  }
}

TEST(DofLocks, SceneFileLocksAreTheApisAndBadAxesAreRejected) {
  const char* scene = R"({"bodies": [
    {"name": "puck", "mass": 1, "shapes": [{"type": "sphere", "radius": 0.5}],
     "lock_translation": [[0, 1, 0]], "lock_rotation": [[1, 0, 0], [0, 0, 1]]}]})";
  const SceneDesc s = parseScene(scene, "locks.json");
  EXPECT_EQ(s.bodies[0].lock_translation, std::vector<Vec3>{Vec3::UnitY()});
  EXPECT_EQ(s.bodies[0].lock_rotation, (std::vector<Vec3>{Vec3::UnitX(), Vec3::UnitZ()}));
  const auto errorFor = [&](const std::string& from, const std::string& to) -> std::string {
    std::string text = scene;
    text.replace(text.find(from), from.size(), to);
    try {
      parseScene(text, "locks.json");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  for (const auto& [from, to, field] : {
           std::tuple<std::string, std::string, std::string>{"[[0, 1, 0]]", "[[0, 0, 0]]", "lock_translation[0]"},
           {"[[1, 0, 0], [0, 0, 1]]", "[[1, 0, 0], [0, 0, 0]]", "lock_rotation[1]"},
           {"[[0, 1, 0]]", "[[0, 1, 1]]", "lock_translation[0]"},
           {"[[0, 1, 0]]", "[0, 1, 0]", "lock_translation[0]"},
           {"\"mass\": 1,", "\"mass\": 1, \"impulses\": [{\"impulse\": [1, 0, 0]}],", "impulses[0].time"},
           {"\"mass\": 1,", "\"mass\": 1, \"impulses\": [{\"time\": -1, \"impulse\": [1, 0, 0]}],", "impulses[0].time"},
           {"\"mass\": 1,", "\"mass\": 1, \"force\": [1, 0],", "force"}}) {
    const std::string msg = errorFor(from, to);
    EXPECT_NE(msg.find("locks.json"), std::string::npos) << msg;
    EXPECT_NE(msg.find("body 'puck'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'" + field + "'"), std::string::npos) << field << " not in: " << msg;
  }
}

}  // namespace
}  // namespace cairn
