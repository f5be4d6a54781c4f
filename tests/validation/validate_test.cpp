// `cairn validate` and `cairn scenes`: the scene writer's round trip, the
// comparison logic on trajectories with a known difference, the hinge
// pendulum in cairn against Bullet, the report files, and bad input
// (exit status 2 with one line naming the path).
#include "cli_test_helpers.hpp"
#include "cairn/error.hpp"
#include "validation/compare.hpp"
#include "validation/report.hpp"
#include "validation/scene_writer.hpp"
#include "validation/standard_scenes.hpp"
#include "world/scene_json.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace cairn::validation {
namespace {

namespace fs = std::filesystem;

using test::CliResult;
using test::slurp;

struct TempDir : test::TempDir {
  TempDir() : test::TempDir("cairn_validate") {}
};

CliResult cairn(const std::string& args, const TempDir& tmp) { return test::runCairn(args, tmp); }

int lineCount(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// ------------------------------------------------------------- scene writer

void expectSameSoftness(const Softness& a, const Softness& b) {
  EXPECT_EQ(a.erp, b.erp);
  EXPECT_EQ(a.cfm, b.cfm);
  EXPECT_EQ(a.stiffness, b.stiffness);
  EXPECT_EQ(a.damping, b.damping);
  EXPECT_EQ(a.frequency, b.frequency);
  EXPECT_EQ(a.damping_ratio, b.damping_ratio);
}

void expectSameMotor(const MotorDef& a, const MotorDef& b) {
  EXPECT_EQ(a.enabled, b.enabled);
  if (!a.enabled) return;
  EXPECT_EQ(a.target_velocity, b.target_velocity);
  EXPECT_EQ(a.target_position, b.target_position);
  EXPECT_EQ(a.max_force, b.max_force);
  expectSameSoftness(a.softness, b.softness);
}

// Quaternions and plane normals are normalised by the reader, which may
// move the last bit; everything else must come back bit for bit.
void expectSameScene(const SceneDesc& a, const SceneDesc& b) {
  EXPECT_EQ(a.gravity, b.gravity);
  EXPECT_EQ(a.dt, b.dt);
  EXPECT_EQ(a.steps, b.steps);
  const SolverSettings &s = a.solver, &t = b.solver;
  EXPECT_EQ(s.method, t.method);
  EXPECT_EQ(s.iterations, t.iterations);
  EXPECT_EQ(s.tolerance, t.tolerance);
  EXPECT_EQ(s.sor, t.sor);
  EXPECT_EQ(s.warm_start, t.warm_start);
  EXPECT_EQ(s.warm_start_factor, t.warm_start_factor);
  EXPECT_EQ(s.randomize_order, t.randomize_order);
  EXPECT_EQ(s.nncg, t.nncg);
  EXPECT_EQ(s.seed, t.seed);
  EXPECT_EQ(s.substeps, t.substeps);
  EXPECT_EQ(s.erp, t.erp);
  EXPECT_EQ(s.cfm, t.cfm);
  EXPECT_EQ(s.position_correction, t.position_correction);
  EXPECT_EQ(s.contact_erp, t.contact_erp);
  EXPECT_EQ(s.slop, t.slop);
  EXPECT_EQ(s.restitution_threshold, t.restitution_threshold);
  EXPECT_EQ(s.split_impulse, t.split_impulse);
  EXPECT_EQ(s.max_correction_velocity, t.max_correction_velocity);
  EXPECT_EQ(s.contact_margin, t.contact_margin);
  EXPECT_EQ(s.sleeping, t.sleeping);
  EXPECT_EQ(s.sleep_linear_velocity, t.sleep_linear_velocity);
  EXPECT_EQ(s.sleep_angular_velocity, t.sleep_angular_velocity);
  EXPECT_EQ(s.sleep_time, t.sleep_time);
  EXPECT_EQ(s.max_angular_velocity, t.max_angular_velocity);
  EXPECT_EQ(s.gyroscopic, t.gyroscopic);
  EXPECT_EQ(s.orientation, t.orientation);

  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    SCOPED_TRACE("body " + a.bodies[i].name);
    const BodyDef &x = a.bodies[i], &y = b.bodies[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.mass, y.mass);
    EXPECT_EQ(x.density, y.density);
    ASSERT_EQ(x.inertia.has_value(), y.inertia.has_value());
    if (x.inertia) {
      EXPECT_EQ(*x.inertia, *y.inertia);
    }
    EXPECT_EQ(x.position, y.position);
    EXPECT_LT((x.orientation.coeffs() - y.orientation.coeffs()).norm(), 1e-15);
    EXPECT_EQ(x.linear_velocity, y.linear_velocity);
    EXPECT_EQ(x.angular_velocity, y.angular_velocity);
    EXPECT_EQ(x.friction, y.friction);
    EXPECT_EQ(x.restitution, y.restitution);
    EXPECT_EQ(x.rolling_friction, y.rolling_friction);
    EXPECT_EQ(x.torsional_friction, y.torsional_friction);
    EXPECT_EQ(x.linear_damping, y.linear_damping);
    EXPECT_EQ(x.angular_damping, y.angular_damping);
    EXPECT_EQ(x.ccd, y.ccd);
    EXPECT_EQ(x.collision_group, y.collision_group);
    EXPECT_EQ(x.collision_mask, y.collision_mask);
    EXPECT_EQ(x.force, y.force);
    EXPECT_EQ(x.torque, y.torque);
    ASSERT_EQ(x.impulses.size(), y.impulses.size());
    for (size_t k = 0; k < x.impulses.size(); ++k) {
      EXPECT_EQ(x.impulses[k].time, y.impulses[k].time);
      EXPECT_EQ(x.impulses[k].impulse, y.impulses[k].impulse);
      EXPECT_EQ(x.impulses[k].point, y.impulses[k].point);
    }
    EXPECT_EQ(x.lock_translation, y.lock_translation);
    EXPECT_EQ(x.lock_rotation, y.lock_rotation);
    ASSERT_EQ(x.shapes.size(), y.shapes.size());
    for (size_t k = 0; k < x.shapes.size(); ++k) {
      const ShapeDesc &p = x.shapes[k], &q = y.shapes[k];
      EXPECT_EQ(p.type, q.type);
      EXPECT_EQ(p.radius, q.radius);
      EXPECT_EQ(p.half_height, q.half_height);
      EXPECT_EQ(p.half_extents, q.half_extents);
      EXPECT_LT((p.normal - q.normal).norm(), 1e-15);
      EXPECT_EQ(p.offset, q.offset);
      EXPECT_EQ(p.local.p, q.local.p);
      EXPECT_LT((p.local.q.coeffs() - q.local.q.coeffs()).norm(), 1e-15);
      ASSERT_EQ(p.hull != nullptr, q.hull != nullptr);
      if (p.hull) {
        EXPECT_EQ(p.hull->vertices, q.hull->vertices);
        EXPECT_EQ(p.hull->faces.size(), q.hull->faces.size());
      }
    }
  }
  ASSERT_EQ(a.springs.size(), b.springs.size());
  for (size_t i = 0; i < a.springs.size(); ++i) {
    const SpringDef &x = a.springs[i], &y = b.springs[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.body_a, y.body_a);
    EXPECT_EQ(x.body_b, y.body_b);
    EXPECT_EQ(x.anchor_a, y.anchor_a);
    EXPECT_EQ(x.anchor_b, y.anchor_b);
    EXPECT_EQ(x.rest_length, y.rest_length);
    EXPECT_EQ(x.stiffness, y.stiffness);
    EXPECT_EQ(x.damping, y.damping);
  }
  ASSERT_EQ(a.joints.size(), b.joints.size());
  for (size_t i = 0; i < a.joints.size(); ++i) {
    SCOPED_TRACE("joint " + a.joints[i].name);
    const JointDef &x = a.joints[i], &y = b.joints[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.body_a, y.body_a);
    EXPECT_EQ(x.body_b, y.body_b);
    EXPECT_EQ(x.anchor, y.anchor);
    EXPECT_EQ(x.axis, y.axis);
    EXPECT_EQ(x.axis2, y.axis2);
    EXPECT_EQ(x.anchor_a, y.anchor_a);
    EXPECT_EQ(x.anchor_b, y.anchor_b);
    EXPECT_EQ(x.length, y.length);
    EXPECT_EQ(x.limit.enabled, y.limit.enabled);
    if (x.limit.enabled) {
      EXPECT_EQ(x.limit.lower, y.limit.lower);
      EXPECT_EQ(x.limit.upper, y.limit.upper);
      EXPECT_EQ(x.limit.restitution, y.limit.restitution);
      expectSameSoftness(x.limit.softness, y.limit.softness);
    }
    EXPECT_EQ(x.swing_span1, y.swing_span1);
    EXPECT_EQ(x.swing_span2, y.swing_span2);
    expectSameMotor(x.motor, y.motor);
    for (int k = 0; k < kDofCount; ++k) {
      SCOPED_TRACE(dofName(k));
      const DofDef &p = x.dofs[static_cast<size_t>(k)], &q = y.dofs[static_cast<size_t>(k)];
      EXPECT_EQ(p.mode, q.mode);
      if (p.mode == DofMode::Limited) {
        EXPECT_EQ(p.limit.lower, q.limit.lower);
        EXPECT_EQ(p.limit.upper, q.limit.upper);
        EXPECT_EQ(p.limit.restitution, q.limit.restitution);
        expectSameSoftness(p.limit.softness, q.limit.softness);
      }
      EXPECT_EQ(p.spring.enabled, q.spring.enabled);
      EXPECT_EQ(p.spring.rest, q.spring.rest);
      expectSameSoftness(p.spring.softness, q.spring.softness);
      expectSameMotor(p.motor, q.motor);
    }
    EXPECT_EQ(x.motor_axes, y.motor_axes);
    EXPECT_EQ(x.motor_targets, y.motor_targets);
    EXPECT_EQ(x.motor_max_torques, y.motor_max_torques);
    expectSameSoftness(x.softness, y.softness);
    EXPECT_EQ(x.break_force, y.break_force);
    EXPECT_EQ(x.break_torque, y.break_torque);
    EXPECT_EQ(x.collide_connected, y.collide_connected);
  }
  EXPECT_EQ(nlohmann::json::parse(a.validation_json.empty() ? "null" : a.validation_json),
            nlohmann::json::parse(b.validation_json.empty() ? "null" : b.validation_json));
}

SceneDesc roundTrip(const SceneDesc& scene, const TempDir& tmp, const std::string& name) {
  const std::string path = (tmp.path / (name + ".json")).string();
  writeScene(path, scene, "round trip of " + name);
  return loadScene(path);
}

// Every standard scenario written and read back gives the same scene, and
// writing what was read gives the same text.
TEST(SceneWriter, StandardScenesRoundTripThroughLoadScene) {
  TempDir tmp;
  for (const std::string& key : standardSceneNames()) {
    SCOPED_TRACE(key);
    const StandardScene s = standardScene(key);
    const SceneDesc back = roundTrip(s.scene, tmp, key);
    expectSameScene(s.scene, back);
    EXPECT_EQ(sceneToText(back, s.description), sceneToText(s.scene, s.description));
  }
}

// Everything the format has that the standard scenes do not use: other
// shapes and offsets, springs, every joint type with limits, motors,
// softness and breaking, non-default solver settings and body fields.
TEST(SceneWriter, EveryFieldRoundTrips) {
  SceneDesc s;
  s.gravity = Vec3(0.1, -9.7, 0.2);
  s.dt = 1.0 / 240;
  s.steps = 17;
  s.solver.method = SolverMethod::Direct;
  s.solver.iterations = 33;
  s.solver.tolerance = 1e-7;
  s.solver.sor = 1.3;
  s.solver.warm_start = false;
  s.solver.warm_start_factor = 0.85;
  s.solver.randomize_order = true;
  s.solver.seed = 12345678901234ull;
  s.solver.substeps = 4;
  s.solver.erp = 0.3;
  s.solver.cfm = 1e-6;
  s.solver.position_correction = Correction::PseudoVelocity;
  s.solver.contact_erp = 0.25;
  s.solver.slop = 0.002;
  s.solver.restitution_threshold = 0.5;
  s.solver.split_impulse = false;
  s.solver.max_correction_velocity = 3;
  s.solver.contact_margin = 0.03;
  s.solver.sleeping = false;
  s.solver.sleep_linear_velocity = 0.1;
  s.solver.sleep_angular_velocity = 0.2;
  s.solver.sleep_time = 1.5;
  s.solver.max_angular_velocity = 100;
  s.solver.gyroscopic = Gyroscopic::ImplicitEuler;
  s.solver.orientation = OrientationIntegrator::Derivative;

  BodyDef ground;
  ground.name = "ground";
  ground.type = BodyType::Static;
  ground.shapes.push_back(ShapeDesc::plane(Vec3(0, 1, 0), -0.25));
  s.bodies.push_back(ground);
  BodyDef a;
  a.name = "a";
  a.density = 700;
  a.position = Vec3(0.1, 2.2, -0.3);
  a.orientation = Quat(Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()));
  a.linear_velocity = Vec3(1, 2, 3);
  a.angular_velocity = Vec3(-1, 0.5, 0.25);
  a.friction = 0.8;
  a.restitution = 0.3;
  a.rolling_friction = 0.01;
  a.torsional_friction = 0.02;
  a.linear_damping = 0.1;
  a.angular_damping = 0.2;
  a.ccd = true;
  a.collision_group = 4;
  a.collision_mask = ~6u;
  a.force = Vec3(0.5, -1, 2);
  a.torque = Vec3(0, 0.25, -0.125);
  a.impulses = {{0.1, Vec3(1, 0, 0), Vec3(0.1, 2.3, -0.3)}, {0.5, Vec3(0, -2, 0.5), std::nullopt}};
  a.lock_translation = {Vec3::UnitZ()};
  a.lock_rotation = {Vec3(1, 1, 0), Vec3::UnitY()};
  ShapeDesc cap = ShapeDesc::capsule(0.2, 0.4);
  cap.local.p = Vec3(0.1, 0, 0);
  cap.local.q = Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitX()));
  a.shapes = {cap, ShapeDesc::cylinder(0.3, 0.2), ShapeDesc::sphere(0.15)};
  s.bodies.push_back(a);
  BodyDef b;
  b.name = "b";
  b.mass = 2.5;
  b.inertia = Mat3::Identity() * 0.4;
  b.position = Vec3(1, 3, 0);
  s.bodies.push_back(b);
  BodyDef c;
  c.name = "c";
  c.type = BodyType::Kinematic;
  c.position = Vec3(-1, 1, 0);
  c.shapes.push_back(ShapeDesc::box(Vec3(0.5, 0.1, 0.2)));
  s.bodies.push_back(c);
  BodyDef h;
  h.name = "hull";
  h.mass = 1;
  h.position = Vec3(3, 1, 0);
  ShapeDesc hull;
  hull.type = ShapeType::ConvexHull;
  {
    // A unit tetrahedron through the loader, to get a real ConvexHullData.
    const std::string text = R"({"bodies": [{"name": "t", "mass": 1, "shapes": [{"type": "convex_hull",
        "points": [[0,0,0],[1,0,0],[0,1,0],[0,0,1],[0.1,0.1,0.1]]}]}]})";
    hull = parseScene(text, "tetra.json").bodies[0].shapes[0];
  }
  h.shapes.push_back(hull);
  s.bodies.push_back(h);

  SpringDef spring;
  spring.name = "spring";
  spring.body_a = kWorldBody;
  spring.body_b = BodyId{2};
  spring.anchor_a = Vec3(1, 5, 0);
  spring.anchor_b = Vec3(1, 3, 0);
  spring.rest_length = 1.5;
  spring.stiffness = 40;
  spring.damping = 0.3;
  s.springs.push_back(spring);

  const auto joint = [&](JointType type, const std::string& name, BodyId ja, BodyId jb) -> JointDef& {
    JointDef j;
    j.type = type;
    j.name = name;
    j.body_a = ja;
    j.body_b = jb;
    j.anchor = Vec3(0.5, 2.5, 0);
    s.joints.push_back(j);
    return s.joints.back();
  };
  JointDef& hinge = joint(JointType::Hinge, "hinge", BodyId{1}, BodyId{2});
  hinge.axis = Vec3(0, 0, -1);
  hinge.limit = LimitDef{true, -0.5, 0.75, 0.2, Softness{}};
  hinge.limit.softness.erp = 0.5;
  hinge.motor = MotorDef{true, 2, 10, {}, {}};
  hinge.motor.softness.damping = 3;
  hinge.softness.erp = 0.4;
  hinge.softness.cfm = 1e-5;
  hinge.break_force = 1000;
  hinge.break_torque = 500;
  hinge.collide_connected = true;
  JointDef& slider = joint(JointType::Slider, "slider", kWorldBody, BodyId{2});
  slider.axis = Vec3(1, 0, 0);
  slider.limit = LimitDef{true, -1, 1, 0, Softness{}};
  slider.limit.softness.frequency = 5;
  slider.limit.softness.damping_ratio = 0.7;
  slider.softness.stiffness = 1000;
  slider.softness.damping = 10;
  slider.motor = MotorDef{true, 0, 50, 0.3, {}};
  slider.motor.softness.frequency = 3;
  slider.motor.softness.damping_ratio = 0.8;
  joint(JointType::Ball, "ball", BodyId{1}, kWorldBody);
  joint(JointType::Fixed, "fixed", BodyId{4}, BodyId{2});
  JointDef& uni = joint(JointType::Universal, "universal", BodyId{1}, BodyId{4});
  uni.axis = Vec3(0, 1, 0);
  uni.axis2 = Vec3(0, 0, 1);
  JointDef& cone = joint(JointType::ConeTwist, "cone", BodyId{2}, BodyId{4});
  cone.axis = Vec3(0, -1, 0);
  cone.swing_span1 = 0.4;
  cone.swing_span2 = 0.6;
  cone.limit = LimitDef{true, -0.2, 0.3, 0, Softness{}};
  JointDef& dist = joint(JointType::Distance, "distance", BodyId{1}, BodyId{2});
  dist.anchor_a = Vec3(0.1, 2.2, -0.3);
  dist.anchor_b = Vec3(1, 3, 0);
  dist.length = 1.7;
  dist.anchor = Vec3::Zero();  // a distance joint has two anchors instead
  JointDef& motor = joint(JointType::AngularMotor, "motor", kWorldBody, BodyId{1});
  motor.motor_axes = {Vec3::UnitX(), Vec3::UnitY()};
  motor.motor_targets = {1, -2};
  motor.motor_max_torques = {5, 6};
  JointDef& six = joint(JointType::SixDof, "six_dof", BodyId{4}, BodyId{1});
  six.axis = Vec3(0, 1, 0);
  six.axis2 = Vec3(0, 0, -1);
  six.dofs[0].mode = DofMode::Locked;
  six.dofs[1].mode = DofMode::Limited;
  six.dofs[1].limit = LimitDef{true, -0.1, 0.2, 0.3, Softness{}};
  six.dofs[1].motor = MotorDef{true, -0.5, 20, {}, {}};
  six.dofs[2].spring.enabled = true;
  six.dofs[2].spring.rest = 0.05;
  six.dofs[2].spring.softness.stiffness = 400;
  six.dofs[2].spring.softness.damping = 4;
  six.dofs[3].motor = MotorDef{true, 0, 8, -1.2, {}};
  six.dofs[4].mode = DofMode::Limited;
  six.dofs[4].limit = LimitDef{true, -0.4, 1.4, 0, Softness{}};
  six.dofs[4].limit.softness.stiffness = 300;
  six.dofs[5].mode = DofMode::Limited;
  six.dofs[5].limit = LimitDef{true, 0.25, 0.25, 0, Softness{}};
  six.dofs[5].spring.enabled = true;
  six.dofs[5].spring.softness.frequency = 2;
  s.validation_json = R"({"kind":"trajectory","tolerances":{"position":0.1}})";

  TempDir tmp;
  const SceneDesc back = roundTrip(s, tmp, "everything");
  expectSameScene(s, back);
}

