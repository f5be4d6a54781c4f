// The Bullet oracle: it must build every shape and joint cairn has, step
// them sanely, and reproduce what cairn is compared on (free fall, resting
// contact, pendulum period, the settings mapping) — with every tolerance
// explained by Bullet's own behaviour.
#include "collision/hull.hpp"
#include "cairn/error.hpp"
#include "validation/bullet_oracle.hpp"
#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace cairn::validation {
namespace {

constexpr Real kH = Real(1) / 60;
constexpr Real kG = Real(9.81);

SceneDesc emptyScene(const Vec3& gravity = Vec3(0, -kG, 0)) {
  SceneDesc s;
  s.dt = kH;
  s.gravity = gravity;
  return s;
}

BodyDef dynamicBody(const std::string& name, const Vec3& pos, ShapeDesc shape, Real mass = 1) {
  return scenarios::solid(name, mass, pos, std::move(shape));
}

BodyDef box(const std::string& name, const Vec3& pos, Real mass = 1, const Vec3& he = Vec3(0.5, 0.5, 0.5)) {
  return dynamicBody(name, pos, ShapeDesc::box(he), mass);
}

bool finite(const OracleBodyState& s) {
  return s.position.allFinite() && s.orientation.coeffs().allFinite() && s.linear_velocity.allFinite() &&
         s.angular_velocity.allFinite();
}

bool mentions(const std::vector<std::string>& notes, const std::string& text) {
  return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.find(text) != std::string::npos; });
}

// Rotation angle between two orientations (rad).
Real angleBetween(const Quat& a, const Quat& b) { return rotationVectorFromQuat(a.conjugate() * b).norm(); }

// Signed rotation of `q` about `axis` for a rotation that is (nearly) about it.
Real angleAbout(const Quat& q, const Vec3& axis) { return rotationVectorFromQuat(q).dot(axis); }

// Mean period from upward zero crossings of f, linearly interpolated.
template <class F>
Real measurePeriod(BulletOracle& o, int steps, F f) {
  std::vector<Real> crossings;
  Real prev = f(o);
  for (int s = 1; s <= steps; ++s) {
    o.step();
    const Real v = f(o);
    if (prev < 0 && v >= 0) crossings.push_back(s * kH - kH * v / (v - prev));
    prev = v;
  }
  if (crossings.size() < 2) return 0;
  return (crossings.back() - crossings.front()) / Real(crossings.size() - 1);
}

// ------------------------------------------------------------- integration

// Bullet's step with no contact: v += h g inside the solver, then x += h v:
// the same semi-implicit Euler as cairn, so x_n = x0 + n h v0 + h^2 g n(n+1)/2
// holds to round-off (1e-9 m is ~1e5 ulps of the 10 m scale, far above the
// round-off of 60 steps and far below any modelling difference).
TEST(BulletOracle, FreeFallMatchesSemiImplicitEulerExactly) {
  SceneDesc scene = emptyScene();
  BodyDef ball = dynamicBody("ball", Vec3(1, 10, -2), ShapeDesc::sphere(0.5), 2.5);
  const Vec3 v0(0.3, 2, -0.1);
  ball.linear_velocity = v0;
  scene.bodies.push_back(ball);
  BulletOracle oracle(scene);
  const Vec3 x0 = oracle.state(0).position;
  for (int n = 1; n <= 60; ++n) {
    oracle.step();
    const Vec3 expected_x = x0 + n * kH * v0 + kH * kH * scene.gravity * (n * (n + 1) / 2.0);
    const Vec3 expected_v = v0 + n * kH * scene.gravity;
    ASSERT_LT((oracle.state(0).position - expected_x).norm(), 1e-9) << "step " << n;
    ASSERT_LT((oracle.state(0).linear_velocity - expected_v).norm(), 1e-9) << "step " << n;
  }
  EXPECT_EQ(oracle.stepCount(), 60);
  EXPECT_GE(oracle.lastStepSeconds(), 0);
}

// cairn's damping v /= (1 + h c) is mapped to Bullet's v *= (1 - c_b)^h
// with the same per-step factor; with no gravity the order (Bullet damps
// before adding forces) does not matter, so the match is to round-off.
TEST(BulletOracle, DampingMatchesCairnsPerStepFactor) {
  SceneDesc scene = emptyScene(Vec3::Zero());
  BodyDef ball = dynamicBody("ball", Vec3::Zero(), ShapeDesc::sphere(0.5));
  ball.linear_velocity = Vec3(2, 0, 0);
  ball.angular_velocity = Vec3(0, 0, 3);  // a sphere: no gyroscopic term
  ball.linear_damping = 0.5;
  ball.angular_damping = 1.0;
  scene.bodies.push_back(ball);
  BulletOracle oracle(scene);
  for (int n = 0; n < 60; ++n) oracle.step();
  EXPECT_NEAR(oracle.state(0).linear_velocity.x(), 2 / std::pow(1 + kH * 0.5, 60), 1e-12);
  EXPECT_NEAR(oracle.state(0).angular_velocity.z(), 3 / std::pow(1 + kH * 1.0, 60), 1e-12);
  EXPECT_TRUE(mentions(oracle.skipped(), "damping approximated"));
}

