// A joint in the World: its definition, its frames captured at creation
// (anchors and axes stored in each body's frame, so they move with the
// bodies), the impulses carried between steps for warm starting, and the
// force feedback of the last step.
//
// Each joint type lives in its own file (constraints/<type>_joint.cpp) and
// writes its rows through the parts of constraints/parts.hpp. Row slots are
// fixed per type so warm starting is keyed by (joint, slot):
//
//   type          rows (slots)
//   ball          point 0-2
//   hinge         point 0-2, two angular 3-4, limit 5, motor 6
//   slider        orientation 0-2, two linear 3-4, limit 5, motor 6
//   fixed         point 0-2, orientation 3-5
//   universal     point 0-2, one angular 3
//   cone_twist    point 0-2, swing 3, twist 4
//   distance      one linear 0
//   angular_motor up to three angular 0-2
//   six_dof       per axis i (translation x, y, z, rotation x, y, z):
//                 limit or lock i, spring 6 + i, motor 12 + i
//
// Limits and motors act on coordinates measured as body a relative to body
// b (hinge angle, slider travel, cone-twist twist, six_dof axes), ODE's and
// Bullet's convention (docs/constraints.md, "Sign conventions").
#pragma once

#include "constraints/parts.hpp"
#include "cairn/defs.hpp"
#include "cairn/events.hpp"

#include <array>
#include <string>
#include <vector>

namespace cairn {

inline constexpr int kMaxJointRows = 3 * kDofCount;  // six_dof

struct Joint {
  JointDef def;
  bool broken = false;
  bool alive = true;             // false: a free slot (destroyed joint)
  std::uint32_t generation = 0;  // of the slot

  // Frames in body coordinates (relative to the center of mass); for the
  // world they are world coordinates.
  Vec3 local_anchor_a = Vec3::Zero(), local_anchor_b = Vec3::Zero();
  Vec3 local_axis_a = Vec3::UnitZ(), local_axis_b = Vec3::UnitZ();
  Vec3 local_ref_a = Vec3::UnitX(), local_ref_b = Vec3::UnitX();  // perpendicular to the axis
  Vec3 local_axis2_b = Vec3::UnitX();                             // universal joint
  Quat local_frame_a = Quat::Identity(), local_frame_b = Quat::Identity();  // six_dof: x = axis, y = axis2
  Quat rel_orientation0 = Quat::Identity();                       // q_a^-1 q_b at creation
  Real length = 0;                                                // distance joint
  std::vector<Vec3> local_motor_axes;                             // angular motor, in a's frame

  // Warm start: last step's impulse per slot (zero for a slot that had no row).
  std::vector<Real> warm = std::vector<Real>(kMaxJointRows, 0);
  JointFeedback feedback;
};

// Fills the joint's body-frame data from its world-frame definition and the
// bodies' poses at creation. `a` or `b` is the world's BodyView when the
// joint attaches to the world.
Joint makeJoint(const JointDef& def, const BodyView& a, const BodyView& b);

// Checks a definition (throws InputError naming "joint 'name'" and the field).
void validateJointDef(const JointDef& def, int body_count);

// Appends the joint's rows for this step.
struct JointRowSettings {
  Real restitution_threshold = Real(0.2);
};
void buildJointRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx,
                    const JointRowSettings& settings);

JointError measureJointError(const Joint& j, const BodyView& a, const BodyView& b);

// Per-type row builders (one file each).
void buildBallRows(const Joint&, const BodyView&, const BodyView&, RowContext&);
void buildHingeRows(const Joint&, const BodyView&, const BodyView&, RowContext&, const JointRowSettings&);
void buildSliderRows(const Joint&, const BodyView&, const BodyView&, RowContext&, const JointRowSettings&);
void buildFixedRows(const Joint&, const BodyView&, const BodyView&, RowContext&);
void buildUniversalRows(const Joint&, const BodyView&, const BodyView&, RowContext&);
void buildConeTwistRows(const Joint&, const BodyView&, const BodyView&, RowContext&, const JointRowSettings&);
void buildDistanceRows(const Joint&, const BodyView&, const BodyView&, RowContext&);
void buildAngularMotorRows(const Joint&, const BodyView&, const BodyView&, RowContext&);
void buildSixDofRows(const Joint&, const BodyView&, const BodyView&, RowContext&, const JointRowSettings&);

// Hinge angle of a relative to b about the hinge axis (rad, in (-pi, pi]).
Real hingeAngle(const Joint& j, const BodyView& a, const BodyView& b);
// Slider travel of a relative to b along the axis (m).
Real sliderPosition(const Joint& j, const BodyView& a, const BodyView& b);
// Cone-twist: swing angle (between the twist axes) and twist angle (a
// relative to b).
void coneTwistAngles(const Joint& j, const BodyView& a, const BodyView& b, Real& swing, Real& twist);
// six_dof: the translations (m) and the twist and swing angles (rad) of a
// relative to b, indexed as Dof.
std::array<Real, kDofCount> sixDofCoordinates(const Joint& j, const BodyView& a, const BodyView& b);

}  // namespace cairn
