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

enum class BodyType { Static, Kinematic, Dynamic };  ///< how a body moves: not at all, as scripted, or by forces

const char* bodyTypeName(BodyType t);  ///< lower-case name, as in scene files
/// A rigid body to create (World::createBody).
struct BodyDef {
  std::string name;
  BodyType type = BodyType::Dynamic;
  /// Exactly one of mass and density for a dynamic body with shapes; a
  /// dynamic body without volume (no shapes) needs mass and inertia.
  std::optional<Real> mass;
  std::optional<Real> density;
  std::optional<Mat3> inertia;  ///< body frame, about the center of mass
  Vec3 position = Vec3::Zero();  ///< of the body frame origin (shapes are offset from it)
  Quat orientation = Quat::Identity();
  Vec3 linear_velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();  ///< world frame, rad/s
  std::vector<ShapeDesc> shapes;
  Real friction = Real(0.5);
  Real restitution = 0;
  Real rolling_friction = 0;    ///< m
  Real torsional_friction = 0;  ///< m
  Real linear_damping = 0;
  Real angular_damping = 0;
  bool ccd = false;
  /// Collision filtering: two shapes collide when
  /// (a.group & b.mask) != 0 and (b.group & a.mask) != 0.
  std::uint32_t collision_group = 1;
  std::uint32_t collision_mask = 0xffffffffu;
  bool sleeping_allowed = true;  ///< false: the body's island never sleeps

  /// External loads (world frame), for scripted pushes in scene files:
  /// a force and a torque applied at the center of mass in every step, and
  /// impulses applied once each, at the start of the first step that begins
  /// at or after their time.
  Vec3 force = Vec3::Zero();   ///< N
  Vec3 torque = Vec3::Zero();  ///< N m
  struct TimedImpulse {
    Real time = 0;                   ///< s
    Vec3 impulse = Vec3::Zero();     ///< N s
    std::optional<Vec3> point;       ///< world point at that time; default: the center of mass
  };
  std::vector<TimedImpulse> impulses;

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
  std::vector<Vec3> lock_rotation;
};
/// A linear spring-damper between two anchors (World::createSpring).
struct SpringDef {
  std::string name;
  BodyId body_a = kWorldBody, body_b = kWorldBody;
  Vec3 anchor_a = Vec3::Zero(), anchor_b = Vec3::Zero();  ///< world points at creation
  std::optional<Real> rest_length;  ///< default: the anchors' distance at creation
  Real stiffness = 0;  ///< N/m
  Real damping = 0;    ///< N s/m
};

/// Softness of a constraint in one of three spellings (docs/constraints.md):
/// raw ERP/CFM, a spring (stiffness N/m or N m/rad, damping N s/m), or a
/// frequency (Hz) and damping ratio. Unset fields fall back to the solver's
/// global ERP and CFM.
struct Softness {
  std::optional<Real> erp, cfm;
  std::optional<Real> stiffness, damping;
  std::optional<Real> frequency, damping_ratio;
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
  bool enabled = false;
  Real lower = 0, upper = 0;  // rad for angular limits, m for linear ones
  Real restitution = 0;       // rigid limits with lower < upper only
  Softness softness;
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
  bool enabled = false;
  Real target_velocity = 0;            // rad/s or m/s
  std::optional<Real> max_force;       // N or N m; the row's bounds are +- max_force h
  std::optional<Real> target_position; // rad or m: a position motor
  Softness softness;
};

/// One degree of freedom of a six_dof joint: free, limited (a LimitDef) or
/// locked (held at 0), with an optional spring toward `rest` and a motor.
enum class DofMode { Free, Limited, Locked };

const char* dofModeName(DofMode m);

struct DofSpringDef {
  bool enabled = false;
  Real rest = 0;      // rad or m
  Softness softness;  // stiffness/damping or frequency/damping_ratio
};

struct DofDef {
  DofMode mode = DofMode::Free;
  LimitDef limit;  // Limited: the range (enabled follows the mode)
  DofSpringDef spring;
  MotorDef motor;
};

/// The six axes of a six_dof joint, in its frame (x = axis, y = axis2):
/// translations along x, y, z, then rotations about x (twist), y, z (swing).
enum class Dof { TranslationX, TranslationY, TranslationZ, RotationX, RotationY, RotationZ };
inline constexpr int kDofCount = 6;

const char* dofName(int dof);  // "translation_x" ... "rotation_z"

enum class JointType { Ball, Hinge, Slider, Fixed, Universal, ConeTwist, Distance, AngularMotor, SixDof };

const char* jointTypeName(JointType t);

const char* jointTypeName(JointType t);  ///< lower-case name, as in scene files
/// A joint to create (World::createJoint); which fields count depends on its type.
struct JointDef {
  std::string name;
  JointType type = JointType::Ball;
  BodyId body_a = kWorldBody, body_b = kWorldBody;
  Vec3 anchor = Vec3::Zero();        // world frame at creation
  Vec3 axis = Vec3::UnitZ();         // hinge/slider axis, cone-twist twist axis, universal axis on a, six_dof x
  Vec3 axis2 = Vec3::UnitX();        // universal: axis on b; six_dof: y (perpendicular to axis)
  Vec3 anchor_a = Vec3::Zero(), anchor_b = Vec3::Zero();  // distance joint
  std::optional<Real> length;        // distance joint, default: the anchors' distance
  LimitDef limit;                    // hinge angle, slider distance, cone-twist twist
  Real swing_span1 = kPi, swing_span2 = kPi;  // cone-twist cone half-angles (rad)
  MotorDef motor;                    // hinge, slider
  std::array<DofDef, kDofCount> dofs;  // six_dof
  /// Angular motor: target angular velocity of a relative to b on up to
  /// three axes (world at creation, then fixed in a), each with its own
  /// maximum torque.
  std::vector<Vec3> motor_axes;
  std::vector<Real> motor_targets;
  std::vector<Real> motor_max_torques;
  Softness softness;
  Real break_force = kInf;  ///< N; the joint is removed when its force exceeds this
  Real break_torque = kInf;
  bool collide_connected = false;
};

}  // namespace cairn