// A body's scripted loads reach Bullet as cairn applies them: a constant
// force and a torque on a sphere in zero gravity give x_n = x0 +
// h^2 (F/m) n(n+1)/2 and w_n = n h tau / I (the sphere has no gyroscopic
// term) in both engines, and a timed impulse at 0.5 s lands in the same
// step; a translation lock (Bullet's linear factor) keeps the pushed body
// on its plane. Tolerances as in the free fall above.
TEST(BulletOracle, ScriptedLoadsAndTranslationLocksMatchCairn) {
  SceneDesc scene = emptyScene(Vec3::Zero());
  BodyDef ball = dynamicBody("ball", Vec3(1, 2, 3), ShapeDesc::sphere(0.5), 2);
  ball.force = Vec3(3, -1, 0.5);
  ball.torque = Vec3(0, 0.2, -0.1);
  ball.impulses = {{0.5, Vec3(0, 0, 4), std::nullopt}};
  ball.lock_translation = {Vec3::UnitY()};
  scene.bodies.push_back(ball);
  BulletOracle oracle(scene);
  World world = buildWorld(scene);
  const BodyId id = world.findBody("ball");
  const Real inertia = Real(0.4) * 2 * 0.25;  // 2/5 m r^2
  const Vec3 x0 = oracle.state(0).position;
  const Vec3 a = ball.force.cwiseProduct(Vec3(1, 0, 1)) / 2;  // y locked
  for (int n = 1; n <= 60; ++n) {
    oracle.step();
    world.step(kH);
    // The impulse acts from the step starting at 0.5 s (step 31): its
    // velocity p/m has moved the ball for n - 30 steps.
    const Vec3 kick = n > 30 ? Vec3((n - 30) * kH * ball.impulses[0].impulse / 2) : Vec3::Zero();
    const Vec3 expected_x = x0 + kH * kH * a * (n * (n + 1) / 2.0) + kick;
    ASSERT_LT((oracle.state(0).position - expected_x).norm(), 1e-9) << "step " << n;
    ASSERT_LT((world.centerOfMass(id) - expected_x).norm(), 1e-9) << "step " << n;
    ASSERT_LT((oracle.state(0).angular_velocity - n * kH * ball.torque / inertia).norm(), 1e-9) << "step " << n;
  }
}

// A body whose inertia is not diagonal in its own frame: Bullet gets it in
// principal axes and state() must undo that rotation. The initial state is
// cairn's (center of mass, orientation) to round-off, and a spin about a
// principal axis stays steady (w x Jw = 0, so any gyroscopic treatment leaves
// it alone) while the orientation follows exp(n h w) q0; a wrong principal
// frame would make the spin precess at once.
TEST(BulletOracle, PrincipalFrameOfAnOffsetCompoundIsUndone) {
  SceneDesc scene = emptyScene(Vec3::Zero());
  BodyDef body;
  body.name = "lopsided";
  body.mass = 3;
  body.position = Vec3(1, 2, 3);
  body.orientation = Quat(Eigen::AngleAxis<Real>(0.4, Vec3(1, 2, 0.5).normalized()));
  ShapeDesc rod = ShapeDesc::box(Vec3(0.8, 0.1, 0.15));
  rod.local.p = Vec3(0.3, 0.2, 0);
  rod.local.q = Quat(Eigen::AngleAxis<Real>(0.6, Vec3::UnitZ()));
  ShapeDesc knob = ShapeDesc::sphere(0.3);
  knob.local.p = Vec3(-0.5, 0, 0.4);
  body.shapes = {rod, knob};
  scene.bodies.push_back(body);

  const World reference = buildWorld(scene);
  const Body& cb = cairn::detail::internals(reference).bodies()[0];
  ASSERT_GT(std::abs(cb.inertia_body(0, 1)), 1e-3);  // really not diagonal

  BulletOracle oracle(scene);
  EXPECT_LT((oracle.state(0).position - cb.position).norm(), 1e-12);
  EXPECT_LT(angleBetween(oracle.state(0).orientation, cb.orientation), 1e-12);

  // Spin about the principal axis with the largest moment, in world terms.
  Eigen::SelfAdjointEigenSolver<Mat3> es(cb.inertia_body);
  const Vec3 w = 3 * (cb.orientation * es.eigenvectors().col(2)).normalized();
  scene.bodies[0].angular_velocity = w;
  BulletOracle spinning(scene);
  for (int n = 0; n < 60; ++n) spinning.step();
  EXPECT_LT((spinning.state(0).angular_velocity - w).norm(), 1e-9);
  const Quat expected = quatFromRotationVector(60 * kH * w) * cb.orientation;
  EXPECT_LT(angleBetween(spinning.state(0).orientation, expected), 1e-9);
  EXPECT_LT((spinning.state(0).position - cb.position).norm(), 1e-9);  // it spins about its center of mass
}

// A kinematic body moves by its scripted velocity exactly as cairn moves it
// (x += h v, q <- exp(h w) q), and a dynamic box resting on a kinematic
// platform is carried along by friction (mu = 0.5 needs only 0.5 g of the
// tangential pull, and the platform does not accelerate).
TEST(BulletOracle, KinematicBodyFollowsItsScriptedVelocity) {
  SceneDesc scene = emptyScene();
  BodyDef platform = box("platform", Vec3(0, -0.5, 0), 1, Vec3(5, 0.5, 5));
  platform.type = BodyType::Kinematic;
  platform.mass.reset();
  platform.linear_velocity = Vec3(0.5, 0, 0);
  scene.bodies.push_back(platform);
  BodyDef spinner = box("spinner", Vec3(0, 5, 20), 1);
  spinner.type = BodyType::Kinematic;
  spinner.mass.reset();
  spinner.linear_velocity = Vec3(1, 0, 0);
  spinner.angular_velocity = Vec3(0, 0.5, 0.2);
  scene.bodies.push_back(spinner);
  BodyDef crate = box("crate", Vec3(0, 0.5, 0));
  crate.linear_velocity = Vec3(0.5, 0, 0);
  scene.bodies.push_back(crate);

  BulletOracle oracle(scene);
  Vec3 x = oracle.state(1).position;
  Quat q = oracle.state(1).orientation;
  for (int n = 0; n < 90; ++n) {
    oracle.step();
    x += kH * spinner.linear_velocity;
    q = (quatFromRotationVector(kH * spinner.angular_velocity) * q).normalized();
  }
  EXPECT_LT((oracle.state(1).position - x).norm(), 1e-12);
  EXPECT_LT(angleBetween(oracle.state(1).orientation, q), 1e-12);
  EXPECT_EQ(oracle.state(1).linear_velocity, spinner.linear_velocity);
  EXPECT_NEAR(oracle.state(0).position.x(), 90 * kH * 0.5, 1e-12);
  // Carried: same speed as the platform, still on top of it.
  EXPECT_NEAR(oracle.state(2).linear_velocity.x(), 0.5, 0.02);
  EXPECT_NEAR(oracle.state(2).position.x() - oracle.state(0).position.x(), 0, 0.02);
  EXPECT_NEAR(oracle.state(2).position.y(), 0.5, 0.02);
}

