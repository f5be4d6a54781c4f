// Recording a replay (replay.hpp) from a cairn World: the one place the
// viewer reads the engine's state. After World::step, record() reads the
// bodies (pose, velocities, sleep), the touching contacts (points, normal,
// impulses), the joints (anchors, axis, error, force feedback) and derives
// the islands.
#pragma once

#include "cairn/scene.hpp"
#include "validation/replay.hpp"

#include <string>

namespace cairn {
class World;
}

namespace cairn::validation {

// The bodies (shapes relative to the center of mass, as the World keeps
// them), the joints and the settings of `world`, with no frames.
Replay describeWorld(const World& world, Real dt);
// The same for the World `scene` builds (throws InputError as buildWorld).
Replay describeScene(const SceneDesc& scene);

// Runs `scene` for scene.steps steps, recording every step into `out`.
// Returns "" or why the run stopped early (a non-finite state: the body,
// the stage and the step); `out` then holds the frames before it.
std::string recordRun(const SceneDesc& scene, Replay& out);

class ReplayRecorder {
 public:
  // Fills `out` with describeWorld and records the current state as frame 0.
  ReplayRecorder(const World& world, Real dt, Replay& out);
  // Appends a frame: call after each World::step.
  void record(const World& world);

 private:
  Replay& out_;
  std::vector<std::int32_t> parent_;  // union-find scratch for the islands
};

}  // namespace cairn::validation
