/// @file
/// Definitions: plain structs a user fills and hands to World::create*, as in
/// Box2D's b2BodyDef. Every field has a usable default. The World validates a
/// definition completely before it changes anything.
#pragma once

#include "cairn/handles.hpp"
#include "cairn/shape.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cairn {

/// How a body moves: not at all, as scripted, or by forces.
enum class BodyType { Static, Kinematic, Dynamic };

const char* bodyTypeName(BodyType t);  ///< lower-case name, as in scene files
/// A rigid body to create (World::createBody).
struct BodyDef {
  std::string name;  ///< for messages and World::findBody; may be empty
  BodyType type = BodyType::Dynamic;  ///< static, kinematic or dynamic
  /// Mass (kg). Exactly one of mass and density for a dynamic body with shapes; a
  /// dynamic body without volume (no shapes) needs mass and inertia.
  std::optional<Real> mass;
  std::optional<Real> density;  ///< kg/m^3, for all the body's shapes (see mass)
  std::optional<Mat3> inertia;  ///< body frame, about the center of mass
  Vec3 position = Vec3::Zero();  ///< of the body frame origin (shapes are offset from it)
  Quat orientation = Quat::Identity();  ///< of the body frame, body to world
  Vec3 linear_velocity = Vec3::Zero();  ///< of the center of mass, world frame, m/s
  Vec3 angular_velocity = Vec3::Zero();  ///< world frame, rad/s
  std::vector<ShapeDesc> shapes;  ///< collision shapes in the body frame; several make a compound body
  Real friction = Real(0.5);  ///< Coulomb coefficient; a contact uses sqrt(friction_a friction_b) unless World::setPairMaterial
  Real restitution = 0;  ///< bounciness, 0 to 1; a contact uses the larger of the two unless World::setPairMaterial
  Real rolling_friction = 0;    ///< m
  Real torsional_friction = 0;  ///< m
  Real linear_damping = 0;   ///< 1/s: v *= 1 / (1 + h c) each (sub)step
  Real angular_damping = 0;  ///< 1/s: the same for the angular velocity
  bool ccd = false;  ///< speculative contacts reach as far as the body moves in a step (fast bodies)
  /// Collision filtering: two shapes collide when
  /// (a.group & b.mask) != 0 and (b.group & a.mask) != 0.
  std::uint32_t collision_group = 1;
  std::uint32_t collision_mask = 0xffffffffu;  ///< the groups this body collides with (see above)
  bool sleeping_allowed = true;  ///< false: the body's island never sleeps

  /// External loads (world frame), for scripted pushes in scene files:
  /// a force and a torque applied at the center of mass in every step, and
  /// impulses applied once each, at the start of the first step that begins
  /// at or after their time.
  Vec3 force = Vec3::Zero();   ///< N
  Vec3 torque = Vec3::Zero();  ///< N m
  /// An impulse applied once, at the start of the first step that begins at or after `time`.
  struct TimedImpulse {
    Real time = 0;                   ///< s
    Vec3 impulse = Vec3::Zero();     ///< N s
    std::optional<Vec3> point;       ///< world point at that time; default: the center of mass
  };
  std::vector<TimedImpulse> impulses;  ///< one-time impulses (see above)

