/// @file
/// A scene in memory: what a scene file holds, independent of any engine.
/// The same SceneDesc builds a cairn World (world/world.hpp) or, for
/// validation, a Bullet world (validation/bullet_oracle.hpp).
#pragma once

#include "cairn/defs.hpp"
#include "cairn/settings.hpp"

#include <string>
#include <vector>

namespace cairn {

class World;
/// A whole scene: gravity, step, solver settings, bodies, springs, joints.
struct SceneDesc {
  std::string path;  ///< where it was read from, for messages ("" if built in code)
  Vec3 gravity = Vec3(0, Real(-9.81), 0);  ///< m/s^2
  Real dt = Real(1) / 60;  ///< time step (s)
  int steps = 600;         ///< steps `cairn run` takes
  SolverSettings solver;   ///< the World's solver settings
  std::vector<BodyDef> bodies;     ///< in file order
  std::vector<SpringDef> springs;  ///< in file order
  std::vector<JointDef> joints;    ///< in file order
  std::string validation_json;  ///< the raw "validation" block, read by validation/

  int bodyIndex(const std::string& name) const {  ///< index in bodies, -1 when none
    for (size_t i = 0; i < bodies.size(); ++i)
      if (bodies[i].name == name) return static_cast<int>(i);
    return -1;
  }
};

/// Build a World from a scene. Validates everything first: on bad input it
/// throws InputError and builds nothing.
World buildWorld(const SceneDesc& scene);

}  // namespace cairn