TEST(SceneWriter, UnwritablePathThrowsInputErrorNamingIt) {
  TempDir tmp;
  const std::string path = (tmp.path / "no-such-dir" / "x.json").string();
  try {
    writeScene(path, standardScene("column-10").scene);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// scenes/ is `cairn scenes --out scenes` output: every shipped file is what
// the generator writes today (regenerate with that command when this fails).
TEST(SceneWriter, ShippedScenesAreTheGeneratorsOutput) {
  for (const std::string& key : standardSceneNames()) {
    SCOPED_TRACE(key);
    const fs::path file = fs::path(CAIRN_SOURCE_DIR) / "scenes" / (key + ".json");
    ASSERT_TRUE(fs::exists(file)) << file;
    const StandardScene s = standardScene(key);
    EXPECT_EQ(slurp(file), sceneToText(s.scene, s.description));
  }
}

// --------------------------------------------------------- comparison logic

// A synthetic run: `bodies` bodies moving along x at 1 m/s, one sample per
// 1/60 s.
EngineRun straightRun(int samples, int bodies) {
  EngineRun r;
  for (int s = 0; s < samples; ++s) {
    const double t = s / 60.0;
    r.time.push_back(t);
    std::vector<Vec3> x;
    std::vector<Quat> q;
    for (int i = 0; i < bodies; ++i) {
      x.push_back(Vec3(t + i, 1, 0));
      q.push_back(Quat(Eigen::AngleAxis<Real>(0.1 * t, Vec3::UnitZ())));
    }
    r.positions.push_back(x);
    r.orientations.push_back(q);
    r.velocities.push_back(std::vector<Vec3>(size_t(bodies), Vec3(1, 0, 0)));
    r.joint_error.push_back(0);
    r.joint_error_angular.push_back(0);
    r.energy.push_back(1);
    r.rotational_energy.push_back(0);
    r.momentum.push_back(Vec3(bodies, 0, 0));
    r.step_seconds.push_back(s ? 1e-5 : 0);
  }
  return r;
}

SceneDesc twoBodyScene() {
  SceneDesc s;
  for (int i = 0; i < 2; ++i) {
    BodyDef b;
    b.name = "b" + std::to_string(i);
    b.mass = 1;
    b.position = Vec3(i, 1, 0);
    s.bodies.push_back(b);
  }
  s.steps = 119;
  return s;
}

const Figure* figure(const std::vector<Figure>& figs, const std::string& key) {
  for (const Figure& f : figs)
    if (f.key == key) return &f;
  return nullptr;
}

// Two trajectories that agree except that body 1 is shifted 0.1 m along y
// and turned 0.2 rad about x from sample 60 on: the comparison finds exactly
// that offset, on that body, at that time, and fails a 0.05 m / 0.1 rad
// tolerance by 0.05 m / 0.1 rad while passing 0.2 m / 0.3 rad.
TEST(Comparison, FlagsADeliberatelyPerturbedTrajectory) {
  const EngineRun a = straightRun(120, 2);
  EngineRun b = a;
  const Quat turn(Eigen::AngleAxis<Real>(0.2, Vec3::UnitX()));
  for (int s = 60; s < 120; ++s) {
    b.positions[size_t(s)][1] += Vec3(0, 0.1, 0);
    b.orientations[size_t(s)][1] = turn * b.orientations[size_t(s)][1];
  }
  const TrajectoryDifference same = trajectoryDifference(a, a);
  EXPECT_EQ(same.position, 0);
  EXPECT_EQ(same.angle, 0);
  const TrajectoryDifference d = trajectoryDifference(a, b);
  EXPECT_NEAR(d.position, 0.1, 1e-12);
  EXPECT_EQ(d.position_body, 1);
  EXPECT_EQ(d.position_sample, 60);
  EXPECT_NEAR(d.angle, 0.2, 1e-12);
  EXPECT_EQ(d.angle_body, 1);

  const SceneDesc scene = twoBodyScene();
  ValidationSpec spec;
  spec.kind = ValidationKind::Trajectory;
  spec.tolerances = {{"position", 0.05}, {"angle", 0.1}};
  std::vector<Figure> figs = compareRuns(scene, spec, a, b);
  const Figure* pos = figure(figs, "position");
  const Figure* ang = figure(figs, "angle");
  ASSERT_TRUE(pos && ang);
  EXPECT_FALSE(pos->pass);
  EXPECT_NEAR(pos->excess, 0.05, 1e-12);
  EXPECT_NE(pos->note.find("'b1'"), std::string::npos) << pos->note;
  EXPECT_NE(pos->note.find("t = 1.000 s"), std::string::npos) << pos->note;
  EXPECT_FALSE(ang->pass);
  EXPECT_NEAR(ang->excess, 0.1, 1e-12);

  SceneResult result;
  result.name = "perturbed";
  result.figures = figs;
  EXPECT_FALSE(result.pass());
  const auto lines = failureLines(result);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[0].find("perturbed: position"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("off by 0.05 m"), std::string::npos) << lines[0];

  spec.tolerances = {{"position", 0.2}, {"angle", 0.3}};
  figs = compareRuns(scene, spec, a, b);
  EXPECT_TRUE(figure(figs, "position")->pass);
  EXPECT_TRUE(figure(figs, "angle")->pass);
  // Unperturbed runs pass the tightest tolerance.
  spec.tolerances = {{"position", 0}, {"angle", 0}};
  figs = compareRuns(scene, spec, a, a);
  EXPECT_TRUE(figure(figs, "position")->pass);
}

// A horizon leaves the later samples out of the checked difference (the
// perturbation from t = 1 s on is invisible over the first 0.9 s and the
// whole run's figure still shows it), and a reference run puts each
// engine's distance from it side by side under a ratio check.
TEST(Comparison, HorizonAndExactReferenceJudgeOnlyThePredictableWindow) {
  const EngineRun a = straightRun(120, 2);
  EngineRun b = a, far = a;
  for (int s = 60; s < 120; ++s) b.positions[size_t(s)][1] += Vec3(0, 0.1, 0);
  for (int s = 1; s < 120; ++s) far.positions[size_t(s)][0] += Vec3(0.01 * s, 0, 0);
  EXPECT_EQ(trajectoryDifference(a, b, 0.9).position, 0);
  EXPECT_NEAR(trajectoryDifference(a, b, 1.0).position, 0.1, 1e-12);

  const SceneDesc scene = twoBodyScene();
  ValidationSpec spec;
  spec.kind = ValidationKind::Trajectory;
  spec.horizon = 0.9;
  spec.tolerances = {{"position", 0.05}, {"reference_distance", 1.5}};
  // cairn = a (on the reference), Bullet = far (0.01 m per sample off it).
  std::vector<Figure> figs = compareRuns(scene, spec, a, far, &b);
  const Figure* pos = figure(figs, "position");
  const Figure* whole = figure(figs, "position_whole_run");
  const Figure* ref = figure(figs, "reference_distance");
  ASSERT_TRUE(pos && whole && ref);
  EXPECT_NEAR(*pos->cairn, 0.01 * 54, 1e-9);  // sample 54 is t = 0.9 s
  EXPECT_NEAR(*whole->cairn, 0.01 * 119, 1e-9);
  EXPECT_EQ(whole->check, Check::None);
  EXPECT_EQ(*ref->cairn, 0);                  // b matches a before t = 1 s
  EXPECT_NEAR(*ref->bullet, 0.01 * 54, 1e-9);
  EXPECT_TRUE(ref->pass);
  figs = compareRuns(scene, spec, far, a, &b);  // the engines swapped: cairn is the one off the reference
  EXPECT_FALSE(figure(figs, "reference_distance")->pass);

  // chain-N gets the horizon and the reference by default; bad values are named.
  const ValidationSpec chain = validationSpec(standardScene("chain-20").scene);
  EXPECT_EQ(chain.horizon, 1);
  EXPECT_TRUE(chain.direct_reference);
  SceneDesc bad = standardScene("hinge-pendulum-0.1").scene;
  bad.validation_json = R"({"reference": "bullet"})";
  try {
    (void)validationSpec(bad);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "reference");
  }
  bad.validation_json = R"({"horizon": -1})";
  EXPECT_THROW((void)validationSpec(bad), InputError);
}

// Each check type: where the boundary is, and what "excess" means.
TEST(Comparison, ChecksPassAtTheToleranceAndReportTheExcess) {
  Figure f;
  f.cairn = 1.10;
  f.bullet = 1.00;
  f.analytic = 1.00;
  f.tolerance = 0.05;
  f.check = Check::DiffBullet;
  f.evaluate();
  EXPECT_FALSE(f.pass);
  EXPECT_NEAR(f.excess, 0.05, 1e-12);
  f.check = Check::RelAnalytic;
  f.tolerance = 0.11;
  f.evaluate();
  EXPECT_TRUE(f.pass);
  f.check = Check::RatioBullet;
  f.tolerance = 1.05;
  f.evaluate();
  EXPECT_FALSE(f.pass);
  EXPECT_NEAR(f.excess, 0.05, 1e-12);
  f.check = Check::NotWorseFlag;
  f.cairn = 1;
  f.bullet = 0;
  f.evaluate();
  EXPECT_FALSE(f.pass);  // cairn collapsed, Bullet did not
  f.bullet = 1;
  f.evaluate();
  EXPECT_TRUE(f.pass);
  f.check = Check::AtMost;
  f.cairn.reset();
  f.evaluate();
  EXPECT_FALSE(f.pass);  // no cairn value is a failure, never a pass
}

TEST(Comparison, MeasuresThePeriodOfASine) {
  std::vector<double> t, x;
  for (int s = 0; s <= 600; ++s) {
    t.push_back(s / 60.0);
    x.push_back(0.3 + std::sin(2 * kPi * t.back() / 2.1 + 0.4));
  }
  EXPECT_NEAR(measurePeriod(t, x), 2.1, 1e-3);
  EXPECT_EQ(measurePeriod({0, 1}, {0, 1}), 0);
}

TEST(Comparison, BadValidationBlockIsAnInputErrorNamingTheField) {
  SceneDesc scene = standardScene("hinge-pendulum-0.1").scene;
  scene.validation_json = R"({"kind": "trajectory", "traces": [{"body": "nobody"}]})";
  try {
    (void)validationSpec(scene);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), "validation");
    EXPECT_EQ(e.field(), "traces[0].body");
  }
  scene.validation_json = R"({"tolerances": {"position": -1}})";
  EXPECT_THROW((void)validationSpec(scene), InputError);
  scene.validation_json = R"({"tolerence": {}})";
  EXPECT_THROW((void)validationSpec(scene), InputError);
}

