#include "world/def_checks.hpp"

#include "cairn/error.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <sstream>

namespace cairn {

namespace {

std::string num(Real v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string got(Real v) { return " (got " + num(v) + ")"; }

// A coordinate, velocity, force...: finite with |v| <= kMaxMagnitude. NaN
// and infinities fail here too, with the range in the message.
void magnitude(const std::string& obj, const std::string& field, Real v) {
  if (!(std::abs(v) <= kMaxMagnitude))
    throw InputError(obj, field, "must be finite with magnitude at most " + num(kMaxMagnitude) + got(v));
}

void magnitude(const std::string& obj, const std::string& field, const Vec3& v) {
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(v[k]) <= kMaxMagnitude))
      throw InputError(obj, field, "must have finite components with magnitude at most " + num(kMaxMagnitude) + got(v[k]));
}

// Like magnitude(), but +infinity ("never", e.g. a break force) is allowed.
void magnitudeOrInfinity(const std::string& obj, const std::string& field, Real v) {
  if (v != kInf) magnitude(obj, field, v);
}

// A size, mass or density: in [kMinSize, kMaxMagnitude] (or exactly 0
// where `zero_ok`, e.g. a capsule's half height).
void size(const std::string& obj, const std::string& field, Real v, bool zero_ok = false) {
  if (zero_ok && v == 0) return;
  if (!(v >= kMinSize && v <= kMaxMagnitude))
    throw InputError(obj, field, "must lie in [" + num(kMinSize) + ", " + num(kMaxMagnitude) + "]" +
                                     (zero_ok ? " or be 0" : "") + got(v));
}

void optionalMagnitude(const std::string& obj, const std::string& field, const std::optional<Real>& v) {
  if (v) magnitude(obj, field, *v);
}

void softness(const std::string& obj, const std::string& prefix, const Softness& s) {
  optionalMagnitude(obj, prefix + "erp", s.erp);
  optionalMagnitude(obj, prefix + "cfm", s.cfm);
  optionalMagnitude(obj, prefix + "stiffness", s.stiffness);
  optionalMagnitude(obj, prefix + "damping", s.damping);
  optionalMagnitude(obj, prefix + "frequency", s.frequency);
  optionalMagnitude(obj, prefix + "damping_ratio", s.damping_ratio);
}

void count(const std::string& obj, const std::string& field, size_t n, std::uint64_t limit, const char* name) {
  if (n > limit)
    throw InputError(obj, field, std::to_string(n) + " entries exceed the limit " + limitHint(name, limit));
}

void shape(const std::string& obj, const std::string& f, const ShapeDesc& s) {
  magnitude(obj, f + ".position", s.local.p);
  switch (s.type) {
    case ShapeType::Sphere: size(obj, f + ".radius", s.radius); break;
    case ShapeType::Box:
      for (int k = 0; k < 3; ++k) size(obj, f + ".half_extents", s.half_extents[k]);
      break;
    case ShapeType::Capsule:
    case ShapeType::Cylinder:
      size(obj, f + ".radius", s.radius);
      size(obj, f + ".half_height", s.half_height, s.type == ShapeType::Capsule);
      break;
    case ShapeType::Plane:
      magnitude(obj, f + ".normal", s.normal);
      magnitude(obj, f + ".offset", s.offset);
      break;
    case ShapeType::ConvexHull:
      if (s.hull) {
        Vec3 lo = Vec3::Constant(kInf), hi = -lo;
        for (const Vec3& v : s.hull->vertices) {
          magnitude(obj, f + ".points", v);
          lo = lo.cwiseMin(v);
          hi = hi.cwiseMax(v);
        }
        // Its extent is a size: the inertia of a smaller hull underflows.
        if (!s.hull->vertices.empty()) size(obj, f + ".points", (hi - lo).maxCoeff());
      }
      break;
    case ShapeType::Mesh:
      if (s.mesh)
        for (const Vec3& v : s.mesh->vertices) magnitude(obj, f + ".obj", v);
      break;
  }
}

}  // namespace

