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
  int step = 0;   ///< the step it broke in (World::stepCount() before that step)
  JointId joint;  ///< the joint, removed from the World since
  std::string name;  ///< the joint's name from its definition
  Real force = 0;   ///< magnitude of the constraint force on body b over the step (N)
  Real torque = 0;  ///< magnitude of the constraint torque on body b about its anchor (N m)
};

/// Contacts begun and ended, for sounds and damage: read after the step.
struct ContactEvent {
  /// Whether the contact began or ended.
  enum class Type {
    Begin,  ///< the shapes started touching in this step
    End     ///< the shapes stopped touching (or one was removed)
  };
  Type type = Type::Begin;  ///< begin or end
  int step = 0;             ///< the step it happened in (World::stepCount() before that step)
  BodyId body_a;            ///< the body of shape_a
  BodyId body_b;            ///< the body of shape_b
  std::int32_t shape_a = -1;  ///< shape slot index (ShapeId::index) on body_a
  std::int32_t shape_b = -1;  ///< shape slot index (ShapeId::index) on body_b
  Vec3 point = Vec3::Zero();   ///< deepest point (world)
  Vec3 normal = Vec3::Zero();  ///< from a to b
  Real impulse = 0;            ///< total normal impulse of the step (N s); 0 for End
};

/// What a contact callback sees and may change, once per manifold per step
/// before any row is built: veto (enabled = false, e.g. a one-way platform),
/// or change friction and restitution for this contact.
struct ContactInfo {
  BodyId body_a;  ///< the body of shape_a
  BodyId body_b;  ///< the body of shape_b
  std::int32_t shape_a = -1;  ///< shape slot index (ShapeId::index) on body_a
  std::int32_t shape_b = -1;  ///< shape slot index (ShapeId::index) on body_b
  Vec3 normal = Vec3::Zero();  ///< from a to b
  int count = 0;         ///< points in use, 1 to 4
  Vec3 points[4];        ///< world points on a's surface
  Real depths[4] = {};   ///< penetration of each point (m, > 0 overlapping)
  Vec3 relative_velocity = Vec3::Zero();  ///< of b's deepest point relative to a's
  Real friction = 0;     ///< the contact's friction coefficient; may be changed (negative becomes 0)
  Real restitution = 0;  ///< the contact's restitution; may be changed (clamped to [0, 1])
  bool enabled = true;   ///< set false to veto the contact for this step
};
/// Called once per contact manifold per step, before any row is built (see ContactInfo).
using ContactCallback = std::function<void(ContactInfo&)>;

/// A joint's constraint force and torque on each body over the last step
/// (its impulses divided by the step); zero once broken.
struct JointFeedback {
  Vec3 force_a = Vec3::Zero();   ///< on body a (N)
  Vec3 torque_a = Vec3::Zero();  ///< on body a, about its center of mass (N m)
  Vec3 force_b = Vec3::Zero();   ///< on body b (N)
  Vec3 torque_b = Vec3::Zero();  ///< on body b, about its center of mass (N m)
};

/// Position error of the joint now: the largest anchor separation (m) of its
/// positional rows and the largest angle error (rad) of its angular rows
/// (limits count only when violated).
struct JointError {
  Real linear = 0;   ///< largest anchor separation (m)
  Real angular = 0;  ///< largest angle error (rad)
};

/// A non-finite value caught by the guard (docs/extremes.md, "Safety nets").
/// The guard stops the step for the island it appeared in: every awake
/// dynamic body of that island goes back to its state at the start of the
/// step, at rest, and stays there for the rest of the step; other islands
/// keep stepping. Stages, in step order: "step start" (a state set through
/// the API between steps), "velocity integration", "row building",
/// "constraint solve", "position integration".
struct NumericalEvent {
  int step = 0;           ///< the step it happened in (World::stepCount() before that step)
  BodyId body;            ///< the body found non-finite (for a row: its dynamic body)
  std::string body_name;  ///< that body's name
  std::string stage;       ///< where it was caught: one of the stages above, or "restitution"
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
  BodyId body;            ///< the body concerned; kWorldBody for world-wide kinds ("energy rise")
  std::string body_name;  ///< that body's name; "world" for kWorldBody
  std::string kind;       ///< what went wrong, e.g. "gyroscopic solve", "joint drift", "penetration"
  std::string detail;     ///< figures of the latest occurrence, for a human
  int first_step = 0;     ///< the first step it happened in (World::stepCount() before that step)
  int count = 0;  ///< how many (sub)steps it happened in
};

}  // namespace cairn