// ------------------------------------------------------------------ shapes

std::shared_ptr<const ConvexHullData> octahedron(Real r) {
  return buildConvexHull({Vec3(r, 0, 0), Vec3(-r, 0, 0), Vec3(0, r, 0), Vec3(0, -r, 0), Vec3(0, 0, r), Vec3(0, 0, -r)});
}

// Every shape type, dropped on a static plane (and one on a static triangle
// mesh): after 2 s all rest on their supports. Bullet's contacts act within
// a margin and settle a little into the ground; 2 cm covers that and the
// rounding of box, cylinder and hull edges (0.04 m margins).
TEST(BulletOracle, EveryShapeTypeBuildsAndComesToRest) {
  SceneDesc scene = emptyScene();
  BodyDef ground;
  ground.name = "ground";
  ground.type = BodyType::Static;
  ground.shapes.push_back(ShapeDesc::plane(Vec3(0, 2, 0), 0));  // not unit: normalized by the oracle
  scene.bodies.push_back(ground);

  auto mesh = std::make_shared<TriangleMeshData>();
  mesh->vertices = {Vec3(-2, 0, -2), Vec3(2, 0, -2), Vec3(2, 0, 2), Vec3(-2, 0, 2)};
  mesh->triangles = {{0, 2, 1}, {0, 3, 2}};
  BodyDef table;
  table.name = "table";
  table.type = BodyType::Static;
  table.position = Vec3(20, 1, 0);
  ShapeDesc mesh_shape;
  mesh_shape.type = ShapeType::Mesh;
  mesh_shape.mesh = mesh;
  table.shapes.push_back(mesh_shape);
  scene.bodies.push_back(table);

  // Expected resting height of each body's center of mass.
  struct Drop {
    BodyDef def;
    Real rest_y;
  };
  std::vector<Drop> drops;
  drops.push_back({dynamicBody("sphere", Vec3(0, 1.5, 0), ShapeDesc::sphere(0.4)), 0.4});
  drops.push_back({dynamicBody("box", Vec3(3, 1.5, 0), ShapeDesc::box(Vec3(0.5, 0.3, 0.4))), 0.3});
  drops.push_back({dynamicBody("capsule", Vec3(6, 1.5, 0), ShapeDesc::capsule(0.3, 0.5)), 0.3});
  drops.back().def.orientation = Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ()));  // lying down
  drops.push_back({dynamicBody("cylinder", Vec3(9, 1.5, 0), ShapeDesc::cylinder(0.4, 0.3)), 0.3});  // upright
  ShapeDesc hull;
  hull.type = ShapeType::ConvexHull;
  hull.hull = octahedron(0.6);
  BodyDef hull_body = dynamicBody("hull", Vec3(12, 1.5, 0), hull);
  // Resting on a face: rotate so a face normal (1,1,1)/sqrt(3) points down.
  hull_body.orientation = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), -Vec3::UnitY());
  drops.push_back({hull_body, 0.6 / std::sqrt(3.0)});
  BodyDef dumbbell;
  dumbbell.name = "dumbbell";
  dumbbell.mass = 2;
  dumbbell.position = Vec3(15, 1.5, 0);
  ShapeDesc left = ShapeDesc::sphere(0.3), right = ShapeDesc::sphere(0.3), bar = ShapeDesc::box(Vec3(0.5, 0.1, 0.1));
  left.local.p = Vec3(-0.6, 0, 0);
  right.local.p = Vec3(0.6, 0, 0);
  dumbbell.shapes = {left, right, bar};
  drops.push_back({dumbbell, 0.3});
  drops.push_back({dynamicBody("on_mesh", Vec3(20, 2.5, 0), ShapeDesc::sphere(0.5)), 1.5});
  for (const auto& d : drops) scene.bodies.push_back(d.def);

  BulletOracle oracle(scene);
  ASSERT_EQ(oracle.bodyCount(), static_cast<int>(scene.bodies.size()));
  for (int n = 0; n < 120; ++n) oracle.step();
  for (size_t k = 0; k < drops.size(); ++k) {
    const OracleBodyState s = oracle.state(static_cast<int>(k) + 2);
    SCOPED_TRACE(drops[k].def.name);
    ASSERT_TRUE(finite(s));
    EXPECT_NEAR(s.position.y(), drops[k].rest_y, 0.02);
    EXPECT_LT(s.linear_velocity.norm(), 0.05);
  }
  // Static bodies report their pose and never move.
  EXPECT_EQ(oracle.state(1).position, Vec3(20, 1, 0));
  EXPECT_EQ(oracle.state(1).linear_velocity, Vec3::Zero());
  EXPECT_TRUE(mentions(oracle.skipped(), "two-sided"));
}

// The standard one-box column: a 1 m cube at y = 0.5 on the static ground
// box. Bullet creates its contacts within a small gap and its box edges are
// rounded (0.04 m margin inside the size), so the box sits within a few mm
// of 0.5; it must not sink, drift or tip over 2 s.
TEST(BulletOracle, BoxRestsOnTheGround) {
  BulletOracle oracle(scenarios::column(1));
  for (int n = 0; n < 120; ++n) {
    oracle.step();
    const OracleBodyState s = oracle.state(1);
    ASSERT_NEAR(s.position.y(), 0.5, 0.02) << "step " << n;
  }
  const OracleBodyState s = oracle.state(1);
  EXPECT_LT(std::abs(s.position.x()) + std::abs(s.position.z()), 1e-3);
  EXPECT_LT(s.linear_velocity.norm(), 0.01);
  EXPECT_LT(angleBetween(s.orientation, Quat::Identity()), 1e-3);
}

