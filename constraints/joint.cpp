#include "constraints/joint.hpp"

#include "cairn/error.hpp"

#include <cmath>
#include <sstream>

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
    case JointType::SixDof: return "six_dof";
  }
  return "unknown";
}

const char* dofModeName(DofMode m) {
  switch (m) {
    case DofMode::Free: return "free";
    case DofMode::Limited: return "limited";
    case DofMode::Locked: return "locked";
  }
  return "unknown";
}

const char* dofName(int dof) {
  static const char* names[kDofCount] = {"translation_x", "translation_y", "translation_z",
                                         "rotation_x",    "rotation_y",    "rotation_z"};
  return dof >= 0 && dof < kDofCount ? names[dof] : "unknown";
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

std::string num(Real v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

Vec3 requireAxis(const std::string& obj, const char* field, const Vec3& v) {
  if (!v.allFinite()) throw InputError(obj, field, "must be finite");
  if (v.norm() < Real(1e-9)) throw InputError(obj, field, "zero axis");
  return v.normalized();
}

}  // namespace

namespace {

bool hasLimit(JointType t) { return t == JointType::Hinge || t == JointType::Slider || t == JointType::ConeTwist; }
bool hasMotor(JointType t) { return t == JointType::Hinge || t == JointType::Slider; }

// `angular`: the coordinate is an angle in (-pi, pi], so a bound outside
// [-pi, pi] could never be reached.
void validateLimit(const LimitDef& l, const Softness& joint_softness, const std::string& obj, const std::string& p,
                   bool angular) {
  if (!std::isfinite(l.lower)) throw InputError(obj, p + "lower", "must be finite");
  if (!std::isfinite(l.upper)) throw InputError(obj, p + "upper", "must be finite");
  if (l.lower > l.upper) throw InputError(obj, p + "lower", "lower > upper (" + num(l.lower) + " > " + num(l.upper) + ")");
  if (angular && (l.lower < -kPi || l.upper > kPi))
    throw InputError(obj, p + (l.lower < -kPi ? "lower" : "upper"), "an angle limit must lie in [-pi, pi]");
  validateSoftness(l.softness, obj, p);
  if (!std::isfinite(l.restitution) || l.restitution < 0 || l.restitution > 1)
    throw InputError(obj, p + "restitution", "must lie in [0, 1]");
  if (l.restitution > 0 && l.lower == l.upper)
    throw InputError(obj, p + "restitution", "a locked axis (lower == upper) does not bounce");
  if (l.restitution > 0 && isSpring(l.softness.isSet() ? l.softness : joint_softness))
    throw InputError(obj, p + "restitution", "a soft limit (stiffness/damping or frequency) bounces on its spring");
}

void validateMotor(const MotorDef& m, const std::string& obj, const std::string& p) {
  if (!m.enabled) return;
  if (!std::isfinite(m.target_velocity)) throw InputError(obj, p + "target_velocity", "must be finite");
  if (!m.max_force) throw InputError(obj, p + "max_force", "missing: a motor needs its largest force (N) or torque (N m)");
  if (!std::isfinite(*m.max_force) || *m.max_force < 0)
    throw InputError(obj, p + "max_force", "must be finite and >= 0 (got " + num(*m.max_force) + ")");
  validateSoftness(m.softness, obj, p);
  const Softness& s = m.softness;
  if (m.target_position) {
    if (!std::isfinite(*m.target_position)) throw InputError(obj, p + "target_position", "must be finite");
    if (m.target_velocity != 0)
      throw InputError(obj, p + "target_velocity", "give target_velocity (a velocity motor) or target_position (a servo), not both");
    if (s.erp || s.cfm)
      throw InputError(obj, p + (s.erp ? "erp" : "cfm"), "a servo's softness is a spring: stiffness/damping or frequency/damping_ratio");
    if (s.damping && !s.stiffness) throw InputError(obj, p + "damping", "a servo needs a stiffness (or a frequency)");
  } else {
    const char* spring = s.stiffness ? "stiffness" : s.frequency ? "frequency" : s.damping_ratio ? "damping_ratio" : s.erp ? "erp" : nullptr;
    if (spring)
      throw InputError(obj, p + spring, "a velocity motor's softness is a damper: damping (N s/m, N m s/rad) or cfm");
  }
}

void validateSixDof(const JointDef& d, const std::string& obj) {
  for (int i = 0; i < kDofCount; ++i) {
    const DofDef& dof = d.dofs[static_cast<size_t>(i)];
    const std::string p = std::string("dofs.") + dofName(i) + ".";
    const bool angular = i >= 3;
    if (dof.mode == DofMode::Limited) validateLimit(dof.limit, d.softness, obj, p + "limits.", angular);
    else if (dof.limit.enabled)
      throw InputError(obj, p + "limits", std::string("a ") + dofModeName(dof.mode) + " axis has no limits (mode \"limited\")");
    if (dof.spring.enabled) {
      const Softness& s = dof.spring.softness;
      validateSoftness(s, obj, p + "spring.");
      if (!s.stiffness && !s.frequency)
        throw InputError(obj, p + "spring.stiffness", "a spring needs a stiffness or a frequency");
      if (s.erp || s.cfm) throw InputError(obj, p + "spring.erp", "a spring is given by stiffness/damping or frequency/damping_ratio");
      if (!std::isfinite(dof.spring.rest) || (angular && std::abs(dof.spring.rest) > kPi))
        throw InputError(obj, p + "spring.rest", angular ? "must lie in [-pi, pi]" : "must be finite");
    }
    validateMotor(dof.motor, obj, p + "motor.");
  }
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
                         d.type == JointType::ConeTwist || d.type == JointType::SixDof;
  if (uses_axis) requireAxis(obj, "axis", d.axis);
  if (d.type == JointType::Universal || d.type == JointType::SixDof) {
    const Vec3 a2 = requireAxis(obj, "axis2", d.axis2);
    if (std::abs(a2.dot(d.axis.normalized())) > Real(1e-3))
      throw InputError(obj, "axis2", "must be perpendicular to axis");
  }
  if (d.limit.enabled) {
    if (!hasLimit(d.type))
      throw InputError(obj, "limits", std::string("a ") + jointTypeName(d.type) + " joint has no limits" +
                                          (d.type == JointType::SixDof ? " of its own (give them per axis in dofs)" : ""));
    validateLimit(d.limit, d.softness, obj, "limits.", d.type != JointType::Slider);
  }
  if (d.motor.enabled && !hasMotor(d.type))
    throw InputError(obj, "motor", std::string("a ") + jointTypeName(d.type) + " joint has no motor" +
                                       (d.type == JointType::SixDof ? " of its own (give one per axis in dofs)" : ""));
  validateMotor(d.motor, obj, "motor.");
  if (d.type == JointType::SixDof) validateSixDof(d, obj);
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
  if (def.type == JointType::SixDof) {
    Mat3 frame;  // x = axis, y = axis2 made exactly perpendicular, z = x cross y
    frame.col(0) = axis;
    frame.col(1) = (def.axis2 - axis * axis.dot(def.axis2)).normalized();
    frame.col(2) = frame.col(0).cross(frame.col(1));
    const Quat f(frame);
    j.local_frame_a = (a.q.conjugate() * f).normalized();
    j.local_frame_b = (b.q.conjugate() * f).normalized();
  }
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
    case JointType::SixDof: buildSixDofRows(j, a, b, ctx, s); break;
  }
}

JointError measureJointError(const Joint& j, const BodyView& a, const BodyView& b) {
  JointError e;
  const Vec3 pa = worldPoint(a, j.local_anchor_a), pb = worldPoint(b, j.local_anchor_b);
  // The axes only for the joints that read them (the watchers measure every
  // joint every step).
  const auto axisA = [&] { return worldVector(a, j.local_axis_a); };
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
      e.angular = std::max(std::asin(std::min(Real(1), axisA().cross(worldVector(b, j.local_axis_b)).norm())),
                           beyond(j.def.limit, angleNearLimits(hingeAngle(j, a, b), j.def.limit)));
      break;
    case JointType::Slider: {
      const Vec3 d = pb - pa, axa = axisA();
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
      e.angular = std::abs(std::asin(std::clamp(axisA().dot(worldVector(b, j.local_axis2_b)), Real(-1), Real(1))));
      break;
    case JointType::ConeTwist: {
      e.linear = (pb - pa).norm();
      Real swing, twist;
      coneTwistAngles(j, a, b, swing, twist);
      e.angular = std::max(beyond(j.def.limit, angleNearLimits(twist, j.def.limit)), std::max(Real(0), swing - std::max(j.def.swing_span1, j.def.swing_span2)));
      break;
    }
    case JointType::Distance:
      e.linear = std::abs((pb - pa).norm() - j.length);
      break;
    case JointType::AngularMotor:
      break;
    case JointType::SixDof: {
      const std::array<Real, kDofCount> c = sixDofCoordinates(j, a, b);
      for (int i = 0; i < kDofCount; ++i) {
        const DofDef& dof = j.def.dofs[static_cast<size_t>(i)];
        LimitDef l = dof.limit;
        l.enabled = dof.mode == DofMode::Limited;
        const Real off = dof.mode == DofMode::Locked ? std::abs(i >= 3 ? wrapAngle(c[i]) : c[i])
                                                      : beyond(l, i >= 3 ? angleNearLimits(c[i], l) : c[i]);
        Real& e_i = i < 3 ? e.linear : e.angular;
        e_i = std::max(e_i, off);
      }
      break;
    }
  }
  return e;
}

}  // namespace cairn