// ------------------------------------------------ cairn against Bullet

// The standard hinge pendulum in both engines. Both take the same 5 rows
// on one body and the same semi-implicit Euler step, so they agree far
// better than with the exact solution: Bullet's hinge keeps its rows in a
// lever-aligned basis and never warm-starts them, which at 1.5 rad leaves
// 0.45 mm between the two after 10 s (0.5 mrad). Bars: 1 cm and 0.01 rad
// (20x that), and a period difference of 5 ms (0.2%; a third of a step, far
// above the zero-crossing interpolation's error, far below the 22 ms the
// 1.5 rad pendulum's decaying amplitude costs). Against the exact period:
// 0.5% at 0.1 rad (measured 0.007%); at 1.5 rad both engines lose 0.075 rad
// of amplitude to O(h^2) constraint drift over 10 s and the period follows
// the smaller swing (the exact period at the mean amplitude, 1.46 rad, is
// 2.4966 s; measured 2.4959 s), so 1.5% there.
TEST(CairnAgainstBullet, HingePendulumStaysWithinTolerance) {
  for (const double a0 : {0.1, 1.5}) {
    SCOPED_TRACE(a0);
    const std::string key = a0 < 1 ? "hinge-pendulum-0.1" : "hinge-pendulum-1.5";
    const StandardScene s = standardScene(key);
    const SceneResult r = validateScene(s.scene, key, "test", s.description);
    ASSERT_EQ(r.cairn.samples(), 601);
    ASSERT_EQ(r.bullet.samples(), 601);
    const TrajectoryDifference d = trajectoryDifference(r.cairn, r.bullet);
    EXPECT_LT(d.position, 0.01);
    EXPECT_LT(d.angle, 0.01);
    const Figure* period = figure(r.figures, "period");
    ASSERT_TRUE(period && period->cairn && period->bullet);
    EXPECT_LT(std::abs(*period->cairn - *period->bullet), 0.005);
    EXPECT_NEAR(*period->cairn, hingePendulumPeriod(a0), (a0 < 1 ? 0.005 : 0.015) * hingePendulumPeriod(a0));
    EXPECT_TRUE(r.pass()) << failureLines(r).front();
  }
}