  /// Degrees of freedom locked by the mass matrix (Jolt's AllowedDOFs,
  /// Bullet's linear and angular factors): world axes the body may neither
  /// translate along nor rotate about. The inverse mass and inertia become
  /// the constrained body's (dynamics/body.hpp), so that no impulse or force
  /// moves the body along them, exactly (no constraint rows that could
  /// stretch), and torques about the free axes meet the right inertia.
  /// Translation locks take the world axes x, y and z (unit vectors, either
  /// sign); a translation along any other line is a slider joint's job.
  /// Rotation locks take any non-zero world vectors.
  std::vector<Vec3> lock_translation;
  std::vector<Vec3> lock_rotation;  ///< world axes the body may not rotate about (see above)
};
/// A linear spring-damper between two anchors (World::createSpring).
struct SpringDef {
  std::string name;  ///< for messages; may be empty
  BodyId body_a = kWorldBody;  ///< the body at anchor_a; kWorldBody: fixed in the world
  BodyId body_b = kWorldBody;  ///< the body at anchor_b; kWorldBody: fixed in the world
  Vec3 anchor_a = Vec3::Zero();  ///< on body_a: world point at creation
  Vec3 anchor_b = Vec3::Zero();  ///< on body_b: world point at creation
  std::optional<Real> rest_length;  ///< default: the anchors' distance at creation
  Real stiffness = 0;  ///< N/m
  Real damping = 0;    ///< N s/m
};

/// Softness of a constraint in one of three spellings (docs/constraints.md):
/// raw ERP/CFM, a spring (stiffness N/m or N m/rad, damping N s/m), or a
/// frequency (Hz) and damping ratio. Unset fields fall back to the solver's
/// global ERP and CFM.
struct Softness {
  std::optional<Real> erp;        ///< ODE's error reduction parameter, in [0, 1]
  std::optional<Real> cfm;        ///< ODE's constraint force mixing (m/(N s), or rad/(N m s) for angular rows)
  std::optional<Real> stiffness;  ///< spring: N/m, or N m/rad for angular rows
  std::optional<Real> damping;    ///< spring: N s/m, or N m s/rad for angular rows
  std::optional<Real> frequency;  ///< Hz, of each row on its own effective mass
  std::optional<Real> damping_ratio;  ///< with frequency: 1 is critical damping (the default)
  /// True when any field is set.
  bool isSet() const { return erp || cfm || stiffness || damping || frequency || damping_ratio; }
};

/// A limit on a joint coordinate s (hinge angle, slider travel, cone-twist
/// twist, a six_dof axis), all measured as body_a relative to body_b
/// (docs/constraints.md, "Sign conventions"). lower == upper holds the
/// coordinate there from both sides (a locked axis). A limit whose softness
/// is a spring (stiffness/damping or frequency/damping_ratio) is a soft
/// stop: past a bound it is a spring-damper toward that bound, pushing and
/// pulling, instead of a one-sided rigid row.
struct LimitDef {
  bool enabled = false;  ///< false: the coordinate is not limited
  Real lower = 0;        ///< lower bound: rad for angular limits, m for linear ones
  Real upper = 0;        ///< upper bound: rad for angular limits, m for linear ones
  Real restitution = 0;  ///< bounce off a bound, 0 to 1; rigid limits with lower < upper only
  Softness softness;     ///< erp/cfm: a rigid stop; a spring: a soft stop; unset: the joint's
};

/// A motor on a joint coordinate s (as for LimitDef: body_a relative to
/// body_b). A velocity motor drives ds/dt to target_velocity: rigid by
/// default, or through a damper (softness.damping, or ODE's softness.cfm)
/// for a soft velocity motor. A position motor (servo) drives s to
/// target_position through a spring-damper: softness stiffness/damping or
/// frequency/damping_ratio, critically damped at 2 Hz when unset (Jolt's
/// MotorSettings default) and critically damped when only a stiffness or a
/// frequency is given. Either way |force| <= max_force, which is required.
struct MotorDef {
  bool enabled = false;                 ///< false: no motor
  Real target_velocity = 0;             ///< rad/s or m/s
  std::optional<Real> max_force;        ///< N or N m, required; the row's bounds are +- max_force h
  std::optional<Real> target_position;  ///< rad or m: a position motor (servo)
  Softness softness;                    ///< velocity motor: a damper; servo: the spring-damper
};

/// What a six_dof joint does with one degree of freedom: leaves it free,
/// limits it (a LimitDef) or locks it (holds it at 0).
enum class DofMode { Free, Limited, Locked };

