/// @file
/// The fixed-step driver: a game loop's bridge from variable frame times to
/// the fixed steps a World wants (Glenn Fiedler, "Fix Your Timestep!", 2004;
/// the same loop as Box2D's and Jolt's samples).
///
/// Each frame the driver adds the frame's duration to an accumulator and
/// takes as many whole steps of h as the accumulator holds; the remainder,
/// less than one step, waits for the next frame. Rendering then sits between
/// the last two physics states: with alpha = accumulator / h in [0, 1), a
/// body is drawn at
///     p = (1 - alpha) p_prev + alpha p_now,  q = slerp(q_prev, q_now, alpha),
/// which is the pose at physics time t_now - (1 - alpha) h. Drawn poses lag
/// the simulation by less than one step and never jitter with the frame rate.
///
/// The spiral of death: when a frame needs more steps than the machine can
/// run in one frame, the next frame is longer still and needs even more.
/// The driver runs at most `max_steps_per_frame` steps per frame and drops
/// the whole steps beyond it (keeping the fraction of a step), so a slow
/// machine sees the world in slow motion instead of freezing. The time
/// dropped is counted in droppedTime().
///
/// Round-off: frame times that add up to whole steps in exact arithmetic
/// (six frames of 1/360 s against h = 1/60 s) may sum to a hair below them
/// in floating point. The driver takes a step when the accumulator is within
/// 1e-9 h of it, so such sequences give the exact step count; a step is
/// never taken more than 1e-9 h early.
#pragma once

#include "cairn/handles.hpp"
#include "cairn/math.hpp"

#include <cstdint>
#include <vector>

namespace cairn {

class World;

/// How a FixedStepDriver steps its World.
struct FixedStepSettings {
  Real step = Real(1) / 60;      ///< h, the fixed step (s); > 0 and finite
  int max_steps_per_frame = 8;   ///< the spiral-of-death cap; >= 1
};

/// Runs a World at fixed steps from variable frame times and hands out
/// interpolated poses for rendering. It keeps a reference to the World,
/// which must outlive it. Single-threaded, like the World.
class FixedStepDriver {
 public:
  /// Throws InputError (object "fixed step driver") on a step that is not
  /// positive and finite or a cap below 1.
  explicit FixedStepDriver(World& world, const FixedStepSettings& settings = {});

  /// Adds `frame_seconds` (>= 0, finite; else InputError) to the
  /// accumulator and runs the whole steps it holds, at most
  /// max_steps_per_frame. Returns the number of steps run.
  int advance(Real frame_seconds);

  /// accumulator / h, in [0, 1): how far rendering sits from the previous
  /// physics state towards the current one.
  Real alpha() const;
  /// Time waiting in the accumulator (s), in [0, h).
  Real accumulator() const { return accumulator_; }
  /// Physics time of the interpolated poses: World::time() - (1 - alpha) h
  /// (World::time() before any step).
  Real renderTime() const;

  /// The body's pose for drawing: position lerped and orientation slerped
  /// between its pose before the last step and its pose now. A body created
  /// or teleported since the last step is drawn where it is now.
  Transform interpolatedTransform(BodyId body) const;

  /// Forgets the previous poses, so every body is drawn where it is now
  /// (after teleporting bodies or restoring a snapshot).
  void resetInterpolation();

  /// Steps run by this driver, and time dropped by the cap (s).
  std::int64_t steps() const { return steps_; }
  Real droppedTime() const { return dropped_; }  ///< time dropped by the cap (s)
  const FixedStepSettings& settings() const { return settings_; }  ///< the settings given

 private:
  struct Saved {
    std::uint32_t generation = 0;
    bool valid = false;
    Transform before;  // the pose before the last step
    Transform after;   // the pose after it: a differing pose now means a teleport
  };
  void savePoses();
  void recordAfter();

  World& world_;
  FixedStepSettings settings_;
  Real accumulator_ = 0;
  Real dropped_ = 0;
  std::int64_t steps_ = 0;
  std::vector<Saved> saved_;  // by body slot index
};

}  // namespace cairn
