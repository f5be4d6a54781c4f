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

// Replaces the first occurrence of `from` in the valid scene by `to`, parses,
// and returns the error message ("" if it parsed).
std::string errorFor(const std::string& from, const std::string& to) {
  std::string text = kValid;
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

void expectError(const std::string& from, const std::string& to, const std::string& object, const std::string& field) {
  const std::string msg = errorFor(from, to);
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