// cairn combines friction by the geometric mean: a box of mu = 0.25 sliding
// at 3 m/s on ground of mu = 1 stops after v^2 / (2 mu g) = 0.917 m with
// mu = 0.5, where Bullet's product (0.25) would take 1.83 m. 5 cm allows for
// the first contact steps and the friction pyramid of two directions.
TEST(BulletOracle, FrictionCombinesAsCairnsGeometricMean) {
  SceneDesc scene = scenarios::column(1);
  scene.bodies[0].friction = 1.0;
  scene.bodies[1].friction = 0.25;
  scene.bodies[1].linear_velocity = Vec3(3, 0, 0);
  const Real expected = 9 / (2 * 0.5 * kG);
  for (bool match : {true, false}) {
    BulletOracle oracle(scene, OracleOptions{match});
    for (int n = 0; n < 120; ++n) oracle.step();
    const Real distance = oracle.state(1).position.x();
    EXPECT_LT(oracle.state(1).linear_velocity.norm(), 1e-3);
    if (match) {
      EXPECT_NEAR(distance, expected, 0.05);
    } else {
      EXPECT_NEAR(distance, 9 / (2 * 0.25 * kG), 0.1);  // Bullet's own product rule
    }
  }
}

// cairn combines restitution by the maximum: a ball of e = 0.8 dropped from
// 2 m on ground of e = 0 bounces (Bullet's product would give 0). Ideal
// rebound height e^2 2 m = 1.28 m; Bullet's speculative contact subtracts
// the remaining gap from the target velocity at impact, which eats some of
// it, so accept 0.9 to 1.4 m.
TEST(BulletOracle, RestitutionCombinesAsCairnsMaximum) {
  SceneDesc scene = scenarios::column(1);
  scene.bodies[1] = dynamicBody("ball", Vec3(0, 2.5, 0), ShapeDesc::sphere(0.5));
  scene.bodies[1].restitution = 0.8;
  BulletOracle oracle(scene);
  Real top = 0;
  bool bounced = false;
  for (int n = 0; n < 150; ++n) {
    oracle.step();
    const OracleBodyState s = oracle.state(1);
    if (s.linear_velocity.y() > 0) bounced = true;
    if (bounced) top = std::max(top, s.position.y() - 0.5);
  }
  EXPECT_TRUE(bounced);
  EXPECT_GT(top, 0.9);
  EXPECT_LT(top, 1.4);
}

// Collision groups and masks reach Bullet: a box whose mask excludes the
// ground's group falls through it.
TEST(BulletOracle, CollisionMaskLetsABodyFallThrough) {
  SceneDesc scene = scenarios::column(1);
  scene.bodies[1].collision_mask = ~1u;  // the ground is in group 1
  BulletOracle oracle(scene);
  for (int n = 0; n < 60; ++n) oracle.step();
  EXPECT_LT(oracle.state(1).position.y(), -3);
}

// ------------------------------------------------------------------ joints

// The standard hinge pendulum released from 0.1 rad: the period of the
// small-amplitude cube pendulum is 2.168155 s (docs/scenarios.md). Semi-implicit
// Euler at h = 1/60 and Bullet's Baumgarte pivot correction move it by a
// fraction of a percent; 2% is the bar set for cairn too.
TEST(BulletOracle, HingePendulumPeriodMatchesTheExactPeriod) {
  BulletOracle oracle(scenarios::hingePendulum(0.1));
  Real max_drift = 0;
  const Real period = measurePeriod(oracle, 600, [&](BulletOracle& o) {
    max_drift = std::max(max_drift, o.jointAnchorSeparation(0).norm());
    const Vec3 x = o.state(0).position;
    return std::atan2(x.x(), -x.y());
  });
  EXPECT_NEAR(period, 2.168155, 0.02 * 2.168155);
  EXPECT_LT(max_drift, 1e-3);  // the pivot holds
}

TEST(BulletOracle, HingePendulumLargeAmplitudePeriod) {
  BulletOracle oracle(scenarios::hingePendulum(1.5));
  const Real period = measurePeriod(oracle, 600, [](BulletOracle& o) {
    const Vec3 x = o.state(0).position;
    return std::atan2(x.x(), -x.y());
  });
  EXPECT_NEAR(period, 2.517753, 0.02 * 2.517753);
}

// The standard ball chain released horizontally: 60 steps stay finite and
// the chain holds together. Bullet never warm-starts joint rows, so with 10
// iterations the 20-link chain stretches while it falls (about 0.6 m at the
// worst joint after 1 s, 2.4 m summed: Bullet's own result, the same with
// match_cairn off); more iterations close the joints, which shows the
// stretch is convergence and not the mapping.
TEST(BulletOracle, BallChainStaysFiniteAndTightensWithIterations) {
  const auto worstSeparation = [](int iterations) {
    SceneDesc scene = scenarios::chain(20);
    scene.solver.iterations = iterations;
    BulletOracle oracle(scene);
    Real worst = 0;
    for (int n = 0; n < 60; ++n) {
      oracle.step();
      for (int j = 0; j < static_cast<int>(scene.joints.size()); ++j)
        worst = std::max(worst, oracle.jointAnchorSeparation(j).norm());
    }
    for (int i = 0; i < oracle.bodyCount(); ++i) EXPECT_TRUE(finite(oracle.state(i))) << i;
    EXPECT_LT(oracle.state(19).position.y(), -4);  // the tip fell
    return worst;
  };
  EXPECT_LT(worstSeparation(10), 1.0);
  EXPECT_LT(worstSeparation(200), 0.1);
}

