// Bad scene files are refused with an InputError that names the file, the
// object, the field and what is allowed, never with another exception:
// missing keys, keys of the wrong JSON type, integers that do not fit their
// field (refused, never wrapped), values outside the ranges a step can
// carry, nesting and counts beyond the input limits.
#include "cairn/error.hpp"
#include "world/scene_json.hpp"
#include "cairn/world.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace cairn {
namespace {

const char* kScene = R"({
  "steps": 10,
  "solver": {"iterations": 20, "seed": 7},
  "bodies": [
    {"name": "ground", "type": "static", "shapes": [{"type": "plane", "normal": [0, 1, 0], "offset": 0}]},
    {"name": "a", "mass": 2, "position": [0, 1, 0], "collision_group": 1, "collision_mask": 3,
     "shapes": [{"type": "box", "half_extents": [0.5, 0.5, 0.5]}]},
    {"name": "b", "position": [2, 1, 0], "shapes": [{"type": "sphere", "radius": 0.2}]}
  ],
  "springs": [{"name": "s", "bodies": ["a", "b"], "anchors": [[0, 1, 0], [2, 1, 0]], "stiffness": 10}],
  "joints": [{"name": "h", "type": "hinge", "bodies": ["world", "a"], "anchor": [0, 2, 0], "axis": [0, 0, 1],
              "limits": {"lower": -1, "upper": 1}, "motor": {"target_velocity": 1, "max_force": 5}}]
})";

// The scene with the first `from` replaced by `to`.
std::string edited(const std::string& from, const std::string& to) {
  std::string text = kScene;
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

// Parses the edited scene and checks that it is refused with an InputError
// whose object, field and message say what is wrong.
void expectRefused(const std::string& from, const std::string& to, const std::string& object, const std::string& field,
                   const std::string& allowed) {
  try {
    parseScene(edited(from, to), "bad.json");
    ADD_FAILURE() << "accepted: " << to;
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), "bad.json: " + object) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(e.message().find(allowed), std::string::npos) << "'" << allowed << "' missing in: " << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what();
  }
}

TEST(SceneRefusal, TheUneditedSceneLoads) { EXPECT_NO_THROW(parseScene(kScene, "good.json")); }

TEST(SceneRefusal, MissingRequiredKeysNameTheFieldAndWhatItNeeds) {
  expectRefused("\"half_extents\": [0.5, 0.5, 0.5]", "\"position\": [0, 0, 0]", "body 'a'", "shapes[0].half_extents",
                "missing: an array of 3 numbers");
  expectRefused("\"radius\": 0.2", "\"position\": [0, 0, 0]", "body 'b'", "shapes[0].radius", "missing: a number");
  expectRefused(", \"stiffness\": 10", "", "spring 's'", "stiffness", "missing: a number");
  expectRefused(", \"max_force\": 5", "", "joint 'h'", "motor.max_force", "missing: a motor needs its largest force (N) or torque (N m)");
  expectRefused(", \"upper\": 1", "", "joint 'h'", "limits.upper", "missing: a number");
  expectRefused("{\"type\": \"box\", ", "{", "body 'a'", "shapes[0].type", "missing: a string");
  expectRefused("\"type\": \"hinge\", ", "", "joint 'h'", "type", "missing: a string");
  expectRefused("\"bodies\": [\"a\", \"b\"], ", "", "spring 's'", "bodies", "missing: [a, b]");
  expectRefused("{\"name\": \"b\", ", "{", "body #2", "name", "missing: a string");
}

TEST(SceneRefusal, KeysOfTheWrongTypeAreRefusedWithWhatWasFound) {
  expectRefused("\"collision_mask\": 3", "\"collision_mask\": null", "body 'a'", "collision_mask",
                "must be an integer in [0, 4294967295] (got null)");
  expectRefused("\"seed\": 7", "\"seed\": \"x\"", "solver", "seed",
                "must be an integer in [0, 18446744073709551615] (got \"x\")");
  expectRefused("\"mass\": 2", "\"mass\": \"2\"", "body 'a'", "mass", "must be a number (got \"2\")");
  expectRefused("\"mass\": 2", "\"mass\": [2]", "body 'a'", "mass", "must be a number (got an array of 1)");
  expectRefused("[{\"type\": \"sphere\", \"radius\": 0.2}]", "{\"type\": \"sphere\", \"radius\": 0.2}", "body 'b'",
                "shapes", "must be an array of shapes (got an object)");
  expectRefused("\"steps\": 10", "\"steps\": 10.5", "scene", "steps", "must be an integer in [0, 2147483647] (got 10.5)");
  expectRefused("\"steps\": 10", "\"steps\": true", "scene", "steps", "must be an integer");
}

