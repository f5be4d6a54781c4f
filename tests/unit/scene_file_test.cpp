// Scene files: a valid scene loads; each bad input of the body, shape and
// constraint fields is rejected with a message naming the file, the object
// and the field, and the C++ API leaves the world unchanged.
#include "cairn/error.hpp"
#include "test_helpers.hpp"
#include "world/scene_json.hpp"

#include <gtest/gtest.h>

#include <string>

namespace cairn {
namespace {

const char* kValid = R"({
  "gravity": [0, -9.81, 0], "dt": 0.01, "steps": 10,
  "solver": {"iterations": 20, "erp": 0.3, "cfm": 1e-9},
  "bodies": [
    {"name": "ground", "type": "static", "shapes": [{"type": "plane", "normal": [0, 1, 0], "offset": 0}]},
    {"name": "a", "mass": 2, "position": [0, 1, 0], "shapes": [{"type": "box", "half_extents": [0.5, 0.5, 0.5]}]},
    {"name": "b", "density": 500, "position": [2, 1, 0], "orientation": [1, 0, 0, 0],
     "shapes": [{"type": "capsule", "radius": 0.2, "half_height": 0.3},
                {"type": "sphere", "radius": 0.2, "position": [0, 0.6, 0]}]}
  ],
  "springs": [{"bodies": ["a", "b"], "anchors": [[0, 1, 0], [2, 1, 0]], "stiffness": 10, "damping": 1}],
  "joints": [{"name": "h", "type": "hinge", "bodies": ["world", "a"], "anchor": [0, 2, 0], "axis": [0, 0, 1],
              "limits": {"lower": -1, "upper": 1}, "motor": {"target_velocity": 1, "max_force": 5}}]
})";

TEST(SceneFile, ValidSceneLoadsAndBuilds) {
  const SceneDesc s = parseScene(kValid, "valid.json");
  EXPECT_EQ(s.bodies.size(), 3u);
  EXPECT_EQ(s.solver.iterations, 20);
  EXPECT_DOUBLE_EQ(s.dt, 0.01);
  World w = buildWorld(s);
  EXPECT_EQ(w.bodyCount(), 3);
  EXPECT_EQ(cairn::detail::internals(w).jointSlots(), 1);
  EXPECT_DOUBLE_EQ(cairn::detail::internals(w).body(BodyId{1}).mass, 2);
}

// Motors, limits and a six_dof joint with one axis of each kind.
const char* kValidJoints = R"({
  "bodies": [
    {"name": "arm", "mass": 1, "shapes": [{"type": "box", "half_extents": [0.5, 0.1, 0.1]}]},
    {"name": "cart", "mass": 1, "position": [3, 0, 0], "shapes": [{"type": "box", "half_extents": [0.2, 0.2, 0.2]}]},
    {"name": "puck", "mass": 1, "position": [6, 0, 0], "shapes": [{"type": "sphere", "radius": 0.2}]}
  ],
  "joints": [
    {"name": "servo", "type": "hinge", "bodies": ["arm", "world"], "axis": [0, 0, 1],
     "limits": {"lower": -0.5, "upper": 1.2, "restitution": 0.3},
     "motor": {"target_position": 0.8, "max_force": 4, "frequency": 2, "damping_ratio": 1}},
    {"name": "rail", "type": "slider", "bodies": ["cart", "world"], "anchor": [3, 0, 0], "axis": [1, 0, 0],
     "limits": {"lower": 0.1, "upper": 0.1, "stiffness": 100, "damping": 2},
     "motor": {"target_velocity": 0.5, "max_force": 20, "damping": 10}},
    {"name": "six", "type": "six_dof", "bodies": ["puck", "world"], "anchor": [6, 0, 0],
     "axis": [1, 0, 0], "axis2": [0, 1, 0],
     "dofs": {"translation_x": {"mode": "free"},
              "translation_y": {"mode": "limited", "limits": {"lower": -0.2, "upper": 0.1}},
              "translation_z": {"mode": "locked"},
              "rotation_x": {"motor": {"target_velocity": 2, "max_force": 3}},
              "rotation_y": {"spring": {"rest": 0.1, "stiffness": 50, "damping": 1}},
              "rotation_z": {"mode": "limited", "limits": {"lower": -0.3, "upper": 1.4}}}}
  ]
})";