// One joint of every type, each holding a box under gravity (most to the
// world, two between bodies): after 1 s everything is finite and the joints
// hold their anchors to a few mm (10 PGS iterations, no joint warm start).
TEST(BulletOracle, EveryJointTypeBuildsAndHolds) {
  SceneDesc scene = emptyScene();
  const auto add = [&](const std::string& name, const Vec3& pos) {
    scene.bodies.push_back(box(name, pos, 1, Vec3(0.2, 0.2, 0.2)));
    return BodyId{static_cast<std::int32_t>(scene.bodies.size() - 1)};
  };
  const auto joint = [&](JointType type, const std::string& name, BodyId a, BodyId b, const Vec3& anchor) {
    scene.joints.push_back(scenarios::joint(name, type, a, b, anchor));
    return &scene.joints.back();
  };
  joint(JointType::Ball, "ball", kWorldBody, add("b0", Vec3(0, -0.5, 0)), Vec3(0.3, 0, 0));
  joint(JointType::Hinge, "hinge", kWorldBody, add("b1", Vec3(3, -0.5, 0)), Vec3(3, 0, 0));
  JointDef* slider = joint(JointType::Slider, "slider", kWorldBody, add("b2", Vec3(6, 0, 0)), Vec3(6, 0, 0));
  slider->axis = Vec3(0, 1, 0);
  slider->limit.enabled = true;
  slider->limit.lower = -0.3;
  slider->limit.upper = 0.3;
  joint(JointType::Fixed, "fixed", kWorldBody, add("b3", Vec3(9, 0, 0)), Vec3(9.5, 0, 0));
  const BodyId u = add("b4", Vec3(12, -0.5, 0));
  JointDef* universal = joint(JointType::Universal, "universal", kWorldBody, u, Vec3(12, 0, 0));
  universal->axis = Vec3(1, 0, 0);
  universal->axis2 = Vec3(0, 0, 1);
  JointDef* cone = joint(JointType::ConeTwist, "cone", u, add("b5", Vec3(12, -1.2, 0)), Vec3(12, -0.8, 0));
  cone->axis = Vec3(0, -1, 0);
  cone->swing_span1 = cone->swing_span2 = 0.5;
  JointDef* distance = joint(JointType::Distance, "distance", kWorldBody, add("b6", Vec3(15, -1, 0)), Vec3::Zero());
  distance->anchor_a = Vec3(15.4, 0, 0);
  distance->anchor_b = Vec3(15, -0.8, 0);
  const BodyId spinner = add("b7", Vec3(18, 0, 0));
  JointDef* hold = joint(JointType::Ball, "hold", kWorldBody, spinner, Vec3(18, 0, 0));
  (void)hold;
  JointDef* motor = joint(JointType::AngularMotor, "motor", spinner, kWorldBody, Vec3::Zero());
  motor->motor_axes = {Vec3(0, 0, 1)};
  motor->motor_targets = {1};
  motor->motor_max_torques = {10};

  BulletOracle oracle(scene);
  for (int n = 0; n < 60; ++n) oracle.step();
  for (int i = 0; i < oracle.bodyCount(); ++i) ASSERT_TRUE(finite(oracle.state(i))) << scene.bodies[i].name;
  for (int j = 0; j < static_cast<int>(scene.joints.size()); ++j) {
    SCOPED_TRACE(scene.joints[j].name);
    EXPECT_TRUE(oracle.jointActive(j));
    EXPECT_LT(oracle.jointAnchorSeparation(j).norm(), 5e-3);
  }
  // The slider's limit holds the box at -0.3 (0.01 for Baumgarte at the stop).
  EXPECT_NEAR(oracle.state(2).position.y(), -0.3, 0.01);
  // The fixed joint holds its box in place.
  EXPECT_LT((oracle.state(3).position - Vec3(9, 0, 0)).norm(), 0.01);
  // The motor spins its box at the target.
  EXPECT_NEAR(oracle.state(7).angular_velocity.z(), 1, 1e-3);
  EXPECT_TRUE(mentions(oracle.skipped(), "joint 'motor' (angular_motor): 1 axis mapped to btGeneric6DofSpring2Constraint"));
  EXPECT_TRUE(mentions(oracle.skipped(), "joint 'distance' (distance): Bullet has no distance joint"));
}

// Sign conventions: cairn's motors drive the rate of a (the first body)
// relative to b about (along) +axis, as ODE's and Bullet's do. With no
// gravity and the anchor at the center of mass the motor row is decoupled
// from the others, so the body reaches the target to the solver's
// precision within one step. The last hinge lists the world first: the
// body then turns at -target.
TEST(BulletOracle, MotorsDriveTheFirstBodyRelativeToTheSecond) {
  SceneDesc scene = emptyScene(Vec3::Zero());
  scene.bodies.push_back(box("hinged", Vec3(0, 0, 0)));
  scene.bodies.push_back(box("sliding", Vec3(5, 0, 0)));
  scene.bodies.push_back(box("spun", Vec3(10, 0, 0)));
  scene.bodies.push_back(box("rolled", Vec3(15, 0, 0)));
  scene.bodies.push_back(box("second", Vec3(20, 0, 0)));
  JointDef hinge;
  hinge.name = "hinge";
  hinge.type = JointType::Hinge;
  hinge.body_a = BodyId{0};
  hinge.body_b = kWorldBody;
  hinge.axis = Vec3(0, 0, 1);
  hinge.motor = MotorDef{true, 2, 100, {}, {}};
  JointDef slider;
  slider.name = "slider";
  slider.type = JointType::Slider;
  slider.body_a = BodyId{1};
  slider.body_b = kWorldBody;
  slider.anchor = Vec3(5, 0, 0);
  slider.axis = Vec3(1, 0, 0);
  slider.motor = MotorDef{true, 0.5, 100, {}, {}};
  // Angular motors: one axis, and two axes of which only the first turns
  // (the second holds zero), so that the body turns about the motor axes
  // and Bullet's Euler axes stay on cairn's.
  JointDef spin;
  spin.name = "spin";
  spin.type = JointType::AngularMotor;
  spin.body_a = BodyId{2};
  spin.body_b = kWorldBody;
  spin.motor_axes = {Vec3(0, 1, 0)};
  spin.motor_targets = {1.5};
  spin.motor_max_torques = {100};
  JointDef roll = spin;
  roll.name = "roll";
  roll.body_a = BodyId{3};
  roll.motor_axes = {Vec3(1, 0, 0), Vec3(0, 0, -1)};
  roll.motor_targets = {-0.5, 0};
  roll.motor_max_torques = {100, 100};
  JointDef reversed = hinge;
  reversed.name = "reversed";
  reversed.body_a = kWorldBody;
  reversed.body_b = BodyId{4};
  reversed.anchor = Vec3(20, 0, 0);
  scene.joints = {hinge, slider, spin, roll, reversed};
  BulletOracle oracle(scene);
  for (int n = 0; n < 30; ++n) oracle.step();
  EXPECT_NEAR(oracle.state(0).angular_velocity.z(), 2, 1e-6);
  EXPECT_NEAR(oracle.state(1).linear_velocity.x(), 0.5, 1e-6);
  EXPECT_LT((oracle.state(2).angular_velocity - Vec3(0, 1.5, 0)).norm(), 1e-6);
  EXPECT_LT((oracle.state(3).angular_velocity - Vec3(-0.5, 0, 0)).norm(), 1e-6);
  EXPECT_NEAR(oracle.state(4).angular_velocity.z(), -2, 1e-6);
}