void checkBodyDef(const BodyDef& def, const std::string& obj, const InputLimits& limits) {
  count(obj, "shapes", def.shapes.size(), limits.shapes_per_body, "shapes_per_body");
  if (def.mass) size(obj, "mass", *def.mass);
  if (def.density) size(obj, "density", *def.density);
  if (def.inertia) {
    const Mat3& m = *def.inertia;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        if (!(std::abs(m(r, c)) <= kMaxInertia))
          throw InputError(obj, "inertia", "must have finite entries with magnitude at most " + num(kMaxInertia) + got(m(r, c)));
    // The World refuses a tensor that is not positive definite; one that is
    // must not be so small that its inverse overflows.
    const Real smallest = Eigen::SelfAdjointEigenSolver<Mat3>(m, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
    if (smallest > 0 && smallest < kMinInertia)
      throw InputError(obj, "inertia", "eigenvalues must be at least " + num(kMinInertia) + got(smallest));
  }
  magnitude(obj, "position", def.position);
  magnitude(obj, "linear_velocity", def.linear_velocity);
  magnitude(obj, "angular_velocity", def.angular_velocity);
  magnitude(obj, "friction", def.friction);
  magnitude(obj, "restitution", def.restitution);
  magnitude(obj, "rolling_friction", def.rolling_friction);
  magnitude(obj, "torsional_friction", def.torsional_friction);
  magnitude(obj, "linear_damping", def.linear_damping);
  magnitude(obj, "angular_damping", def.angular_damping);
  magnitude(obj, "force", def.force);
  magnitude(obj, "torque", def.torque);
  for (size_t i = 0; i < def.impulses.size(); ++i) {
    const std::string f = "impulses[" + std::to_string(i) + "]";
    magnitude(obj, f + ".time", def.impulses[i].time);
    magnitude(obj, f + ".impulse", def.impulses[i].impulse);
    if (def.impulses[i].point) magnitude(obj, f + ".point", *def.impulses[i].point);
  }
  for (size_t i = 0; i < def.lock_translation.size(); ++i)
    magnitude(obj, "lock_translation[" + std::to_string(i) + "]", def.lock_translation[i]);
  for (size_t i = 0; i < def.lock_rotation.size(); ++i)
    magnitude(obj, "lock_rotation[" + std::to_string(i) + "]", def.lock_rotation[i]);
  for (size_t i = 0; i < def.shapes.size(); ++i) shape(obj, "shapes[" + std::to_string(i) + "]", def.shapes[i]);
}

void checkSpringDef(const SpringDef& def, const std::string& obj) {
  magnitude(obj, "anchors[0]", def.anchor_a);
  magnitude(obj, "anchors[1]", def.anchor_b);
  optionalMagnitude(obj, "rest_length", def.rest_length);
  magnitude(obj, "stiffness", def.stiffness);
  magnitude(obj, "damping", def.damping);
}

void checkJointDef(const JointDef& d, const std::string& obj) {
  magnitude(obj, "anchor", d.anchor);
  magnitude(obj, "axis", d.axis);
  magnitude(obj, "axis2", d.axis2);
  magnitude(obj, "anchors[0]", d.anchor_a);
  magnitude(obj, "anchors[1]", d.anchor_b);
  optionalMagnitude(obj, "length", d.length);
  if (d.limit.enabled) {
    magnitude(obj, "limits.lower", d.limit.lower);
    magnitude(obj, "limits.upper", d.limit.upper);
    magnitude(obj, "limits.restitution", d.limit.restitution);
    softness(obj, "limits.", d.limit.softness);
  }
  magnitude(obj, "swing_span1", d.swing_span1);
  magnitude(obj, "swing_span2", d.swing_span2);
  const auto motor = [&](const std::string& prefix, const MotorDef& m) {
    if (!m.enabled) return;
    magnitude(obj, prefix + "target_velocity", m.target_velocity);
    optionalMagnitude(obj, prefix + "max_force", m.max_force);
    optionalMagnitude(obj, prefix + "target_position", m.target_position);
    softness(obj, prefix, m.softness);
  };
  motor("motor.", d.motor);
  for (int i = 0; i < kDofCount; ++i) {  // six_dof axes
    const DofDef& dof = d.dofs[static_cast<size_t>(i)];
    const std::string prefix = std::string("dofs.") + dofName(i) + ".";
    if (dof.mode == DofMode::Limited) {
      magnitude(obj, prefix + "limits.lower", dof.limit.lower);
      magnitude(obj, prefix + "limits.upper", dof.limit.upper);
      softness(obj, prefix + "limits.", dof.limit.softness);
    }
    if (dof.spring.enabled) {
      magnitude(obj, prefix + "spring.rest", dof.spring.rest);
      softness(obj, prefix + "spring.", dof.spring.softness);
    }
    motor(prefix + "motor.", dof.motor);
  }
  for (size_t i = 0; i < d.motor_axes.size(); ++i) magnitude(obj, "motor[" + std::to_string(i) + "].axis", d.motor_axes[i]);
  for (size_t i = 0; i < d.motor_targets.size(); ++i)
    magnitude(obj, "motor[" + std::to_string(i) + "].target_velocity", d.motor_targets[i]);
  for (size_t i = 0; i < d.motor_max_torques.size(); ++i)
    magnitude(obj, "motor[" + std::to_string(i) + "].max_force", d.motor_max_torques[i]);
  softness(obj, "", d.softness);
  magnitudeOrInfinity(obj, "break_force", d.break_force);
  magnitudeOrInfinity(obj, "break_torque", d.break_torque);
}

void checkSolverSettings(const SolverSettings& s, const InputLimits& limits) {
  const std::string o = "solver";
  if (static_cast<std::uint64_t>(std::max(s.iterations, 0)) > limits.iterations)
    throw InputError(o, "iterations", std::to_string(s.iterations) + " exceeds the limit " + limitHint("iterations", limits.iterations));
  if (static_cast<std::uint64_t>(std::max(s.substeps, 0)) > limits.substeps)
    throw InputError(o, "substeps", std::to_string(s.substeps) + " exceeds the limit " + limitHint("substeps", limits.substeps));
  for (const auto& [v, f] : {std::pair{s.tolerance, "tolerance"}, std::pair{s.sor, "sor"},
                             std::pair{s.warm_start_factor, "warm_start_factor"}, std::pair{s.erp, "erp"},
                             std::pair{s.cfm, "cfm"}, std::pair{s.contact_erp, "contact_erp"}, std::pair{s.slop, "slop"},
                             std::pair{s.restitution_threshold, "restitution_threshold"},
                             std::pair{s.max_correction_velocity, "max_correction_velocity"},
                             std::pair{s.contact_margin, "contact_margin"},
                             std::pair{s.recycle_distance, "recycle_distance"},
                             std::pair{s.recycle_angle, "recycle_angle"},
                             std::pair{s.sleep_linear_velocity, "sleep_linear_velocity"},
                             std::pair{s.sleep_angular_velocity, "sleep_angular_velocity"},
                             std::pair{s.sleep_time, "sleep_time"}})
    magnitude(o, f, v);
  magnitudeOrInfinity(o, "max_angular_velocity", s.max_angular_velocity);
  for (const auto& [v, f] : {std::pair{s.energy_rise, "energy_rise"}, std::pair{s.joint_drift, "joint_drift"},
                             std::pair{s.joint_drift_angle, "joint_drift_angle"},
                             std::pair{s.penetration_drift, "penetration_drift"}})
    magnitudeOrInfinity(o, f, v);
}

void checkScene(const SceneDesc& scene, const InputLimits& limits) {
  count("scene", "bodies", scene.bodies.size(), limits.bodies, "bodies");
  count("scene", "springs", scene.springs.size(), limits.springs, "springs");
  count("scene", "joints", scene.joints.size(), limits.joints, "joints");
  magnitude("scene", "gravity", scene.gravity);
  size("scene", "dt", scene.dt);
  checkSolverSettings(scene.solver, limits);
  for (const BodyDef& b : scene.bodies) checkBodyDef(b, "body '" + b.name + "'", limits);
  for (size_t i = 0; i < scene.springs.size(); ++i)
    checkSpringDef(scene.springs[i], "spring '" + (scene.springs[i].name.empty() ? "#" + std::to_string(i) : scene.springs[i].name) + "'");
  for (const JointDef& j : scene.joints) checkJointDef(j, "joint '" + j.name + "'");
}

}  // namespace cairn