// Replaces the first occurrence of `from` in the valid scene by `to`, parses,
// and returns the error message ("" if it parsed).
std::string errorFor(const std::string& from, const std::string& to, const char* base = kValid) {
  std::string text = base;
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  text.replace(pos, from.size(), to);
  try {
    parseScene(text, "scene.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expectError(const std::string& from, const std::string& to, const std::string& object, const std::string& field,
                 const char* base = kValid) {
  const std::string msg = errorFor(from, to, base);
  EXPECT_NE(msg.find("scene.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find(object), std::string::npos) << "object '" << object << "' missing in: " << msg;
  EXPECT_NE(msg.find(field), std::string::npos) << "field '" << field << "' missing in: " << msg;
}

TEST(SceneFile, MalformedAndTruncatedFilesAreRejected) {
  EXPECT_NE(errorFor("\"steps\": 10,", "\"steps\": 10,,").find("malformed JSON"), std::string::npos);
  std::string truncated = std::string(kValid).substr(0, 120);
  try {
    parseScene(truncated, "t.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.json"), std::string::npos);
  }
}

TEST(SceneFile, EachBadBodyInputNamesObjectAndField) {
  expectError("\"steps\": 10", "\"stepz\": 10", "scene", "stepz");                        // unknown key
  expectError("\"type\": \"box\"", "\"type\": \"cube\"", "body 'a'", "shapes[0].type");  // unknown shape
  expectError("{\"name\": \"a\", ", "{", "body #1", "name");                             // missing name
  expectError("\"mass\": 2", "\"mass\": 0", "body 'a'", "mass");
  expectError("\"mass\": 2", "\"mass\": -1", "body 'a'", "mass");
  expectError("\"density\": 500", "\"density\": -3", "body 'b'", "density");
  expectError("\"orientation\": [1, 0, 0, 0]", "\"orientation\": [0, 0, 0, 0]", "body 'b'", "orientation");
  expectError("\"half_extents\": [0.5, 0.5, 0.5]", "\"half_extents\": [0.5, 0, 0.5]", "body 'a'", "shapes[0].half_extents");
  expectError("\"radius\": 0.2, \"half_height\"", "\"radius\": -0.2, \"half_height\"", "body 'b'", "shapes[0].radius");
  expectError("\"dt\": 0.01", "\"dt\": 0", "scene", "dt");
  expectError("\"dt\": 0.01", "\"dt\": -0.01", "scene", "dt");
  expectError("\"iterations\": 20", "\"iterations\": 0", "solver", "iterations");
}

// JSON has no NaN or infinity literal; an overflowing number (1e999) is the
// only way to write one, and it is rejected with its line. Through the API,
// non-finite values are rejected field by field.
TEST(SceneFile, NonFiniteValuesAreRejected) {
  const std::string msg = errorFor("\"mass\": 2,", "\"mass\": 2, \"linear_velocity\": [1e999, 0, 0],");
  EXPECT_NE(msg.find("scene.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("line 6"), std::string::npos) << msg;
  World w;
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  for (int field = 0; field < 4; ++field) {
    BodyDef d = test::boxDef("a", Vec3::Zero());
    const char* name = "";
    switch (field) {
      case 0: d.position.x() = nan; name = "position"; break;
      case 1: d.linear_velocity.y() = nan; name = "linear_velocity"; break;
      case 2: d.angular_velocity.z() = nan; name = "angular_velocity"; break;
      case 3: d.mass = nan; name = "mass"; break;
    }
    try {
      w.createBody(d);
      FAIL() << name;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), name);
      EXPECT_EQ(e.object(), "body 'a'");
    }
  }
  EXPECT_EQ(w.bodyCount(), 0);
}

TEST(SceneFile, EachBadJointInputNamesObjectAndField) {
  expectError("[\"world\", \"a\"]", "[\"world\", \"nobody\"]", "joint 'h'", "bodies[1]");
  expectError("[\"world\", \"a\"]", "[\"a\", \"a\"]", "joint 'h'", "bodies");
  expectError("\"axis\": [0, 0, 1]", "\"axis\": [0, 0, 0]", "joint 'h'", "axis");
  expectError("\"lower\": -1, \"upper\": 1", "\"lower\": 1, \"upper\": -1", "joint 'h'", "limits");
  expectError("\"max_force\": 5", "\"max_force\": -5", "joint 'h'", "motor.max_force");
  expectError("\"axis\": [0, 0, 1],", "\"axis\": [0, 0, 1], \"erp\": 1.5,", "joint 'h'", "erp");
  expectError("\"axis\": [0, 0, 1],", "\"axis\": [0, 0, 1], \"cfm\": -1,", "joint 'h'", "cfm");
  expectError("\"type\": \"hinge\"", "\"type\": \"hing\"", "joint 'h'", "type");
}

TEST(SceneFile, MotorsLimitsAndSixDofLoadAndBuild) {
  const SceneDesc s = parseScene(kValidJoints, "joints.json");
  ASSERT_EQ(s.joints.size(), 3u);
  EXPECT_EQ(s.joints[0].motor.target_position, 0.8);
  EXPECT_EQ(s.joints[1].motor.softness.damping, 10);
  const JointDef& six = s.joints[2];
  EXPECT_EQ(six.type, JointType::SixDof);
  EXPECT_EQ(six.dofs[1].mode, DofMode::Limited);
  EXPECT_EQ(six.dofs[1].limit.lower, -0.2);
  EXPECT_EQ(six.dofs[2].mode, DofMode::Locked);
  EXPECT_TRUE(six.dofs[3].motor.enabled);
  EXPECT_TRUE(six.dofs[4].spring.enabled);
  EXPECT_EQ(six.dofs[4].spring.rest, 0.1);
  World w = buildWorld(s);
  for (int k = 0; k < 10; ++k) w.step(1.0 / 60);
  EXPECT_TRUE(w.numericalEvents().empty());
}

TEST(SceneFile, EachBadMotorLimitAndSixDofInputNamesObjectAndField) {
  const auto bad = [](const std::string& from, const std::string& to, const std::string& object,
                      const std::string& field) { expectError(from, to, object, field, kValidJoints); };
  // Limits.
  bad(R"("lower": -0.5, "upper": 1.2)", R"("lower": 1.3, "upper": 1.2)", "joint 'servo'", "limits.lower");
  bad(R"("lower": -0.5, "upper": 1.2)", R"("lower": -4, "upper": 1.2)", "joint 'servo'", "limits.lower");
  bad(R"("stiffness": 100, "damping": 2})", R"("stiffness": 100, "damping": -2})", "joint 'rail'", "limits.damping");
  bad(R"("stiffness": 100, "damping": 2})", R"("frequency": -1})", "joint 'rail'", "limits.frequency");
  bad(R"("upper": 0.1, "stiffness")", R"("upper": 0.1, "restitution": 0.5, "stiffness")", "joint 'rail'",
      "limits.restitution");
  bad(R"("upper": 1.2, "restitution": 0.3})", R"("upper": 1.2, "restitution": 0.3, "stiffness": 10})",
      "joint 'servo'", "limits.restitution");
  // Motors.
  bad(R"("max_force": 4, )", "", "joint 'servo'", "motor.max_force");
  bad(R"("target_position": 0.8, )", "", "joint 'servo'", "motor.target_velocity");
  bad(R"("target_position": 0.8,)", R"("target_position": 0.8, "target_velocity": 1,)", "joint 'servo'",
      "motor.target_velocity");
  bad(R"("frequency": 2, "damping_ratio": 1})", R"("frequency": -2})", "joint 'servo'", "motor.frequency");
  bad(R"("frequency": 2, "damping_ratio": 1})", R"("erp": 0.5})", "joint 'servo'", "motor.erp");
  bad(R"("frequency": 2, "damping_ratio": 1})", R"("damping": 3})", "joint 'servo'", "motor.damping");
  bad(R"("max_force": 20, "damping": 10)", R"("max_force": 20, "stiffness": 10)", "joint 'rail'", "motor.stiffness");
  bad(R"("max_force": 20, "damping": 10)", R"("max_force": 20, "damping": -10)", "joint 'rail'", "motor.damping");
  // six_dof.
  bad(R"({"mode": "free"})", R"({"mode": "loose"})", "joint 'six'", "dofs.translation_x.mode");
  bad(R"({"mode": "free"})", R"({"mode": "free", "limits": {"lower": 0, "upper": 1}})", "joint 'six'",
      "dofs.translation_x.limits");
  bad(R"({"mode": "locked"})", R"({"mode": "limited"})", "joint 'six'", "dofs.translation_z.limits");
  bad(R"("lower": -0.2, "upper": 0.1)", R"("lower": 0.2, "upper": 0.1)", "joint 'six'",
      "dofs.translation_y.limits.lower");
  bad(R"("lower": -0.3, "upper": 1.4)", R"("lower": -0.3, "upper": 3.5)", "joint 'six'",
      "dofs.rotation_z.limits.upper");
  bad(R"("target_velocity": 2, "max_force": 3)", R"("target_velocity": 2)", "joint 'six'",
      "dofs.rotation_x.motor.max_force");
  bad(R"("rest": 0.1, "stiffness": 50, "damping": 1)", R"("rest": 0.1, "damping": 1)", "joint 'six'",
      "dofs.rotation_y.spring.stiffness");
  bad(R"("rest": 0.1, "stiffness": 50, "damping": 1)", R"("rest": 0.1, "frequency": -1)", "joint 'six'",
      "dofs.rotation_y.spring.frequency");
  bad(R"("rest": 0.1,)", R"("rest": 4,)", "joint 'six'", "dofs.rotation_y.spring.rest");
  bad(R"("rotation_x":)", R"("rotation_w":)", "joint 'six'", "dofs.rotation_w");
  bad(R"("axis2": [0, 1, 0])", R"("axis2": [1, 0.5, 0])", "joint 'six'", "axis2");
  bad(R"("type": "six_dof")", R"("type": "ball")", "joint 'six'", "dofs");
  // Limits and motors only where the type has them.
  bad(R"("axis": [1, 0, 0], "axis2")", R"("axis": [1, 0, 0], "motor": {"target_velocity": 1, "max_force": 1}, "axis2")",
      "joint 'six'", "motor");
}

TEST(SceneFile, PlaneOnADynamicBodyIsRejected) {
  expectError("\"type\": \"box\", \"half_extents\": [0.5, 0.5, 0.5]", "\"type\": \"plane\", \"normal\": [0, 1, 0]",
              "body 'a'", "shapes[0].type");
}

TEST(WorldApi, RejectedCreationLeavesTheWorldUnchanged) {
  World w;
  w.createBody(test::boxDef("a", Vec3::Zero()));
  BodyDef bad = test::boxDef("b", Vec3::Zero(), -1);
  EXPECT_THROW(w.createBody(bad), InputError);
  bad = test::boxDef("a", Vec3::Zero());  // duplicate name
  EXPECT_THROW(w.createBody(bad), InputError);
  bad = test::boxDef("c", Vec3::Zero());
  bad.orientation = Quat(0, 0, 0, 0);
  EXPECT_THROW(w.createBody(bad), InputError);
  EXPECT_EQ(w.bodyCount(), 1);

  JointDef j;
  j.type = JointType::Hinge;
  j.body_a = BodyId{0};
  j.body_b = BodyId{0};
  EXPECT_THROW(w.createJoint(j), InputError);
  j.body_b = BodyId{5};
  EXPECT_THROW(w.createJoint(j), InputError);
  EXPECT_EQ(cairn::detail::internals(w).jointSlots(), 0);
  EXPECT_THROW(w.step(0), InputError);
  EXPECT_THROW(w.step(-1), InputError);
  EXPECT_EQ(w.stepCount(), 0);
}

TEST(SceneFile, ShippedScenesLoad) {
  for (const char* f : {"scenes/falling-box.json", "scenes/spring-pendulum.json"}) {
    const SceneDesc s = loadScene(test::sourcePath(f));
    EXPECT_FALSE(s.bodies.empty()) << f;
  }
}

}  // namespace
}  // namespace cairn
