#include "cairn/error.hpp"
#include "cairn/scene.hpp"
#include "world/scene_json.hpp"
#include "cairn/world.hpp"

#include <cmath>

namespace cairn {

World buildWorld(const SceneDesc& scene) {
  if (!scene.gravity.allFinite()) throw InputError("scene", "gravity", "must be finite");
  if (!std::isfinite(scene.dt) || scene.dt <= 0)
    throw InputError("scene", "dt", "must be positive and finite (got " + std::to_string(scene.dt) + ")");
  if (scene.steps < 0) throw InputError("scene", "steps", "must be >= 0");
  World world(WorldDef{scene.gravity, scene.solver});
  for (const auto& b : scene.bodies) world.createBody(b);
  for (const auto& s : scene.springs) world.createSpring(s);
  for (const auto& j : scene.joints) world.createJoint(j);
  return world;
}

// The World checks every definition on creation, so building a throw-away
// World is the one place where scene validity is decided.
void validateScene(const SceneDesc& scene) { (void)buildWorld(scene); }

}  // namespace cairn
