/// @file
/// What the World reports, read after a step: contact begin/end events,
/// the pre-solve contact callback's view of a contact, broken joints, joint
/// forces and errors, and the numerical safety net's reports. Plain data; the
/// World fills them during World::step and they stay valid until the next
/// step (events) or until asked again (joint state).
#pragma once

#include "cairn/handles.hpp"
#include "cairn/math.hpp"

#include <cstdint>
#include <functional>
#include <string>

namespace cairn {

/// A joint that broke: its force or torque exceeded its threshold.
struct JointBreakEvent {
  int step = 0;
  JointId joint;
  std::string name;
  Real force = 0, torque = 0;
};

/// Contacts begun and ended, for sounds and damage: read after the step.
struct ContactEvent {
  enum class Type { Begin, End } type = Type::Begin;
  int step = 0;
  BodyId body_a, body_b;
  std::int32_t shape_a = -1, shape_b = -1;
  Vec3 point = Vec3::Zero();   ///< deepest point (world)
  Vec3 normal = Vec3::Zero();  ///< from a to b
  Real impulse = 0;            ///< total normal impulse of the step (N s); 0 for End
};

/// What a contact callback sees and may change, once per manifold per step
/// before any row is built: veto (enabled = false, e.g. a one-way platform),
/// or change friction and restitution for this contact.
struct ContactInfo {
  BodyId body_a, body_b;
  std::int32_t shape_a = -1, shape_b = -1;
  Vec3 normal = Vec3::Zero();  ///< from a to b
  int count = 0;
  Vec3 points[4];
  Real depths[4] = {};
  Vec3 relative_velocity = Vec3::Zero();  ///< of b's deepest point relative to a's
  Real friction = 0, restitution = 0;
  bool enabled = true;
};
using ContactCallback = std::function<void(ContactInfo&)>;

/// A joint's constraint force and torque on each body over the last step
/// (its impulses divided by the step); zero once broken.
struct JointFeedback {
  Vec3 force_a = Vec3::Zero(), torque_a = Vec3::Zero();  ///< on body a, torque about its center of mass
  Vec3 force_b = Vec3::Zero(), torque_b = Vec3::Zero();  ///< on body b
};

/// Position error of the joint now: the largest anchor separation (m) of its
/// positional rows and the largest angle error (rad) of its angular rows
/// (limits count only when violated).
struct JointError {
  Real linear = 0;
  Real angular = 0;
};

/// A non-finite value caught by the guard (docs/extremes.md, "Safety nets").
/// The guard stops the step for the island it appeared in: every awake
/// dynamic body of that island goes back to its state at the start of the
/// step, at rest, and stays there for the rest of the step; other islands
/// keep stepping. Stages, in step order: "step start" (a state set through
/// the API between steps), "velocity integration", "row building",
/// "constraint solve", "position integration".
struct NumericalEvent {
  int step = 0;
  BodyId body;            ///< the body found non-finite (for a row: its dynamic body)
  std::string body_name;
  std::string stage;
  std::int32_t island = -1;  ///< island index of this step; -1: the body was in none (kinematic, or at step start)
  int bodies_restored = 0;   ///< bodies put back to their step-start state
  std::string detail;        ///< what was non-finite, e.g. "linear velocity" or "joint 'hinge' row 1: rhs"
};

/// A step the engine took but could not take accurately, reported rather
/// than passed on silently (docs/extremes.md, "Safety nets"). One entry per
/// body and kind, counting the (sub)steps it happened in. Kinds:
///   "gyroscopic solve"  the implicit-midpoint gyroscopic step did not solve
///                       its equation to 1e-10 |L| (h |w| too large for the
///                       body's inertia ratio): energy and angular momentum
///                       are not conserved in those steps; substeps with
///                       h |w| < 1 restore it.
struct Diagnostic {
  BodyId body;
  std::string body_name;
  std::string kind;
  std::string detail;
  int first_step = 0;
  int count = 0;  ///< how many (sub)steps it happened in
};

}  // namespace cairn