// Limits in cairn's terms: the hinge angle of the body (listed first) about
// +axis within [-0.2, 0.3]; the cone-twist twist within the asymmetric
// [-0.1, 0.4], which Bullet can only express as a symmetric span about a
// turned frame; the slider travel within [-0.25, 0.15]. Each body is thrown
// against its stops with no gravity; Bullet's limit rows engage only past
// the stop, so allow one step of travel (1 rad/s or m/s x h) plus Baumgarte
// slack: 0.03.
TEST(BulletOracle, LimitsHoldCairnsRanges) {
  for (const Real w : {1.0, -1.0}) {
    SceneDesc scene = emptyScene(Vec3::Zero());
    BodyDef hinged = box("hinged", Vec3::Zero());
    hinged.angular_velocity = Vec3(0, 0, w);
    BodyDef twisted = box("twisted", Vec3(5, 0, 0));
    twisted.angular_velocity = Vec3(w, 0, 0);
    BodyDef slid = box("slid", Vec3(10, 0, 0));
    slid.linear_velocity = Vec3(w, 0, 0);
    scene.bodies = {hinged, twisted, slid};
    const auto limited = [](JointType type, int body, const Vec3& anchor, const Vec3& axis, Real lower, Real upper) {
      JointDef j;
      j.name = jointTypeName(type);
      j.type = type;
      j.body_a = BodyId{body};
      j.body_b = kWorldBody;
      j.anchor = anchor;
      j.axis = axis;
      j.limit = LimitDef{true, lower, upper, 0, {}};
      return j;
    };
    const JointDef hinge = limited(JointType::Hinge, 0, Vec3::Zero(), Vec3::UnitZ(), -0.2, 0.3);
    const JointDef cone = limited(JointType::ConeTwist, 1, Vec3(5, 0, 0), Vec3::UnitX(), -0.1, 0.4);
    const JointDef slider = limited(JointType::Slider, 2, Vec3(10, 0, 0), Vec3::UnitX(), -0.25, 0.15);
    scene.joints = {hinge, cone, slider};
    BulletOracle oracle(scene);
    Real lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int n = 0; n < 90; ++n) {
      oracle.step();
      const Real c[3] = {angleAbout(oracle.state(0).orientation, Vec3::UnitZ()),
                         angleAbout(oracle.state(1).orientation, Vec3::UnitX()), oracle.state(2).position.x() - 10};
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], c[k]);
        hi[k] = std::max(hi[k], c[k]);
      }
    }
    SCOPED_TRACE(w);
    if (w > 0) {
      EXPECT_NEAR(hi[0], 0.3, 0.03);
      EXPECT_NEAR(hi[1], 0.4, 0.03);
      EXPECT_NEAR(hi[2], 0.15, 0.03);
    } else {
      EXPECT_NEAR(lo[0], -0.2, 0.03);
      EXPECT_NEAR(lo[1], -0.1, 0.03);
      EXPECT_NEAR(lo[2], -0.25, 0.03);
    }
  }
}