const char* dofModeName(DofMode m);  ///< lower-case name, as in scene files

/// An unbounded spring-damper on one degree of freedom of a six_dof joint,
/// pulling the coordinate toward `rest`.
struct DofSpringDef {
  bool enabled = false;  ///< false: no spring
  Real rest = 0;         ///< rest coordinate: rad or m
  Softness softness;     ///< stiffness/damping or frequency/damping_ratio
};

/// One degree of freedom of a six_dof joint: free, limited (a LimitDef) or
/// locked (held at 0), with an optional spring toward `rest` and a motor.
struct DofDef {
  DofMode mode = DofMode::Free;  ///< free, limited or locked
  LimitDef limit;       ///< Limited: the range (enabled follows the mode)
  DofSpringDef spring;  ///< optional spring toward spring.rest
  MotorDef motor;       ///< optional motor on this coordinate
};

/// The six axes of a six_dof joint, in its frame (x = axis, y = axis2):
/// translations along x, y, z, then rotations about x (twist), y, z (swing).
enum class Dof { TranslationX, TranslationY, TranslationZ, RotationX, RotationY, RotationZ };
inline constexpr int kDofCount = 6;  ///< number of Dof values

const char* dofName(int dof);  ///< "translation_x" ... "rotation_z", as in scene files

/// The kinds of joint (docs/constraints.md).
enum class JointType { Ball, Hinge, Slider, Fixed, Universal, ConeTwist, Distance, AngularMotor, SixDof };

const char* jointTypeName(JointType t);  ///< lower-case name, as in scene files

/// A joint to create (World::createJoint); which fields count depends on its type.
struct JointDef {
  std::string name;  ///< for messages and World::findJoint; may be empty
  JointType type = JointType::Ball;  ///< which joint; the fields below it uses
  BodyId body_a = kWorldBody;  ///< the body whose motion limits and motors measure; kWorldBody: the world
  BodyId body_b = kWorldBody;  ///< the body it is measured against; kWorldBody: the world
  Vec3 anchor = Vec3::Zero();        ///< world point at creation (all types but distance)
  Vec3 axis = Vec3::UnitZ();         ///< hinge/slider axis, cone-twist twist axis, universal axis on a, six_dof x
  Vec3 axis2 = Vec3::UnitX();        ///< universal: axis on b; six_dof: y (perpendicular to axis)
  Vec3 anchor_a = Vec3::Zero();      ///< distance joint: world point on body_a at creation
  Vec3 anchor_b = Vec3::Zero();      ///< distance joint: world point on body_b at creation
  std::optional<Real> length;        ///< distance joint (m), default: the anchors' distance
  LimitDef limit;                    ///< hinge angle, slider distance, cone-twist twist
  Real swing_span1 = kPi;            ///< cone-twist: swing cone half-angle along its first principal direction (rad)
  Real swing_span2 = kPi;            ///< cone-twist: swing cone half-angle along its second principal direction (rad)
  MotorDef motor;                    ///< hinge, slider
  std::array<DofDef, kDofCount> dofs;  ///< six_dof: one per Dof, in Dof order
  /// Angular motor: target angular velocity of a relative to b on up to
  /// three axes (world at creation, then fixed in a), each with its own
  /// maximum torque.
  std::vector<Vec3> motor_axes;
  std::vector<Real> motor_targets;      ///< angular motor: target velocity about each motor axis (rad/s)
  std::vector<Real> motor_max_torques;  ///< angular motor: maximum torque about each motor axis (N m)
  Softness softness;  ///< the joint's rows; unset: the solver's global ERP and CFM
  Real break_force = kInf;  ///< N; the joint is removed when its force exceeds this
  Real break_torque = kInf;  ///< N m; the joint is removed when its torque about the anchor exceeds this
  bool collide_connected = false;  ///< false: the two bodies do not collide with each other
};

}  // namespace cairn
