// The Bullet oracle: the same in-memory scene (a SceneDesc) built as a
// Bullet 3.24 world (double precision) and stepped, so cairn can be compared
// with Bullet body by body and step by step.
//
// Bullet is built from btDefaultCollisionConfiguration, btCollisionDispatcher,
// btDbvtBroadphase, btSequentialImpulseConstraintSolver and
// btDiscreteDynamicsWorld. docs/validation.md ("How settings map between
// cairn and Bullet") lists every mapping, which ones are exact and which are
// approximate; whatever has no Bullet equivalent is reported by skipped()
// and the rest of the scene still runs.
//
// States are those of the center of mass in the world frame, as in cairn.
// Bullet's body origin sits at the center of mass with the shapes offset in
// a btCompoundShape, and its body frame is the principal frame of cairn's
// inertia tensor (Bullet stores a diagonal inertia); the rotation between
// the two frames is undone in state().
#pragma once

#include "cairn/math.hpp"
#include "cairn/scene.hpp"

#include <memory>
#include <string>
#include <vector>

namespace cairn::validation {

struct OracleBodyState {
  Vec3 position = Vec3::Zero();  // center of mass, world frame
  Quat orientation = Quat::Identity();
  Vec3 linear_velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();  // world frame, rad/s
};

struct OracleOptions {
  // true: map cairn's settings onto Bullet so that differences come from
  // the engines and not from their defaults (docs/validation.md): cairn's
  // friction and restitution combination, damping law, gyroscopic choice,
  // warm-start factor, split impulse for every penetration, two friction
  // directions, ODE-convention CFM on every joint row, limit stiffness and
  // bounce as cairn defines them.
  // false: Bullet as it ships: btContactSolverInfo defaults (except the
  // iteration count and the step), product friction and restitution,
  // Bullet's own damping law and joint parameter conventions, and its
  // default 0.04 m margin on boxes and cylinders down to 0.08 m thick.
  bool match_cairn = true;
  // false: the scene's solver.sleeping decides (off: every dynamic body
  // DISABLE_DEACTIVATION; on: the scene's speed thresholds and sleep time).
  // true: Bullet's own deactivation whatever the scene says, as a program
  // that never touches it gets: btRigidBodyConstructionInfo's thresholds
  // 0.8 m/s and 1 rad/s, and gDeactivationTime 2 s (btRigidBody.cpp). That
  // time is a process-global: this oracle sets it back to 2 s, so two
  // oracles that want different times must not be alive at once.
  bool bullet_deactivation = false;
};

class BulletOracle {
 public:
  // Validates the scene the way cairn does (buildWorld) and throws
  // InputError on bad input before building anything.
  explicit BulletOracle(const SceneDesc& scene, const OracleOptions& options = {});
  ~BulletOracle();
  BulletOracle(const BulletOracle&) = delete;
  BulletOracle& operator=(const BulletOracle&) = delete;

  // One step of scene.dt: solver.substeps internal Bullet steps of
  // dt / substeps each (stepSimulation(h, 0): exactly one internal step per
  // call, no interpolation), springs and kinematic bodies driven as cairn
  // drives them.
  void step();

  int bodyCount() const;                  // the same count and order as scene.bodies
  OracleBodyState state(int body) const;  // center of mass, world frame

  // Features Bullet lacks or that were mapped only approximately, each with
  // its reason, e.g. "solver.method=direct: ...". Entries may be added
  // while stepping (a soft joint row whose CFM Bullet cannot iterate).
  const std::vector<std::string>& skipped() const;

  // Position error of joint `joint` (index into scene.joints) as a world
  // vector: the anchor on b minus the anchor on a for point-like joints;
  // the off-axis part of it for a slider; (|d| - length) along d for a
  // distance joint; zero for an angular motor. Measured whether or not
  // Bullet could build the joint (it is then just the bodies' drift).
  Vec3 jointAnchorSeparation(int joint) const;
  // False once Bullet broke the joint (or when it could not be built).
  bool jointActive(int joint) const;

  // Dynamic bodies Bullet has deactivated (ISLAND_SLEEPING) after the last step.
  int sleepingBodies() const;

  double lastStepSeconds() const;  // wall time of the last step()
  int stepCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cairn::validation
