// Shared helpers for the physics tests.
#pragma once

#include "world/world_access.hpp"

#include <string>

namespace cairn::test {

inline BodyDef boxDef(const std::string& name, const Vec3& pos, Real mass = 1, const Vec3& he = Vec3(0.5, 0.5, 0.5)) {
  BodyDef d;
  d.name = name;
  d.mass = mass;
  d.position = pos;
  d.shapes.push_back(ShapeDesc::box(he));
  return d;
}

inline BodyDef sphereDef(const std::string& name, const Vec3& pos, Real mass = 1, Real r = 0.5) {
  BodyDef d;
  d.name = name;
  d.mass = mass;
  d.position = pos;
  d.shapes.push_back(ShapeDesc::sphere(r));
  return d;
}

inline std::string sourcePath(const std::string& rel) { return std::string(CAIRN_SOURCE_DIR) + "/" + rel; }

}  // namespace cairn::test