// 4294967297 = 2^32 + 1 once ran a single step (wrapped into int), and a
// collision group of 2^32 became 0 (wrapped into uint32): both are refused.
TEST(SceneRefusal, IntegersThatDoNotFitTheirFieldAreRefusedNotWrapped) {
  expectRefused("\"steps\": 10", "\"steps\": 4294967297", "scene", "steps",
                "must be an integer in [0, 2147483647] (got 4294967297)");
  expectRefused("\"steps\": 10", "\"steps\": -1", "scene", "steps", "must be an integer in [0, 2147483647] (got -1)");
  expectRefused("\"collision_group\": 1", "\"collision_group\": 4294967296", "body 'a'", "collision_group",
                "must be an integer in [0, 4294967295] (got 4294967296)");
  expectRefused("\"collision_mask\": 3", "\"collision_mask\": -1", "body 'a'", "collision_mask",
                "must be an integer in [0, 4294967295] (got -1)");
  expectRefused("\"seed\": 7", "\"seed\": 18446744073709551616", "solver", "seed", "must be an integer");
  expectRefused("\"iterations\": 20", "\"iterations\": 0", "solver", "iterations", "must be an integer in [1, 2147483647]");
  // The largest values that fit are kept exactly.
  const SceneDesc s = parseScene(edited("\"collision_mask\": 3", "\"collision_mask\": 4294967295"), "edge.json");
  EXPECT_EQ(s.bodies[1].collision_mask, 4294967295u);
  EXPECT_EQ(parseScene(edited("\"seed\": 7", "\"seed\": 18446744073709551615"), "e.json").solver.seed,
            18446744073709551615ull);
}

// Names go into messages, CSV rows and metrics as they are: control
// characters (a newline, a NUL) are refused; commas and quotes are fine
// (the CSV writer quotes them).
TEST(SceneRefusal, NamesWithControlCharactersAreRefused) {
  expectRefused("\"name\": \"b\"", "\"name\": \"b\\nc\"", "body #2", "name", "without control characters");
  expectRefused("\"name\": \"s\"", "\"name\": \"s\\u0000\"", "spring #0", "name", "without control characters");
  std::string text = kScene;
  for (size_t at; (at = text.find("\"b\"")) != std::string::npos;) text.replace(at, 3, "\"b, \\\"the ball\\\"\"");
  EXPECT_EQ(parseScene(text, "ok.json").bodies[2].name, "b, \"the ball\"");
}

// Values a step cannot carry in double precision are refused at load with
// the range (include/cairn/limits.hpp derives it): each of these once ran
// into an infinite energy written as null in the metrics, or a zero mass.
TEST(SceneRefusal, ValuesOutsideTheRepresentableRangesAreRefusedWithTheRange) {
  expectRefused("\"position\": [2, 1, 0]", "\"position\": [2, 1, 0], \"linear_velocity\": [1e200, 0, 0]", "body 'b'",
                "linear_velocity", "must have finite components with magnitude at most 1e+20 (got 1e+200)");
  expectRefused("\"position\": [0, 1, 0]", "\"position\": [0, 1e21, 0]", "body 'a'", "position", "at most 1e+20");
  expectRefused("\"radius\": 0.2", "\"radius\": 1e-30", "body 'b'", "shapes[0].radius",
                "must lie in [1e-20, 1e+20] (got 1e-30)");
  expectRefused("\"half_extents\": [0.5, 0.5, 0.5]", "\"half_extents\": [0.5, 1e25, 0.5]", "body 'a'",
                "shapes[0].half_extents", "must lie in [1e-20, 1e+20] (got 1e+25)");
  expectRefused("\"mass\": 2", "\"mass\": 1e300", "body 'a'", "mass", "must lie in [1e-20, 1e+20] (got 1e+300)");
  expectRefused("\"mass\": 2", "\"mass\": 2, \"inertia\": [[1e-70, 0, 0], [0, 1e-70, 0], [0, 0, 1e-70]]", "body 'a'",
                "inertia", "eigenvalues must be at least 1e-60");
  expectRefused("\"stiffness\": 10", "\"stiffness\": 1e30", "spring 's'", "stiffness", "at most 1e+20");
  expectRefused("\"max_force\": 5", "\"max_force\": 1e40", "joint 'h'", "motor.max_force", "at most 1e+20");
  expectRefused("\"steps\": 10", "\"steps\": 10, \"gravity\": [0, -1e100, 0]", "scene", "gravity", "at most 1e+20");
  expectRefused("\"steps\": 10", "\"steps\": 10, \"dt\": 1e-300", "scene", "dt", "must lie in [1e-20, 1e+20]");
  expectRefused("\"iterations\": 20", "\"iterations\": 20, \"slop\": 1e99", "solver", "slop", "at most 1e+20");
  // Infinity where it means "never" stays allowed, and the edges of the
  // ranges load.
  EXPECT_NO_THROW(parseScene(edited("\"radius\": 0.2", "\"radius\": 1e-20"), "edge.json"));
  EXPECT_NO_THROW(parseScene(edited("\"position\": [2, 1, 0]", "\"position\": [2, 1e20, 0]"), "edge.json"));
}