// The joint scenes of docs/constraints.md against Bullet, within their
// scenes' tolerances (docs/validation.md says why each is what it is):
// motor-limits, a hinge and a slider motor driving into asymmetric limits
// (sign and value: the arm ends on +1.1 rad, the cart on -0.3 m, in both
// engines), six-dof, one axis of each kind on Bullet's
// btGeneric6DofSpring2Constraint, and ragdoll-6dof, the ragdoll built of
// six_dof joints (penetration, and joint error no worse than Bullet's
// by half again).
TEST(CairnAgainstBullet, MotorLimitAndSixDofScenesStayWithinTolerance) {
  for (const std::string key : {"motor-limits", "six-dof", "ragdoll-6dof"}) {
    SCOPED_TRACE(key);
    const StandardScene s = standardScene(key);
    const SceneResult r = validateScene(s.scene, key, "test", s.description);
    EXPECT_TRUE(r.pass()) << failureLines(r).front();
    if (key == "motor-limits") {
      for (const EngineRun* t : {&r.cairn, &r.bullet}) {
        const Quat& arm = t->orientations.back()[0];
        EXPECT_NEAR(2 * std::atan2(arm.y(), arm.w()), 1.1, 0.02);
        EXPECT_NEAR(t->positions.back()[1].x(), -0.3, 0.01);
      }
    }
  }
}