// six_dof in cairn's terms on Bullet's 6-dof-2 (built with the bodies
// swapped, bullet_six_dof.cpp): each cube is listed first, its frame the
// world's axes, everything locked but the axes under test.
//  - velocity motors on translation x and the twist drive the cube at
//    +0.5 m/s and +1 rad/s (decoupled rows: to the solver's precision);
//  - limits translation y in [-0.25, 0.15], rotation z in [-0.2, 0.3] stop
//    a cube thrown at +-1 m/s and rad/s at the bound it heads for: 6-dof-2
//    sets a limit row's target to the bounce, 0 here, once the joint would
//    cross within the step, so it stops up to a step's travel short
//    (h x 1 = 0.017; 0.02);
//  - springs toward rest points 0.1 m (translation y, under gravity) and
//    0.3 rad (rotation z) settle where cairn's do: rest - m g / k and 0.3
//    (damped 3 s; 1e-3).
TEST(BulletOracle, SixDofAxesFollowCairnsSigns) {
  const auto cube = [](const std::string& name, const Vec3& p, const Vec3& v, const Vec3& w) {
    BodyDef b = box(name, p, 1, Vec3(0.2, 0.2, 0.2));
    b.linear_velocity = v;
    b.angular_velocity = w;
    return b;
  };
  const auto six = [](const std::string& name, int body, const Vec3& anchor) {
    JointDef j;
    j.name = name;
    j.type = JointType::SixDof;
    j.body_a = BodyId{body};
    j.body_b = kWorldBody;
    j.anchor = anchor;
    j.axis = Vec3::UnitX();
    j.axis2 = Vec3::UnitY();
    for (DofDef& d : j.dofs) d.mode = DofMode::Locked;
    return j;
  };
  {
    SceneDesc scene = emptyScene(Vec3::Zero());
    scene.bodies = {cube("driven", Vec3::Zero(), Vec3::Zero(), Vec3::Zero())};
    JointDef j = six("motors", 0, Vec3::Zero());
    j.dofs[0] = DofDef{DofMode::Free, {}, {}, MotorDef{true, 0.5, 100, {}, {}}};
    j.dofs[3] = DofDef{DofMode::Free, {}, {}, MotorDef{true, 1, 100, {}, {}}};
    scene.joints = {j};
    BulletOracle oracle(scene);
    for (int n = 0; n < 30; ++n) oracle.step();
    EXPECT_LT((oracle.state(0).linear_velocity - Vec3(0.5, 0, 0)).norm(), 1e-6);
    EXPECT_LT((oracle.state(0).angular_velocity - Vec3(1, 0, 0)).norm(), 1e-6);
  }
  for (const Real dir : {1.0, -1.0}) {
    SCOPED_TRACE(dir);
    SceneDesc scene = emptyScene(Vec3::Zero());
    scene.bodies = {cube("slid", Vec3::Zero(), Vec3(0, dir, 0), Vec3::Zero()),
                    cube("turned", Vec3(3, 0, 0), Vec3::Zero(), Vec3(0, 0, dir))};
    JointDef slid = six("slid", 0, Vec3::Zero());
    slid.dofs[1].mode = DofMode::Limited;
    slid.dofs[1].limit = LimitDef{true, -0.25, 0.15, 0, {}};
    JointDef turned = six("turned", 1, Vec3(3, 0, 0));
    turned.dofs[5].mode = DofMode::Limited;
    turned.dofs[5].limit = LimitDef{true, -0.2, 0.3, 0, {}};
    scene.joints = {slid, turned};
    BulletOracle oracle(scene);
    for (int n = 0; n < 60; ++n) oracle.step();
    EXPECT_NEAR(oracle.state(0).position.y(), dir > 0 ? 0.15 : -0.25, 0.02);
    EXPECT_NEAR(angleAbout(oracle.state(1).orientation, Vec3::UnitZ()), dir > 0 ? 0.3 : -0.2, 0.02);
  }
  {
    SceneDesc scene = emptyScene();
    scene.bodies = {cube("hung", Vec3::Zero(), Vec3::Zero(), Vec3::Zero()),
                    cube("wound", Vec3(3, 0, 0), Vec3::Zero(), Vec3::Zero())};
    const Real k = 100;
    JointDef hung = six("hung", 0, Vec3::Zero());
    hung.dofs[1].mode = DofMode::Free;
    hung.dofs[1].spring = DofSpringDef{true, 0.1, {}};
    hung.dofs[1].spring.softness.stiffness = k;
    hung.dofs[1].spring.softness.damping = 10;
    JointDef wound = six("wound", 1, Vec3(3, 0, 0));
    wound.dofs[5].mode = DofMode::Free;
    wound.dofs[5].spring = DofSpringDef{true, 0.3, {}};
    wound.dofs[5].spring.softness.stiffness = 2;
    wound.dofs[5].spring.softness.damping = 0.2;
    scene.joints = {hung, wound};
    BulletOracle oracle(scene);
    for (int n = 0; n < 180; ++n) oracle.step();
    EXPECT_NEAR(oracle.state(0).position.y(), 0.1 - kG / k, 1e-3);
    EXPECT_NEAR(angleAbout(oracle.state(1).orientation, Vec3::UnitZ()), 0.3, 1e-3);
  }
}

// The elliptical cone in cairn's frame: swing_span1 bounds the tilt of the
// twist axis toward the joint's reference axis anyPerpendicular(axis) (z
// for the x axis), swing_span2 the tilt toward axis x reference (-y). Each
// cube (no gyroscopic coupling) is spun so that its x axis tilts one way;
// 0.03 rad covers one step of travel past the cone, as for the limits above.
TEST(BulletOracle, ConeSwingSpansFollowCairnsReferenceAxis) {
  SceneDesc scene = emptyScene(Vec3::Zero());
  BodyDef toward_z = box("toward_z", Vec3::Zero());
  toward_z.angular_velocity = Vec3(0, 1, 0);  // x turns toward -z
  BodyDef toward_y = box("toward_y", Vec3(5, 0, 0));
  toward_y.angular_velocity = Vec3(0, 0, 1);  // x turns toward +y
  scene.bodies = {toward_z, toward_y};
  for (int i = 0; i < 2; ++i) {
    JointDef cone;
    cone.name = "cone" + std::to_string(i);
    cone.type = JointType::ConeTwist;
    cone.body_b = BodyId{i};
    cone.anchor = scene.bodies[static_cast<size_t>(i)].position;
    cone.axis = Vec3(1, 0, 0);
    cone.swing_span1 = 0.3;
    cone.swing_span2 = 0.6;
    scene.joints.push_back(cone);
  }
  BulletOracle oracle(scene);
  Real swing[2] = {0, 0};
  for (int n = 0; n < 90; ++n) {
    oracle.step();
    for (int i = 0; i < 2; ++i) {
      const Vec3 x = oracle.state(i).orientation * Vec3::UnitX();
      swing[i] = std::max(swing[i], std::acos(std::clamp(x.x(), Real(-1), Real(1))));
    }
  }
  EXPECT_NEAR(swing[0], 0.3, 0.03);
  EXPECT_NEAR(swing[1], 0.6, 0.03);
}

// cairn's soft joints (ODE convention) reach the same equilibrium in Bullet
// when each row's CFM is rescaled by its effective mass: a 1 kg body on a
// soft ball joint at its center of mass sags by m g / k (spring spelling)
// or by g / omega^2 (frequency spelling). Both are exact at equilibrium;
// 2% allows for the settling left after 3 s.
TEST(BulletOracle, SoftBallJointSagsAsItsSpring) {
  struct Case {
    Softness soft;
    Real sag;
  };
  Softness spring;
  spring.stiffness = 1e4;
  spring.damping = 200;
  Softness frequency;
  frequency.frequency = 8;
  frequency.damping_ratio = 1;
  const Real omega = 2 * kPi * 8;
  for (const Case& c : {Case{spring, kG / 1e4}, Case{frequency, kG / (omega * omega)}}) {
    SceneDesc scene = emptyScene();
    scene.bodies.push_back(dynamicBody("bob", Vec3::Zero(), ShapeDesc::sphere(0.2)));
    JointDef j;
    j.name = "soft";
    j.type = JointType::Ball;
    j.body_b = BodyId{0};
    j.softness = c.soft;
    scene.joints.push_back(j);
    BulletOracle oracle(scene);
    for (int n = 0; n < 180; ++n) oracle.step();
    EXPECT_NEAR(-oracle.state(0).position.y(), c.sag, 0.02 * c.sag);
  }
}

