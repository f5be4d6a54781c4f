#include "constraints/joint.hpp"

#include "cairn/error.hpp"

#include <cmath>

namespace cairn {

const char* jointTypeName(JointType t) {
  switch (t) {
    case JointType::Ball: return "ball";
    case JointType::Hinge: return "hinge";
    case JointType::Slider: return "slider";
    case JointType::Fixed: return "fixed";
    case JointType::Universal: return "universal";
    case JointType::ConeTwist: return "cone_twist";
    case JointType::Distance: return "distance";
    case JointType::AngularMotor: return "angular_motor";
  }
  return "unknown";
}

const char* rowKindName(RowKind k) {
  switch (k) {
    case RowKind::JointLinear: return "joint_linear";
    case RowKind::JointAngular: return "joint_angular";
    case RowKind::Limit: return "limit";
    case RowKind::Motor: return "motor";
    case RowKind::ContactNormal: return "contact_normal";
    case RowKind::ContactFriction: return "contact_friction";
    case RowKind::ContactRolling: return "contact_rolling";
    case RowKind::Count: break;
  }
  return "unknown";
}

namespace {

std::string num(Real v) { return std::to_string(v); }

Vec3 requireAxis(const std::string& obj, const char* field, const Vec3& v) {
  if (!v.allFinite()) throw InputError(obj, field, "must be finite");
  if (v.norm() < Real(1e-9)) throw InputError(obj, field, "zero axis");
  return v.normalized();
}

}  // namespace

void validateJointDef(const JointDef& d, int body_count) {
  const std::string obj = "joint '" + d.name + "'";
  for (const auto& [id, field] : {std::pair{d.body_a, "bodies[0]"}, std::pair{d.body_b, "bodies[1]"}})
    if (!id.isWorld() && (id.index < 0 || id.index >= body_count)) throw InputError(obj, field, "no such body");
  if (d.body_a == d.body_b)
    throw InputError(obj, "bodies", d.body_a.isWorld() ? "a joint needs at least one body" : "a joint between a body and itself");
  if (!d.anchor.allFinite()) throw InputError(obj, "anchor", "must be finite");
  const bool uses_axis = d.type == JointType::Hinge || d.type == JointType::Slider || d.type == JointType::Universal ||
                         d.type == JointType::ConeTwist;
  if (uses_axis) requireAxis(obj, "axis", d.axis);
  if (d.type == JointType::Universal) {
    const Vec3 a2 = requireAxis(obj, "axis2", d.axis2);
    if (std::abs(a2.dot(d.axis.normalized())) > Real(1e-3))
      throw InputError(obj, "axis2", "must be perpendicular to axis");
  }
  if (d.limit.enabled) {
    if (!std::isfinite(d.limit.lower) || !std::isfinite(d.limit.upper))
      throw InputError(obj, "limits", "lower and upper must be finite");
    if (d.limit.lower > d.limit.upper)
      throw InputError(obj, "limits", "lower > upper (" + num(d.limit.lower) + " > " + num(d.limit.upper) + ")");
    if (!std::isfinite(d.limit.restitution) || d.limit.restitution < 0 || d.limit.restitution > 1)
      throw InputError(obj, "limits.restitution", "must lie in [0, 1]");
    validateSoftness(d.limit.softness, obj, "limits.");
  }
  if (d.motor.enabled) {
    if (!std::isfinite(d.motor.target_velocity)) throw InputError(obj, "motor.target_velocity", "must be finite");
    if (!std::isfinite(d.motor.max_force) || d.motor.max_force < 0)
      throw InputError(obj, "motor.max_force", "must be finite and >= 0 (got " + num(d.motor.max_force) + ")");
  }
  if (d.type == JointType::AngularMotor) {
    if (d.motor_axes.empty() || d.motor_axes.size() > 3) throw InputError(obj, "motor", "an angular motor has 1 to 3 axes");
    if (d.motor_targets.size() != d.motor_axes.size() || d.motor_max_torques.size() != d.motor_axes.size())
      throw InputError(obj, "motor", "each axis needs a target_velocity and a max_force");
    for (size_t i = 0; i < d.motor_axes.size(); ++i) {
      const std::string f = "motor[" + std::to_string(i) + "]";
      requireAxis(obj, (f + ".axis").c_str(), d.motor_axes[i]);
      if (!std::isfinite(d.motor_targets[i])) throw InputError(obj, f + ".target_velocity", "must be finite");
      if (!std::isfinite(d.motor_max_torques[i]) || d.motor_max_torques[i] < 0)
        throw InputError(obj, f + ".max_force", "must be finite and >= 0");
    }
  }
  if (d.type == JointType::ConeTwist) {
    for (const auto& [v, f] : {std::pair{d.swing_span1, "swing_span1"}, std::pair{d.swing_span2, "swing_span2"}})
      if (!std::isfinite(v) || v <= 0 || v > kPi) throw InputError(obj, f, "must lie in (0, pi]");
  }
  if (d.type == JointType::Distance) {
    if (!d.anchor_a.allFinite()) throw InputError(obj, "anchors[0]", "must be finite");
    if (!d.anchor_b.allFinite()) throw InputError(obj, "anchors[1]", "must be finite");
    const Real len = d.length.value_or((d.anchor_b - d.anchor_a).norm());
    if (!std::isfinite(len) || len <= 0)
      throw InputError(obj, "length", "must be positive (coincident anchors: use a ball joint)");
  }
  validateSoftness(d.softness, obj, "");
  if (std::isnan(d.break_force) || d.break_force <= 0) throw InputError(obj, "break_force", "must be positive");
  if (std::isnan(d.break_torque) || d.break_torque <= 0) throw InputError(obj, "break_torque", "must be positive");
}

Joint makeJoint(const JointDef& def, const BodyView& a, const BodyView& b) {
  Joint j;
  j.def = def;
  const auto toA = [&](const Vec3& p) { return a.q.conjugate() * (p - a.x); };
  const auto toB = [&](const Vec3& p) { return b.q.conjugate() * (p - b.x); };
  const Vec3 axis = def.axis.normalized();
  const Vec3 ref = anyPerpendicular(axis);
  if (def.type == JointType::Distance) {
    j.local_anchor_a = toA(def.anchor_a);
    j.local_anchor_b = toB(def.anchor_b);
    j.length = def.length.value_or((def.anchor_b - def.anchor_a).norm());
  } else {
    j.local_anchor_a = toA(def.anchor);
    j.local_anchor_b = toB(def.anchor);
  }
  j.local_axis_a = a.q.conjugate() * axis;
  j.local_axis_b = b.q.conjugate() * axis;
  j.local_ref_a = a.q.conjugate() * ref;
  j.local_ref_b = b.q.conjugate() * ref;
  if (def.type == JointType::Universal) j.local_axis2_b = b.q.conjugate() * def.axis2.normalized();
  j.rel_orientation0 = (a.q.conjugate() * b.q).normalized();
  for (const Vec3& ax : def.motor_axes) j.local_motor_axes.push_back(a.q.conjugate() * ax.normalized());
  return j;
}

void buildJointRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx, const JointRowSettings& s) {
  switch (j.def.type) {
    case JointType::Ball: buildBallRows(j, a, b, ctx); break;
    case JointType::Hinge: buildHingeRows(j, a, b, ctx, s); break;
    case JointType::Slider: buildSliderRows(j, a, b, ctx, s); break;
    case JointType::Fixed: buildFixedRows(j, a, b, ctx); break;
    case JointType::Universal: buildUniversalRows(j, a, b, ctx); break;
    case JointType::ConeTwist: buildConeTwistRows(j, a, b, ctx, s); break;
    case JointType::Distance: buildDistanceRows(j, a, b, ctx); break;
    case JointType::AngularMotor: buildAngularMotorRows(j, a, b, ctx); break;
  }
}

