// Shared helpers for the physics tests.
#pragma once

#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include <string>

namespace cairn::test {

inline BodyDef boxDef(const std::string& name, const Vec3& pos, Real mass = 1, const Vec3& he = Vec3(0.5, 0.5, 0.5)) {
  return scenarios::solid(name, mass, pos, ShapeDesc::box(he));
}

inline BodyDef sphereDef(const std::string& name, const Vec3& pos, Real mass = 1, Real r = 0.5) {
  return scenarios::solid(name, mass, pos, ShapeDesc::sphere(r));
}

// A world that never sleeps (default gravity: none), for tests that follow
// motions slowing below the sleep thresholds.
inline World awakeWorld(const Vec3& gravity = Vec3::Zero()) {
  World w(gravity);
  SolverSettings s;
  s.sleeping = false;
  w.setSettings(s);
  return w;
}

inline std::string sourcePath(const std::string& rel) { return std::string(CAIRN_SOURCE_DIR) + "/" + rel; }

}  // namespace cairn::test
