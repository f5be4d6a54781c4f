/// @file
/// The World: cairn's public face. It owns bodies, shapes, joints and
/// springs, hands out generation-checked handles, and advances the
/// simulation one fixed step at a time with World::step (the velocity-based
/// step of section 12.6.2 of Dunn and Parberry's "3D Math Primer for Graphics
/// and Game Development", 2nd ed.: forces, collision, constraint solve,
/// integration). docs/user-guide.md explains the game loop, units, frames
/// and threading rules; docs/architecture.md walks through one step.
///
/// Everything here is plain data in and out: definitions (cairn/defs.hpp),
/// settings (cairn/settings.hpp), handles (cairn/handles.hpp), events and
/// reports (cairn/events.hpp, cairn/stats.hpp) and queries (cairn/query.hpp).
/// The engine's internals are not part of this header.
///
/// Errors: bad definitions and bad values throw InputError naming the object
/// and the field, and change nothing; a handle whose object was destroyed
/// throws HandleError. No call leaves the World half-changed.
///
/// Threads: a World is not thread-safe; call it from one thread at a time.
/// World::step may use worker threads of its own (SolverSettings::threads);
/// its results are bit-identical whatever their number.
#pragma once

#include "cairn/defs.hpp"
#include "cairn/error.hpp"
#include "cairn/events.hpp"
#include "cairn/handles.hpp"
#include "cairn/math.hpp"
#include "cairn/query.hpp"
#include "cairn/settings.hpp"
#include "cairn/shape.hpp"
#include "cairn/stats.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace cairn {

namespace detail {
class WorldImpl;
struct WorldAccess;
}  // namespace detail

/// How a world starts: gravity and the solver settings.
struct WorldDef {
  Vec3 gravity = Vec3(0, Real(-9.81), 0);  ///< m/s^2
  SolverSettings settings;  ///< solver settings (validated by the World)
};

/// A contact of a body, as World::contacts(BodyId) reports it after a step.
struct ContactData {
  BodyId body_a;    ///< the body of shape_a; the normal points from a to b
  BodyId body_b;    ///< the body of shape_b
  ShapeId shape_a;  ///< the shape of body_a in contact
  ShapeId shape_b;  ///< the shape of body_b in contact
  Vec3 normal = Vec3::UnitY();  ///< world, unit, from a to b
  int count = 0;               ///< points, 1 to 4
  Vec3 points[4];              ///< world points midway between the surfaces
  Real depths[4] = {};         ///< penetration at detection (m, > 0 overlapping)
  Real normal_impulses[4] = {};  ///< N s over the last step
  Vec3 friction_impulses[4];     ///< N s over the last step, world vectors
  bool touching = false;  ///< some point within the contact margin in the last step
};
/// The simulation: bodies, shapes, joints, springs, and the step.
class World {
 public:
  explicit World(const WorldDef& def = {});  ///< an empty world
  explicit World(const Vec3& gravity) : World(WorldDef{gravity, {}}) {}  ///< an empty world with default settings
  ~World();
  World(World&&) noexcept;  ///< moves the whole simulation
  World& operator=(World&&) noexcept;  ///< moves the whole simulation
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // --- Bodies -------------------------------------------------------------
  /// Validates the whole definition, then creates; throws InputError and
  /// changes nothing on bad input. Bodies may be created and destroyed at
  /// any time between steps.
  BodyId createBody(const BodyDef& def);
  /// Destroys the body with its shapes, the joints and springs attached to
  /// it and its contacts (which end: contact End events are reported with
  /// the next step). Its handle, and theirs, become stale.
  void destroyBody(BodyId id);
  bool isValid(BodyId id) const;  ///< false for a destroyed or foreign body
  int bodyCount() const;                        ///< bodies alive
  std::vector<BodyId> bodies() const;           ///< every body alive, in creation slot order
  BodyId findBody(const std::string& name) const;  ///< kWorldBody when none
  const std::string& name(BodyId id) const;  ///< the body's name from its definition

  BodyType type(BodyId id) const;  ///< static, kinematic or dynamic
  /// Static, kinematic or dynamic at any time. A body becoming dynamic takes
  /// its mass from its definition (mass, or density times its shapes'
  /// volume); one becoming static or kinematic loses its contacts' cached
  /// impulses and wakes what touched it.
  void setType(BodyId id, BodyType type);