JointError measureJointError(const Joint& j, const BodyView& a, const BodyView& b) {
  JointError e;
  const Vec3 pa = worldPoint(a, j.local_anchor_a), pb = worldPoint(b, j.local_anchor_b);
  const Vec3 axa = worldVector(a, j.local_axis_a), axb = worldVector(b, j.local_axis_b);
  const auto beyond = [](const LimitDef& l, Real s) {
    if (!l.enabled) return Real(0);
    return std::max({l.lower - s, s - l.upper, Real(0)});
  };
  switch (j.def.type) {
    case JointType::Ball:
      e.linear = (pb - pa).norm();
      break;
    case JointType::Hinge:
      e.linear = (pb - pa).norm();
      e.angular = std::max(std::asin(std::min(Real(1), axa.cross(axb).norm())), beyond(j.def.limit, hingeAngle(j, a, b)));
      break;
    case JointType::Slider: {
      const Vec3 d = pb - pa;
      e.linear = std::max((d - axa * axa.dot(d)).norm(), beyond(j.def.limit, sliderPosition(j, a, b)));
      e.angular = rotationVectorFromQuat(b.q * (a.q * j.rel_orientation0).conjugate()).norm();
      break;
    }
    case JointType::Fixed:
      e.linear = (pb - pa).norm();
      e.angular = rotationVectorFromQuat(b.q * (a.q * j.rel_orientation0).conjugate()).norm();
      break;
    case JointType::Universal:
      e.linear = (pb - pa).norm();
      e.angular = std::abs(std::asin(std::clamp(axa.dot(worldVector(b, j.local_axis2_b)), Real(-1), Real(1))));
      break;
    case JointType::ConeTwist: {
      e.linear = (pb - pa).norm();
      Real swing, twist;
      coneTwistAngles(j, a, b, swing, twist);
      e.angular = std::max(beyond(j.def.limit, twist), std::max(Real(0), swing - std::max(j.def.swing_span1, j.def.swing_span2)));
      break;
    }
    case JointType::Distance:
      e.linear = std::abs((pb - pa).norm() - j.length);
      break;
    case JointType::AngularMotor:
      break;
  }
  return e;
}

}  // namespace cairn
