#include "world/world.hpp"

#include "cairn/error.hpp"
#include "dynamics/forces.hpp"
#include "dynamics/mass_properties.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <sstream>

namespace cairn {

const char* bodyTypeName(BodyType t) {
  switch (t) {
    case BodyType::Static: return "static";
    case BodyType::Kinematic: return "kinematic";
    case BodyType::Dynamic: return "dynamic";
  }
  return "unknown";
}

const char* solverMethodName(SolverMethod m) {
  switch (m) {
    case SolverMethod::PGS: return "pgs";
    case SolverMethod::Direct: return "direct";
    case SolverMethod::LCP: return "lcp";
  }
  return "unknown";
}

namespace {

std::string num(Real v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

bool finite(Real v) { return std::isfinite(v); }

void requirePositive(const std::string& obj, const std::string& field, Real v) {
  if (!finite(v) || v <= 0) throw InputError(obj, field, "must be positive and finite (got " + num(v) + ")");
}

void requireNonNegative(const std::string& obj, const std::string& field, Real v) {
  if (!finite(v) || v < 0) throw InputError(obj, field, "must be finite and >= 0 (got " + num(v) + ")");
}

void requireFinite(const std::string& obj, const std::string& field, const Vec3& v) {
  if (!v.allFinite()) throw InputError(obj, field, "must be finite");
}

void validateShape(const std::string& obj, const std::string& f, const ShapeDesc& s, BodyType type) {
  requireFinite(obj, f + ".position", s.local.p);
  if (!s.local.q.coeffs().allFinite() || s.local.q.norm() < Real(1e-9))
    throw InputError(obj, f + ".orientation", "must be a finite, non-zero quaternion");
  switch (s.type) {
    case ShapeType::Sphere: requirePositive(obj, f + ".radius", s.radius); break;
    case ShapeType::Box:
      for (int k = 0; k < 3; ++k) requirePositive(obj, f + ".half_extents", s.half_extents[k]);
      break;
    case ShapeType::Capsule:
      requirePositive(obj, f + ".radius", s.radius);
      requireNonNegative(obj, f + ".half_height", s.half_height);
      break;
    case ShapeType::Cylinder:
      requirePositive(obj, f + ".radius", s.radius);
      requirePositive(obj, f + ".half_height", s.half_height);
      break;
    case ShapeType::Plane:
      if (type != BodyType::Static) throw InputError(obj, f + ".type", "a plane may only belong to a static body");
      requireFinite(obj, f + ".normal", s.normal);
      if (s.normal.norm() < Real(1e-9)) throw InputError(obj, f + ".normal", "must not be zero");
      if (!finite(s.offset)) throw InputError(obj, f + ".offset", "must be finite");
      break;
    case ShapeType::ConvexHull:
      if (!s.hull || s.hull->vertices.size() < 4 || s.hull->faces.size() < 4)
        throw InputError(obj, f + ".points", "convex hull needs at least 4 points that are not coplanar");
      break;
    case ShapeType::Mesh:
      if (type != BodyType::Static) throw InputError(obj, f + ".type", "a triangle mesh may only belong to a static body");
      if (!s.mesh || s.mesh->triangles.empty()) throw InputError(obj, f, "triangle mesh has no triangles");
      break;
  }
}

bool isSymmetricPositiveDefinite(const Mat3& m) {
  if (!m.allFinite() || !m.isApprox(m.transpose(), Real(1e-9))) return false;
  Eigen::SelfAdjointEigenSolver<Mat3> es(m);
  return es.eigenvalues().minCoeff() > 0;
}

}  // namespace

void validateSettings(const SolverSettings& s) {
  const std::string o = "solver";
  if (s.iterations < 1) throw InputError(o, "iterations", "must be >= 1 (got " + std::to_string(s.iterations) + ")");
  if (s.substeps < 1) throw InputError(o, "substeps", "must be >= 1 (got " + std::to_string(s.substeps) + ")");
  if (!finite(s.erp) || s.erp < 0 || s.erp > 1) throw InputError(o, "erp", "must lie in [0, 1] (got " + num(s.erp) + ")");
  if (!finite(s.contact_erp) || s.contact_erp < 0 || s.contact_erp > 1)
    throw InputError(o, "contact_erp", "must lie in [0, 1] (got " + num(s.contact_erp) + ")");
  requireNonNegative(o, "cfm", s.cfm);
  requireNonNegative(o, "tolerance", s.tolerance);
  if (!finite(s.sor) || s.sor <= 0 || s.sor >= 2) throw InputError(o, "sor", "must lie in (0, 2) (got " + num(s.sor) + ")");
  if (!finite(s.warm_start_factor) || s.warm_start_factor < 0 || s.warm_start_factor > 1)
    throw InputError(o, "warm_start_factor", "must lie in [0, 1] (got " + num(s.warm_start_factor) + ")");
  requireNonNegative(o, "slop", s.slop);
  requireNonNegative(o, "restitution_threshold", s.restitution_threshold);
  if (!(s.max_correction_velocity > 0)) throw InputError(o, "max_correction_velocity", "must be positive");
  if (!(s.max_angular_velocity > 0)) throw InputError(o, "max_angular_velocity", "must be positive");
  requireNonNegative(o, "contact_margin", s.contact_margin);
  requireNonNegative(o, "sleep_linear_velocity", s.sleep_linear_velocity);
  requireNonNegative(o, "sleep_angular_velocity", s.sleep_angular_velocity);
  requireNonNegative(o, "sleep_time", s.sleep_time);
}

BodyId World::createBody(const BodyDef& def) {
  // 1. Validate everything; nothing is touched until this passes.
  if (def.name.empty()) throw InputError("body #" + std::to_string(bodies_.size()), "name", "missing body name");
  const std::string obj = "body '" + def.name + "'";
  if (findBody(def.name).index >= 0) throw InputError(obj, "name", "another body has this name");
  requireFinite(obj, "position", def.position);
  if (!def.orientation.coeffs().allFinite()) throw InputError(obj, "orientation", "must be finite");
  if (def.orientation.norm() < Real(1e-9)) throw InputError(obj, "orientation", "zero-length quaternion");
  requireFinite(obj, "linear_velocity", def.linear_velocity);
  requireFinite(obj, "angular_velocity", def.angular_velocity);
  requireNonNegative(obj, "friction", def.friction);
  if (!finite(def.restitution) || def.restitution < 0 || def.restitution > 1)
    throw InputError(obj, "restitution", "must lie in [0, 1] (got " + num(def.restitution) + ")");
  requireNonNegative(obj, "rolling_friction", def.rolling_friction);
  requireNonNegative(obj, "torsional_friction", def.torsional_friction);
  requireNonNegative(obj, "linear_damping", def.linear_damping);
  requireNonNegative(obj, "angular_damping", def.angular_damping);
  for (size_t i = 0; i < def.shapes.size(); ++i)
    validateShape(obj, "shapes[" + std::to_string(i) + "]", def.shapes[i], def.type);

  Body b;
  b.name = def.name;
  b.type = def.type;
  b.orientation = def.orientation.normalized();
  b.friction = def.friction;
  b.restitution = def.restitution;
  b.linear_damping = def.linear_damping;
  b.angular_damping = def.angular_damping;
  b.ccd = def.ccd;
  b.rolling_friction = def.rolling_friction;
  b.torsional_friction = def.torsional_friction;
  b.collision_group = def.collision_group;
  b.collision_mask = def.collision_mask;
  b.shapes = def.shapes;
  for (auto& s : b.shapes) s.local.q.normalize();

  Vec3 com_local = Vec3::Zero();
  if (def.type == BodyType::Dynamic) {
    if (def.mass && def.density) throw InputError(obj, "mass", "give mass or density, not both");
    if (def.mass) requirePositive(obj, "mass", *def.mass);
    if (def.density) requirePositive(obj, "density", *def.density);
    if (def.inertia && !isSymmetricPositiveDefinite(*def.inertia))
      throw InputError(obj, "inertia", "must be a finite, symmetric, positive definite 3x3 matrix");
    Real volume = 0;
    for (const auto& s : def.shapes) volume += shapeVolume(s);
    MassProperties mp;
    if (volume > 0) {
      // Density from the mass if the mass is given; 1000 kg/m^3 (water) by default.
      const Real density = def.mass ? *def.mass / volume : def.density.value_or(Real(1000));
      mp = compoundMassProperties(def.shapes, density);
      if (def.mass) mp.mass = *def.mass;  // exact, not volume * density round-off
    } else {
      if (!def.mass) throw InputError(obj, "mass", "a dynamic body without solid shapes needs a mass");
      if (!def.inertia) throw InputError(obj, "inertia", "a dynamic body without solid shapes needs an inertia");
      mp.mass = *def.mass;
    }
    if (def.inertia) mp.inertia = *def.inertia;
    if (!isSymmetricPositiveDefinite(mp.inertia))
      throw InputError(obj, "shapes", "the shapes give a degenerate inertia tensor");
    com_local = mp.center;
    b.mass = mp.mass;
    b.inv_mass = 1 / mp.mass;
    b.inertia_body = mp.inertia;
    b.inv_inertia_body = mp.inertia.inverse();
    b.linear_velocity = def.linear_velocity;
    b.angular_velocity = def.angular_velocity;
  } else {
    b.mass = kInf;
    if (def.type == BodyType::Kinematic) {
      b.linear_velocity = def.linear_velocity;
      b.angular_velocity = def.angular_velocity;
      Real volume = 0;
      for (const auto& s : def.shapes) volume += shapeVolume(s);
      if (volume > 0) com_local = compoundMassProperties(def.shapes, 1).center;
    }
  }
  // The body origin moves to the center of mass; shapes keep their place.
  b.position = def.position + b.orientation * com_local;
  for (auto& s : b.shapes) s.local.p -= com_local;
  b.updateDerived();

  // 2. Commit.
  step_start_.push_back({b.position, b.orientation, b.linear_velocity, b.angular_velocity});  // its last good state
  bodies_.push_back(std::move(b));
  orientation_offset_.push_back(Vec3::Zero());
  sleep_island_.push_back(-1);
  body_island_.push_back(-1);
  const BodyId id{static_cast<std::int32_t>(bodies_.size() - 1)};
  registerShapes(id);
  return id;
}

int World::createSpring(const SpringDef& def) {
  const std::string obj = "spring '" + (def.name.empty() ? "#" + std::to_string(springs_.size()) : def.name) + "'";
  const auto checkBody = [&](BodyId id, const char* field) {
    if (!id.isWorld() && id.index >= bodyCount()) throw InputError(obj, field, "no such body");
  };
  checkBody(def.body_a, "bodies[0]");
  checkBody(def.body_b, "bodies[1]");
  if (def.body_a == def.body_b && !def.body_a.isWorld()) throw InputError(obj, "bodies", "a spring needs two different bodies");
  requireFinite(obj, "anchors[0]", def.anchor_a);
  requireFinite(obj, "anchors[1]", def.anchor_b);
  requireNonNegative(obj, "stiffness", def.stiffness);
  requireNonNegative(obj, "damping", def.damping);
  if (def.rest_length) requireNonNegative(obj, "rest_length", *def.rest_length);

  Spring s;
  s.def = def;
  s.local_a = def.body_a.isWorld() ? def.anchor_a : body(def.body_a).transform().applyInverse(def.anchor_a);
  s.local_b = def.body_b.isWorld() ? def.anchor_b : body(def.body_b).transform().applyInverse(def.anchor_b);
  s.rest_length = def.rest_length.value_or((def.anchor_b - def.anchor_a).norm());
  springs_.push_back(s);
  return static_cast<int>(springs_.size() - 1);
}

BodyId World::findBody(const std::string& name) const {
  for (size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].name == name) return BodyId{static_cast<std::int32_t>(i)};
  return kWorldBody;
}

// Pushing a body wakes it (and its island).
void World::applyForce(BodyId id, const Vec3& force, const Vec3& world_point) {
  wakeBody(id);
  applyForceAtPoint(body(id), force, world_point);
}
void World::applyCentralForce(BodyId id, const Vec3& force) {
  wakeBody(id);
  body(id).force += force;
}
void World::applyTorque(BodyId id, const Vec3& torque) {
  wakeBody(id);
  body(id).torque += torque;
}
void World::applyImpulse(BodyId id, const Vec3& impulse, const Vec3& world_point) {
  wakeBody(id);
  applyImpulseAtPoint(body(id), impulse, world_point);
}

void World::setKinematicVelocity(BodyId id, const Vec3& linear, const Vec3& angular) {
  Body& b = body(id);
  if (b.type != BodyType::Kinematic) throw InputError("body '" + b.name + "'", "type", "not a kinematic body");
  if (!linear.allFinite() || !angular.allFinite()) throw InputError("body '" + b.name + "'", "velocity", "must be finite");
  b.linear_velocity = linear;
  b.angular_velocity = angular;
}

void World::setGravity(const Vec3& g) {
  requireFinite("world", "gravity", g);
  gravity_ = g;
}

void World::setSettings(const SolverSettings& s) {
  validateSettings(s);
  settings_ = s;
}

Real World::kineticEnergy() const {
  Real e = 0;
  for (const auto& b : bodies_) e += b.kineticEnergy();
  return e;
}

Real World::potentialEnergy() const {
  Real e = 0;
  for (const auto& b : bodies_)
    if (b.isDynamic()) e -= b.mass * gravity_.dot(b.position);
  for (const auto& s : springs_) {
    const Vec3 pa = s.def.body_a.isWorld() ? s.local_a : body(s.def.body_a).transform().apply(s.local_a);
    const Vec3 pb = s.def.body_b.isWorld() ? s.local_b : body(s.def.body_b).transform().apply(s.local_b);
    e += springEnergy((pb - pa).norm(), s.rest_length, s.def.stiffness);
  }
  return e;
}

Vec3 World::linearMomentum() const {
  Vec3 p = Vec3::Zero();
  for (const auto& b : bodies_)
    if (b.isDynamic()) p += b.mass * b.linear_velocity;
  return p;
}

}  // namespace cairn