TEST(CairnAgainstBullet, ExactPendulumPeriodsMatchScenariosMd) {
  EXPECT_NEAR(hingePendulumPeriod(0.1), 2.168155, 5e-7);
  EXPECT_NEAR(hingePendulumPeriod(1.5), 2.517753, 5e-7);
}

// ------------------------------------------------------------ the command

// A short run (30 steps) of a hinge scene and a stacking scene writes the
// report, a CSV per scene and every plot, none of them empty.
TEST(ValidateCommand, ShortRunWritesReportCsvsAndPlots) {
  TempDir tmp;
  const fs::path dir = tmp.path / "report";
  const CliResult r = cairn("validate hinge-pendulum-0.1 column-10 --steps 30 --report " + dir.string(), tmp);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("| hinge-pendulum-0.1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("report: " + (dir / "report.md").string()), std::string::npos) << r.out;
  const std::string md = slurp(dir / "report.md");
  EXPECT_NE(md.find("## hinge-pendulum-0.1"), std::string::npos);
  EXPECT_NE(md.find("## column-10"), std::string::npos);
  EXPECT_NE(md.find("pendulum period"), std::string::npos);
  for (const char* f : {"hinge-pendulum-0.1.csv", "hinge-pendulum-0.1_trace_0.png", "hinge-pendulum-0.1_joint_error.png",
                        "hinge-pendulum-0.1_energy.png", "column-10.csv", "column-10_trace_0.png",
                        "column-10_energy.png", "column-10_penetration.png"}) {
    SCOPED_TRACE(f);
    ASSERT_TRUE(fs::exists(dir / f));
    EXPECT_GT(fs::file_size(dir / f), 100u);
    if (fs::path(f).extension() == ".png") {
      EXPECT_EQ(slurp(dir / f).substr(1, 3), "PNG");
    } else {
      EXPECT_EQ(lineCount(slurp(dir / f)), 32);  // header + 31 samples
    }
  }
}

TEST(ValidateCommand, SceneFileIsReadAndOutsideToleranceExitsOne) {
  TempDir tmp;
  // The 1.5 rad pendulum with a position tolerance of zero: the engines
  // differ by a fraction of a mm, so exactly that figure fails.
  SceneDesc scene = standardScene("hinge-pendulum-1.5").scene;
  auto v = nlohmann::json::parse(scene.validation_json);
  v["tolerances"]["position"] = 0;
  scene.validation_json = v.dump();
  const std::string path = (tmp.path / "strict.json").string();
  writeScene(path, scene);
  const CliResult r = cairn("validate " + path + " --steps 120", tmp);
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("outside tolerance: strict: position"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("outside tolerance: strict: angle"), std::string::npos) << r.out;
}

TEST(ValidateCommand, MissingSceneFileExitsTwoNamingIt) {
  TempDir tmp;
  const std::string missing = (tmp.path / "no-such-scene.json").string();
  const CliResult r = cairn("validate " + missing, tmp);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;
  const CliResult k = cairn("validate no-such-scenario", tmp);
  EXPECT_EQ(k.status, 2);
  EXPECT_NE(k.err.find("no-such-scenario"), std::string::npos) << k.err;
}

TEST(ValidateCommand, BadSceneFileExitsTwoNamingIt) {
  TempDir tmp;
  const fs::path bad = tmp.path / "bad.json";
  std::ofstream(bad) << "{\"bodies\": [{\"name\": \"b\", \"mass\": -1, \"shapes\": []}]}";
  const CliResult r = cairn("validate " + bad.string(), tmp);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
}

TEST(ValidateCommand, UnwritableReportDirectoryExitsTwoNamingIt) {
  TempDir tmp;
  const fs::path file = tmp.path / "a-file";
  std::ofstream(file) << "not a directory";
  const std::string dir = (file / "report").string();  // under a regular file: cannot exist
  const CliResult r = cairn("validate hinge-pendulum-0.1 --steps 5 --report " + dir, tmp);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(dir), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("validating"), std::string::npos) << "nothing should run: " << r.out;
}

TEST(ScenesCommand, WritesEveryStandardSceneLoadable) {
  TempDir tmp;
  const CliResult r = cairn("scenes --out " + (tmp.path / "scenes").string(), tmp);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string& key : standardSceneNames()) {
    const fs::path p = tmp.path / "scenes" / (key + ".json");
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_NO_THROW((void)validationSpec(loadScene(p.string()))) << key;
  }
  const CliResult bad = cairn("scenes --out " + (tmp.path / "scenes" / "column-10.json" / "x").string(), tmp);
  EXPECT_EQ(bad.status, 2);
}

}  // namespace
}  // namespace cairn::validation