// A joint too soft for Bullet's joint iteration (1 Hz at 60 Hz needs a CFM
// of 4.5 x the effective mass, where Bullet's PGS diverges) is clamped and
// reported, and stays finite.
TEST(BulletOracle, TooSoftJointIsClampedAndReported) {
  SceneDesc scene = emptyScene();
  scene.bodies.push_back(dynamicBody("bob", Vec3::Zero(), ShapeDesc::sphere(0.2)));
  JointDef j;
  j.name = "mushy";
  j.type = JointType::Ball;
  j.body_b = BodyId{0};
  j.softness.frequency = 1;
  scene.joints.push_back(j);
  BulletOracle oracle(scene);
  for (int n = 0; n < 120; ++n) oracle.step();
  ASSERT_TRUE(finite(oracle.state(0)));
  const Real ideal_sag = kG / std::pow(2 * kPi, 2);
  EXPECT_GT(-oracle.state(0).position.y(), 0);
  EXPECT_LT(-oracle.state(0).position.y(), ideal_sag);  // stiffer than cairn's
  EXPECT_TRUE(mentions(oracle.skipped(), "joint 'mushy': a soft row needed a Bullet CFM above 0.5"));
}

// A spring between the world and a body oscillates with T = 2 pi sqrt(m/k)
// (semi-implicit Euler at h omega = 0.1 shifts it by ~0.05%; 1% bound).
TEST(BulletOracle, SpringOscillatesAtItsNaturalPeriod) {
  SceneDesc scene = emptyScene(Vec3::Zero());
  scene.bodies.push_back(dynamicBody("bob", Vec3(1.1, 0, 0), ShapeDesc::sphere(0.1), 2));
  SpringDef s;
  s.name = "spring";
  s.body_b = BodyId{0};
  s.anchor_a = Vec3::Zero();
  s.anchor_b = Vec3(1.1, 0, 0);
  s.rest_length = 1.0;
  s.stiffness = 80;
  scene.springs.push_back(s);
  BulletOracle oracle(scene);
  const Real period = measurePeriod(oracle, 300, [](BulletOracle& o) { return o.state(0).position.x() - 1.0; });
  EXPECT_NEAR(period, 2 * kPi * std::sqrt(2.0 / 80), 0.01 * 2 * kPi * std::sqrt(2.0 / 80));
}

// A joint whose break force is below its load breaks at once (Bullet's
// per-row impulse threshold is break_force h) and the body then falls freely.
TEST(BulletOracle, OverloadedJointBreaks) {
  SceneDesc scene = emptyScene();
  scene.bodies.push_back(box("heavy", Vec3(0, -0.5, 0), 10));
  JointDef j;
  j.name = "weak";
  j.type = JointType::Hinge;
  j.body_b = BodyId{0};
  j.axis = Vec3(0, 0, 1);
  j.break_force = 10;  // the weight is 98 N
  scene.joints.push_back(j);
  BulletOracle oracle(scene);
  EXPECT_TRUE(oracle.jointActive(0));
  for (int n = 0; n < 30; ++n) oracle.step();
  EXPECT_FALSE(oracle.jointActive(0));
  EXPECT_LT(oracle.state(0).position.y(), -0.5 - 0.5 * kG * 0.25);  // fell for most of the 0.5 s
  EXPECT_TRUE(mentions(oracle.skipped(), "breaking approximated"));
}

// ------------------------------------------------------- what is not mapped

TEST(BulletOracle, SkippedListsWhatBulletLacks) {
  SceneDesc scene = scenarios::column(1);
  {
    BulletOracle oracle(scene);  // cairn's defaults
    EXPECT_TRUE(mentions(oracle.skipped(), "solver.gyroscopic=implicit_midpoint has no Bullet equivalent"));
    EXPECT_FALSE(mentions(oracle.skipped(), "solver.method"));
  }
  scene.solver.method = SolverMethod::Direct;
  scene.solver.orientation = OrientationIntegrator::Derivative;
  scene.solver.gyroscopic = Gyroscopic::ImplicitEuler;
  scene.solver.randomize_order = true;
  BulletOracle oracle(scene);
  EXPECT_TRUE(mentions(oracle.skipped(), "solver.method=direct has no Bullet equivalent"));
  EXPECT_TRUE(mentions(oracle.skipped(), "solver.orientation=derivative has no Bullet equivalent"));
  EXPECT_TRUE(mentions(oracle.skipped(), "solver.randomize_order approximated"));
  EXPECT_FALSE(mentions(oracle.skipped(), "implicit_midpoint"));
  // It still runs: the box stays on the ground.
  for (int n = 0; n < 30; ++n) oracle.step();
  EXPECT_NEAR(oracle.state(1).position.y(), 0.5, 0.02);
}

TEST(BulletOracle, BadSceneThrowsInputError) {
  SceneDesc scene = scenarios::column(1);
  scene.bodies[1].mass = -1;
  EXPECT_THROW(BulletOracle{scene}, InputError);
}

// A pyramid of 55 boxes in Bullet for 10 s, awake throughout: the reference
// cairn's stacking is compared with. It must stand (no box moved more than
// 0.5 m, docs/scenarios.md's collapse criterion).
TEST(BulletOracle, LongPyramid10StandsForTenSeconds) {
  SceneDesc scene = scenarios::pyramid(10);
  scene.solver.sleeping = false;
  BulletOracle oracle(scene);
  std::vector<Vec3> start;
  for (int i = 0; i < oracle.bodyCount(); ++i) start.push_back(oracle.state(i).position);
  for (int n = 0; n < scene.steps; ++n) oracle.step();
  Real worst = 0;
  for (int i = 0; i < oracle.bodyCount(); ++i) worst = std::max(worst, (oracle.state(i).position - start[i]).norm());
  EXPECT_LT(worst, 0.5);
}

}  // namespace
}  // namespace cairn::validation