// A convex hull 10 km from its body's origin loads, with the mass of the
// same hull at the origin (its inertia is computed about its own centroid;
// collision_hull_test.cpp checks the tensor).
TEST(SceneRefusal, HullFarFromTheBodyOriginLoads) {
  std::string points;
  for (int i = 0; i < 8; ++i)
    points += std::string(i ? ", " : "") + "[" + (i & 1 ? "10000.05" : "9999.95") + ", " + (i & 2 ? "0.05" : "-0.05") +
              ", " + (i & 4 ? "0.05" : "-0.05") + "]";
  const SceneDesc s = parseScene(edited("{\"type\": \"sphere\", \"radius\": 0.2}",
                                        "{\"type\": \"convex_hull\", \"points\": [" + points + "]}"),
                                 "far.json");
  World w = buildWorld(s);
  // Density 1000 x (0.1 m)^3: 1 kg, to the round-off of coordinates near
  // 1e4 (ulp 2e-12, relative 2e-11 of the 0.1 m side, times 3 for a volume).
  EXPECT_NEAR(w.mass(w.findBody("b")), 1.0, 1e-9);
}

// Deep nesting is refused while parsing: 100,000 levels once overflowed the
// stack when the validation block was copied back to text.
TEST(SceneRefusal, NestingDeeperThanTheLimitIsRefusedWhileParsing) {
  const int deep = 100000;
  const std::string text = "{\"validation\": " + std::string(deep, '[') + std::string(deep, ']') + "}";
  try {
    parseScene(text, "deep.json");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("deep.json: arrays and objects nested more than 64 deep (limit json_depth = 64"),
              std::string::npos)
        << e.what();
  }
  // Exactly at the limit: the top-level object plus 63 arrays.
  InputLimits limits;
  const std::string at_limit = "{\"validation\": " + std::string(63, '[') + std::string(63, ']') + "}";
  EXPECT_NO_THROW(parseScene(at_limit, "ok.json", limits));  // the block itself is judged by validation/
  limits.json_depth = 63;
  EXPECT_THROW(parseScene(at_limit, "deep.json", limits), InputError);
}

// Counts beyond the limits are refused before anything is built for them,
// naming the limit and how to raise it.
TEST(SceneRefusal, CountsBeyondTheLimitsAreRefusedWithTheLimitsName) {
  const auto refusedWith = [](const std::string& text, const InputLimits& limits, const std::string& what) {
    try {
      parseScene(text, "big.json", limits);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  const struct {
    std::uint64_t InputLimits::*limit;
    std::uint64_t value;
    const char* message;
  } cases[] = {
      {&InputLimits::bodies, 2,
       "big.json: scene: field 'bodies': 3 entries exceed the limit (limit bodies = 2; raise it with --limit bodies=N"},
      {&InputLimits::shapes_per_body, 0, "field 'shapes': 1 entries exceed the limit (limit shapes_per_body = 0"},
      {&InputLimits::springs, 0, "(limit springs = 0"},
      {&InputLimits::joints, 0, "(limit joints = 0"},
      {&InputLimits::iterations, 19, "solver: field 'iterations': 20 exceeds the limit (limit iterations = 19"},
      {&InputLimits::file_bytes, 100, "bytes exceed the limit (limit file_bytes = 100"},
  };
  for (const auto& c : cases) {
    InputLimits l;
    l.*c.limit = c.value;
    refusedWith(kScene, l, c.message);
  }
}

TEST(SceneRefusal, OnlyRegularFilesAreReadAsScenes) {
  EXPECT_THROW(loadScene("/dev/zero"), InputError);
  EXPECT_THROW(loadScene(std::string(CAIRN_SOURCE_DIR) + "/scenes"), InputError);
}

}  // namespace
}  // namespace cairn