  /// Pose. The body frame is the one BodyDef::position and orientation
  /// placed; the center of mass may sit elsewhere in it.
  Transform transform(BodyId id) const;
  Vec3 centerOfMass(BodyId id) const;  ///< world frame
  /// Teleports the body (no velocity change); wakes it and what it touches.
  void setTransform(BodyId id, const Vec3& position, const Quat& orientation);
  Vec3 linearVelocity(BodyId id) const;   ///< of the center of mass, world frame, m/s
  Vec3 angularVelocity(BodyId id) const;  ///< world frame, rad/s
  void setLinearVelocity(BodyId id, const Vec3& v);  ///< of the center of mass (m/s); wakes the body
  void setAngularVelocity(BodyId id, const Vec3& w);  ///< world frame (rad/s); wakes the body
  Vec3 velocityAt(BodyId id, const Vec3& world_point) const;  ///< v + w x (x - c) at a world point (m/s)
  Real mass(BodyId id) const;        ///< kg; infinite for static and kinematic bodies
  Mat3 inertia(BodyId id) const;     ///< world frame, about the center of mass

  // --- Shapes ---------------------------------------------------------------
  /// Adds a shape to a body (at ShapeDesc::local in its body frame) and, for
  /// a dynamic body created from density, recomputes its mass properties
  /// (its center of mass moves, its body frame does not).
  ShapeId addShape(BodyId body, const ShapeDesc& shape);
  void removeShape(ShapeId shape);  ///< mass properties follow as for addShape
  std::vector<ShapeId> shapes(BodyId body) const;  ///< the body's shapes
  BodyId shapeBody(ShapeId shape) const;  ///< the body a shape belongs to
  const ShapeDesc& shape(ShapeId shape) const;  ///< a shape's description

  // --- Forces -----------------------------------------------------------------
  /// Forces and torques act over the next step and are then cleared;
  /// impulses change the velocity at once. All wake the body.
  void applyForce(BodyId id, const Vec3& force, const Vec3& world_point);
  void applyCentralForce(BodyId id, const Vec3& force);  ///< at the center of mass (N)
  void applyTorque(BodyId id, const Vec3& torque);  ///< world frame (N m)
  void applyImpulse(BodyId id, const Vec3& impulse, const Vec3& world_point);  ///< N s at a world point
  void applyAngularImpulse(BodyId id, const Vec3& angular_impulse);  ///< N m s, world frame
  /// Scripted motion of a kinematic body (m/s, rad/s).
  void setKinematicVelocity(BodyId id, const Vec3& linear, const Vec3& angular);

  // --- Joints and springs ---------------------------------------------------
  JointId createJoint(const JointDef& def);  ///< validates, then creates; InputError on bad input
  /// Removes the joint; the bodies it held are woken. Joints may be removed
  /// between any two steps (a wheel coming off a car).
  void destroyJoint(JointId id);
  bool isValid(JointId id) const;  ///< false for a destroyed or foreign joint
  JointId findJoint(const std::string& name) const;  ///< invalid (index -1) when none
  const JointDef& jointDef(JointId id) const;  ///< the definition the joint was made from
  /// Force and torque the joint applied over the last step, on each body.
  JointFeedback jointFeedback(JointId id) const;
  /// The joint's position error now (anchor separation, angle error).
  JointError jointError(JointId id) const;
  /// A joint whose force or torque passed its break threshold is broken: it
  /// no longer acts, and a JointBreakEvent was reported; its handle stays
  /// valid until destroyed.
  bool isBroken(JointId id) const;
  /// Motors: change a hinge's or slider's motor between steps.
  void setMotor(JointId id, const MotorDef& motor);

  SpringId createSpring(const SpringDef& def);  ///< validates, then creates; InputError on bad input
  void destroySpring(SpringId id);  ///< removes the spring; its handle becomes stale
  bool isValid(SpringId id) const;  ///< false for a destroyed or foreign spring

  // --- Contacts -----------------------------------------------------------------
  /// Every touching contact of a body after the last step.
  std::vector<ContactData> contacts(BodyId id) const;
  /// Every touching contact in the world after the last step.
  std::vector<ContactData> contacts() const;
  /// Begin and End events of the last step (begin events carry the step's
  /// normal impulse, for sounds and damage).
  std::span<const ContactEvent> contactEvents() const;
  /// Called during World::step, once per contact manifold, after collision
  /// and before the solve: it may disable the contact or change its friction
  /// and restitution (one-way platforms, conveyor-free material tricks).
  /// It must not call back into the World.
  void setPreSolveCallback(ContactCallback callback);
  /// Friction and restitution for one body pair, replacing the combination
  /// (geometric-mean friction, larger restitution).
  void setPairMaterial(BodyId a, BodyId b, Real friction, Real restitution);

