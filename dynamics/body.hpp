// The rigid body state of section 12.6.1 (Listing 12.2).
//
// Primary state: center-of-mass position, orientation quaternion, linear and
// angular velocity (world frame). Constant properties: mass and body-space
// inertia tensor and their inverses. Derived each step: the rotation matrix
// and the world-space inverse inertia R J^-1 R^T. Working variables: force
// and torque accumulators, cleared after every step.
//
// Static bodies have zero inverse mass and never move. Kinematic bodies also
// have zero inverse mass but move with their scripted velocity, which
// contacts and joints see.
#pragma once

#include "cairn/defs.hpp"
#include "cairn/math.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cairn {

// Whether a body-frame inertia (or its inverse) is c 1, equal principal
// moments about any axes: a cube, a sphere. Such a body feels no
// gyroscopic torque, and R (c 1) R^T = c 1 for every rotation R.
inline bool isIsotropic(const Mat3& j) {
  return j(0, 1) == 0 && j(0, 2) == 0 && j(1, 0) == 0 && j(1, 2) == 0 && j(2, 0) == 0 && j(2, 1) == 0 &&
         j(0, 0) == j(1, 1) && j(1, 1) == j(2, 2);
}

// What the walks over every body or every pair read to skip it (its type,
// whether it is alive and asleep, its collision filter) is in the first
// cache line: a body is 960 bytes (15 lines), each starting a line.
struct alignas(64) Body {
  std::string name;
  BodyType type = BodyType::Dynamic;
  bool alive = true;             // false: a free slot (destroyed body)
  // Sleeping (world/islands.cpp).
  bool asleep = false;
  bool sleeping_allowed = true;
  std::uint32_t generation = 0;  // of the slot: advances when the body is destroyed
  // Collision filter: a and b collide when (a.group & b.mask) and (b.group & a.mask).
  std::uint32_t collision_group = 1;
  std::uint32_t collision_mask = 0xffffffffu;

  // Primary state.
  Vec3 position = Vec3::Zero();  // center of mass, world frame
  Quat orientation = Quat::Identity();
  Vec3 linear_velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();  // world frame

  // Constant properties.
  Real mass = 0;
  Real inv_mass = 0;
  Mat3 inertia_body = Mat3::Zero();      // about the center of mass
  Mat3 inv_inertia_body = Mat3::Zero();
  Vec3 com_local = Vec3::Zero();         // center of mass in the body frame of the definition

  // Degrees of freedom locked through the mass matrix (BodyDef's
  // lock_translation and lock_rotation): 1 per free world axis, 0 per
  // locked one; and the projector I - sum a a^T onto the rotations allowed.
  Vec3 linear_factor = Vec3::Ones();
  Mat3 rotation_projector = Mat3::Identity();
  bool rotation_locked = false;

  // Derived.
  Mat3 rotation = Mat3::Identity();
  Mat3 inv_inertia_world = Mat3::Zero();  // R J^-1 R^T, projected when rotations are locked

  // Working variables.
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();

  // External loads from the definition (world frame).
  Vec3 constant_force = Vec3::Zero();
  Vec3 constant_torque = Vec3::Zero();
  std::vector<BodyDef::TimedImpulse> impulses;  // by time
  std::size_t next_impulse = 0;

  // Material and damping.
  Real friction = Real(0.5);
  Real restitution = 0;
  Real linear_damping = 0;   // 1/s: v *= 1 / (1 + h c)
  Real angular_damping = 0;
  Real rolling_friction = 0;    // m: rolling resistance torque <= this * normal force
  Real torsional_friction = 0;  // m: spinning resistance about the contact normal
  bool ccd = false;          // speculative contacts reach as far as the body moves in a step

  Real sleep_timer = 0;  // seconds spent below the sleep thresholds (world/islands.cpp)

  // Shapes in the body frame: positions relative to the center of mass;
  // shape_ids[i] is the world's shape slot of shapes[i].
  std::vector<ShapeDesc> shapes;
  std::vector<std::int32_t> shape_ids;

  // How the mass was defined, to recompute it when shapes or the type change.
  std::optional<Real> def_mass, def_density;
  std::optional<Mat3> def_inertia;

  bool isDynamic() const { return type == BodyType::Dynamic; }
  // What the solver's rows see: a static or kinematic body has no inverse
  // mass or inertia (its velocity is given, not solved).
  Real solverInvMass() const { return isDynamic() ? inv_mass : Real(0); }
  Mat3 solverInvInertia() const { return isDynamic() ? inv_inertia_world : Mat3(Mat3::Zero()); }
  // A kinematic body with a velocity: it moves in every step, asleep
  // bodies it touches included.
  bool isMovingKinematic() const {
    return type == BodyType::Kinematic && linear_velocity.squaredNorm() + angular_velocity.squaredNorm() > 0;
  }

  Transform transform() const { return Transform{position, orientation}; }
  // The frame BodyDef::position and orientation placed (the center of mass
  // sits at com_local in it).
  Transform originTransform() const { return Transform{position - orientation * com_local, orientation}; }

  // Refresh R and R J^-1 R^T from the orientation.
  //
  // With rotation locks the angular velocity is w = B u, B an orthonormal
  // basis of the allowed rotations (P = B B^T). The torque tau then moves
  // u by B^T I B du/dt = B^T tau (the locks' reaction is along the locked
  // axes, where B^T removes it), so the inverse inertia seen by forces and
  // constraint rows is B (B^T I B)^-1 B^T, not P I^-1 P: the two differ
  // when the world inertia I = R J R^T couples allowed and locked axes (a
  // tilted box turning about a vertical axis turns at tau / I_zz, whereas
  // P I^-1 P would give (I^-1)_zz tau). It is computed without building B:
  // in the basis [B, N] the matrix P I P + s (1 - P) is block diagonal,
  // diag(B^T I B, s), so P (P I P + s (1 - P))^-1 P = B (B^T I B)^-1 B^T
  // for any s > 0; s = tr(I) / 3 keeps both blocks of the same size.
  void updateDerived() {
    rotation = orientation.toRotationMatrix();
    // c 1 turns into itself: exactly, where the product would add round-off.
    if (isIsotropic(inv_inertia_body)) inv_inertia_world = inv_inertia_body;
    else inv_inertia_world = rotation * inv_inertia_body * rotation.transpose();
    if (rotation_locked && isDynamic()) {
      const Mat3 inertia_world = rotation * inertia_body * rotation.transpose();
      const Mat3& p = rotation_projector;
      const Mat3 m = p * inertia_world * p + (inertia_world.trace() / 3) * (Mat3::Identity() - p);
      inv_inertia_world = p * m.inverse() * p;
    }
  }

  // The velocity the locks allow (their components removed).
  Vec3 allowedLinear(const Vec3& v) const { return v.cwiseProduct(linear_factor); }
  Vec3 allowedAngular(const Vec3& w) const { return rotation_locked ? Vec3(rotation_projector * w) : w; }

  Vec3 velocityAt(const Vec3& world_point) const {
    return linear_velocity + angular_velocity.cross(world_point - position);
  }

  // Angular momentum about the center of mass, world frame: R J R^T w.
  Vec3 angularMomentum() const {
    return rotation * (inertia_body * (rotation.transpose() * angular_velocity));
  }

  Real kineticEnergy() const {
    if (!isDynamic()) return 0;
    return Real(0.5) * mass * linear_velocity.squaredNorm() +
           Real(0.5) * angular_velocity.dot(angularMomentum());
  }
};

}  // namespace cairn