  // --- Collision filtering --------------------------------------------------------
  /// Two shapes collide when (a.group & b.mask) != 0 and (b.group & a.mask) != 0,
  /// the bodies are not joined by a joint that forbids it, and the custom
  /// filter (if any) agrees.
  void setCollisionFilter(BodyId id, std::uint32_t group, std::uint32_t mask);
  using CollisionFilter = std::function<bool(BodyId a, BodyId b)>;  ///< true: the pair may collide
  void setCollisionFilterCallback(CollisionFilter filter);  ///< called during the step; must not call the World

  // --- Sleeping -------------------------------------------------------------------
  bool isAsleep(BodyId id) const;  ///< true while the body's island sleeps
  void wake(BodyId id);            ///< wakes the body's whole island
  void putToSleep(BodyId id);      ///< puts the body's island to sleep now
  void setSleepingAllowed(BodyId id, bool allowed);  ///< false: its island never sleeps

  // --- Queries (through the broadphase) -------------------------------------------
  /// The closest hit of the segment [origin, origin + translation], if any.
  std::optional<RayHit> castRay(const Vec3& origin, const Vec3& translation, const QueryFilter& filter = {}) const;
  /// Every hit along the segment, nearest first.
  std::vector<RayHit> castRayAll(const Vec3& origin, const Vec3& translation, const QueryFilter& filter = {}) const;
  /// The first hit of a convex shape (sphere, box, capsule, cylinder, convex
  /// hull) at `pose` swept by `translation`.
  std::optional<ShapeCastHit> castShape(const ShapeDesc& shape, const Transform& pose, const Vec3& translation,
                                        const QueryFilter& filter = {}) const;
  /// The shapes a convex query shape at `pose` overlaps or touches, by
  /// ascending shape slot. Bad input (non-finite values, a plane or mesh as
  /// the query shape, a bad dimension) throws InputError (docs/collision.md,
  /// "Queries").
  std::vector<ShapeId> overlap(const ShapeDesc& shape, const Transform& pose, const QueryFilter& filter = {}) const;

  // --- Settings -------------------------------------------------------------------
  const Vec3& gravity() const;  ///< m/s^2
  void setGravity(const Vec3& g);  ///< m/s^2, from the next step
  const SolverSettings& settings() const;  ///< the settings in force
  /// Validates and sets; throws InputError naming "solver" and the field.
  void setSettings(const SolverSettings& s);

  // --- Stepping -------------------------------------------------------------------
  /// Advances the world by h seconds (fixed steps work best: see
  /// FixedStepDriver in cairn/fixed_step.hpp).
  void step(Real h);
  int stepCount() const;  ///< steps taken since creation
  Real time() const;  ///< simulated time (s)
  const StepStats& lastStepStats() const;  ///< what the last step reported
  /// Joints broken during the last step.
  std::span<const JointBreakEvent> jointBreakEvents() const;
  /// Non-finite states caught and rolled back, since creation (never
  /// silently passed on).
  std::span<const NumericalEvent> numericalEvents() const;
  /// Steps taken but not taken accurately, since creation: one record per
  /// body and kind. Destroying a body drops its records.
  std::span<const Diagnostic> diagnostics() const;

  // --- Snapshots ------------------------------------------------------------------
  /// The whole simulation state (bodies, shapes, joints, springs, settings,
  /// contact cache and warm-start impulses) in a versioned binary format. A
  /// world restored from it continues bit-identically to the one saved.
  std::vector<std::uint8_t> saveSnapshot() const;
  void saveSnapshot(const std::string& path) const;  ///< the snapshot written to a file
  /// Replaces this world's state with the snapshot's; throws InputError (a
  /// snapshot of another format version, truncated or corrupted) and then
  /// leaves the world untouched. Callbacks set on this world are kept.
  void restoreSnapshot(std::span<const std::uint8_t> bytes);
  void restoreSnapshot(const std::string& path);  ///< a snapshot read from a file

  // --- Energy and momentum (tests, metrics) ----------------------------------------
  Real kineticEnergy() const;  ///< J, translational and rotational
  Real potentialEnergy() const;  ///< gravity (relative to the origin along -g) and springs
  Vec3 linearMomentum() const;  ///< N s, of every dynamic body

 private:
  friend struct detail::WorldAccess;
  std::unique_ptr<detail::WorldImpl> impl_;
};

}  // namespace cairn
