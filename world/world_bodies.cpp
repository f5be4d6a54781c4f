// The World's bodies, shapes and springs: creation (validate everything,
// then commit), destruction, type changes, mass properties, forces,
// settings and energy bookkeeping.
#include "cairn/error.hpp"
#include "dynamics/forces.hpp"
#include "dynamics/mass_properties.hpp"
#include "world/world_impl.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
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

const char* simdName(Simd s) {
  switch (s) {
    case Simd::Auto: return "auto";
    case Simd::Portable: return "portable";
    case Simd::Avx2: return "avx2";
    case Simd::Avx512: return "avx512";
  }
  return "unknown";
}

const char* solverMethodName(SolverMethod m) {
  switch (m) {
    case SolverMethod::PGS: return "pgs";
    case SolverMethod::Direct: return "direct";
    case SolverMethod::LCP: return "lcp";
    case SolverMethod::Auto: return "auto";
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

bool isSymmetricPositiveDefinite(const Mat3& m) {
  if (!m.allFinite() || !m.isApprox(m.transpose(), Real(1e-9))) return false;
  Eigen::SelfAdjointEigenSolver<Mat3> es(m);
  return es.eigenvalues().minCoeff() > 0;
}

}  // namespace

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

void validateSettings(const SolverSettings& s) {
  const std::string o = "solver";
  if (s.iterations < 1) throw InputError(o, "iterations", "must be >= 1 (got " + std::to_string(s.iterations) + ")");
  if (s.position_iterations < 0)
    throw InputError(o, "position_iterations", "must be >= 0 (got " + std::to_string(s.position_iterations) + ")");
  if (s.substeps < 1) throw InputError(o, "substeps", "must be >= 1 (got " + std::to_string(s.substeps) + ")");
  if (s.threads < 1 || s.threads > 64)
    throw InputError(o, "threads", "must lie in [1, 64] (got " + std::to_string(s.threads) + ")");
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
  if (s.friction_directions != 1 && s.friction_directions != 2)
    throw InputError(o, "friction_directions", "must be 1 or 2 (got " + std::to_string(s.friction_directions) + ")");
  requireNonNegative(o, "recycle_distance", s.recycle_distance);
  requireNonNegative(o, "recycle_angle", s.recycle_angle);
  requireNonNegative(o, "sleep_linear_velocity", s.sleep_linear_velocity);
  requireNonNegative(o, "sleep_angular_velocity", s.sleep_angular_velocity);
  requireNonNegative(o, "sleep_time", s.sleep_time);
  if (s.max_pairs_per_shape < 1)
    throw InputError(o, "max_pairs_per_shape", "must be >= 1 (got " + std::to_string(s.max_pairs_per_shape) + ")");
  if (s.max_exact_rows < 1)
    throw InputError(o, "max_exact_rows", "must be >= 1 (got " + std::to_string(s.max_exact_rows) + ")");
  for (const auto& [v, f] : {std::pair{s.energy_rise, "energy_rise"}, std::pair{s.joint_drift, "joint_drift"},
                             std::pair{s.joint_drift_angle, "joint_drift_angle"},
                             std::pair{s.penetration_drift, "penetration_drift"}})
    if (!(v > 0)) throw InputError(o, f, "must be positive (infinity: never reported; got " + num(v) + ")");
}

namespace detail {

namespace {

// Orthonormal basis of the locked rotation axes (Gram-Schmidt), for the
// projector I - sum a a^T.
Mat3 rotationProjector(const std::vector<Vec3>& axes) {
  Mat3 p = Mat3::Identity();
  std::vector<Vec3> basis;
  for (const Vec3& a : axes) {
    Vec3 u = a.normalized();
    for (const Vec3& b : basis) u -= b * b.dot(u);
    if (u.norm() < Real(1e-9)) continue;  // already spanned
    u.normalize();
    basis.push_back(u);
    p -= u * u.transpose();
  }
  return p;
}

void validateLocks(const std::string& obj, const BodyDef& def) {
  for (size_t i = 0; i < def.lock_translation.size(); ++i) {
    const std::string f = "lock_translation[" + std::to_string(i) + "]";
    const Vec3& a = def.lock_translation[i];
    requireFinite(obj, f, a);
    if (a.norm() < Real(1e-9)) throw InputError(obj, f, "a zero axis locks nothing");
    const Vec3 u = a.normalized().cwiseAbs();
    if (std::abs(u.maxCoeff() - 1) > Real(1e-9))
      throw InputError(obj, f, "translation locks take the world axes x, y or z (a translation along another line is a slider joint)");
  }
  for (size_t i = 0; i < def.lock_rotation.size(); ++i) {
    const std::string f = "lock_rotation[" + std::to_string(i) + "]";
    requireFinite(obj, f, def.lock_rotation[i]);
    if (def.lock_rotation[i].norm() < Real(1e-9)) throw InputError(obj, f, "a zero axis locks nothing");
  }
}

void validateLoads(const std::string& obj, const BodyDef& def) {
  requireFinite(obj, "force", def.force);
  requireFinite(obj, "torque", def.torque);
  for (size_t i = 0; i < def.impulses.size(); ++i) {
    const std::string f = "impulses[" + std::to_string(i) + "]";
    const BodyDef::TimedImpulse& imp = def.impulses[i];
    if (!finite(imp.time) || imp.time < 0) throw InputError(obj, f + ".time", "must be finite and >= 0 (got " + num(imp.time) + ")");
    requireFinite(obj, f + ".impulse", imp.impulse);
    if (imp.point) requireFinite(obj, f + ".point", *imp.point);
  }
}

}  // namespace

// Mass properties from the definition and the shapes (dynamic bodies); the
// body frame stays, the center of mass moves to where the shapes put it.
void WorldImpl::recomputeMass(Body& b, const std::string& obj) {
  const Transform origin = b.originTransform();
  // Shapes back into the definition's frame.
  std::vector<ShapeDesc> shapes = b.shapes;
  for (auto& sh : shapes) sh.local.p += b.com_local;
  Vec3 com_local = Vec3::Zero();
  if (b.type == BodyType::Dynamic) {
    // Checked here, not only at creation: a static or kinematic body's
    // definition may carry a mass that only counts once it turns dynamic.
    if (b.def_mass && b.def_density) throw InputError(obj, "mass", "give mass or density, not both");
    if (b.def_mass) requirePositive(obj, "mass", *b.def_mass);
    if (b.def_density) requirePositive(obj, "density", *b.def_density);
    Real volume = 0;
    for (const auto& sh : shapes) volume += shapeVolume(sh);
    MassProperties mp;
    if (volume > 0) {
      // Density from the mass if the mass is given; 1000 kg/m^3 (water) by default.
      const Real density = b.def_mass ? *b.def_mass / volume : b.def_density.value_or(Real(1000));
      mp = compoundMassProperties(shapes, density);
      if (b.def_mass) mp.mass = *b.def_mass;  // exact, not volume * density round-off
    } else {
      if (!b.def_mass) throw InputError(obj, "mass", "a dynamic body without solid shapes needs a mass");
      if (!b.def_inertia) throw InputError(obj, "inertia", "a dynamic body without solid shapes needs an inertia");
      mp.mass = *b.def_mass;
    }
    if (b.def_inertia) mp.inertia = *b.def_inertia;
    if (!isSymmetricPositiveDefinite(mp.inertia))
      throw InputError(obj, "shapes", "the shapes give a degenerate inertia tensor");
    com_local = mp.center;
    b.mass = mp.mass;
    b.inv_mass = 1 / mp.mass;
    b.inertia_body = mp.inertia;
    b.inv_inertia_body = mp.inertia.inverse();
  } else {
    b.mass = kInf;
    b.inv_mass = 0;
    b.inertia_body = b.inv_inertia_body = Mat3::Zero();
    if (b.type == BodyType::Kinematic) {
      Real volume = 0;
      for (const auto& sh : shapes) volume += shapeVolume(sh);
      if (volume > 0) com_local = compoundMassProperties(shapes, 1).center;
    }
  }
  b.com_local = com_local;
  b.position = origin.apply(com_local);
  b.shapes = std::move(shapes);
  for (auto& sh : b.shapes) sh.local.p -= com_local;
  b.updateDerived();
}

BodyId WorldImpl::createBody(const BodyDef& def) {
  // 1. Validate everything; nothing is touched until this passes.
  if (def.name.empty()) throw InputError("body #" + std::to_string(alive_bodies_), "name", "missing body name");
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
  validateLocks(obj, def);
  validateLoads(obj, def);
  if (def.type == BodyType::Dynamic) {
    if (def.mass && def.density) throw InputError(obj, "mass", "give mass or density, not both");
    if (def.mass) requirePositive(obj, "mass", *def.mass);
    if (def.density) requirePositive(obj, "density", *def.density);
    if (def.inertia && !isSymmetricPositiveDefinite(*def.inertia))
      throw InputError(obj, "inertia", "must be a finite, symmetric, positive definite 3x3 matrix");
  }

  Body b;
  b.name = def.name;
  b.type = def.type;
  b.orientation = def.orientation.normalized();
  b.position = def.position;  // the body frame; recomputeMass moves it to the center of mass
  b.friction = def.friction;
  b.restitution = def.restitution;
  b.linear_damping = def.linear_damping;
  b.angular_damping = def.angular_damping;
  b.ccd = def.ccd;
  b.rolling_friction = def.rolling_friction;
  b.torsional_friction = def.torsional_friction;
  b.collision_group = def.collision_group;
  b.collision_mask = def.collision_mask;
  b.sleeping_allowed = def.sleeping_allowed;
  b.shapes = def.shapes;
  for (auto& sh : b.shapes) sh.local.q.normalize();
  b.def_mass = def.mass;
  b.def_density = def.density;
  b.def_inertia = def.inertia;
  for (const Vec3& a : def.lock_translation) b.linear_factor = b.linear_factor.cwiseProduct(Vec3::Ones() - a.normalized().cwiseAbs());
  if (!def.lock_rotation.empty()) {
    b.rotation_projector = rotationProjector(def.lock_rotation);
    b.rotation_locked = true;
  }
  b.constant_force = def.force;
  b.constant_torque = def.torque;
  b.impulses = def.impulses;
  std::stable_sort(b.impulses.begin(), b.impulses.end(),
                   [](const BodyDef::TimedImpulse& x, const BodyDef::TimedImpulse& y) { return x.time < y.time; });
  recomputeMass(b, obj);  // may throw: nothing committed yet
  if (b.isDynamic() || b.type == BodyType::Kinematic) {
    b.linear_velocity = b.isDynamic() ? b.allowedLinear(def.linear_velocity) : def.linear_velocity;
    b.angular_velocity = b.isDynamic() ? b.allowedAngular(def.angular_velocity) : def.angular_velocity;
  }

  // 2. Commit.
  std::int32_t index;
  if (!free_bodies_.empty()) {
    index = free_bodies_.back();
    free_bodies_.pop_back();
    b.generation = bodies_[static_cast<size_t>(index)].generation;
    bodies_[static_cast<size_t>(index)] = std::move(b);
  } else {
    index = static_cast<std::int32_t>(bodies_.size());
    bodies_.push_back(std::move(b));
    sleep_island_.push_back(-1);
    ctx_.step_start.emplace_back();
    ctx_.body_island.push_back(-1);
  }
  ++alive_bodies_;
  Body& nb = bodies_[static_cast<size_t>(index)];
  sleep_island_[static_cast<size_t>(index)] = -1;
  ctx_.step_start[static_cast<size_t>(index)] = {nb.position, nb.orientation, nb.linear_velocity, nb.angular_velocity, nb.asleep};
  const BodyId id{index, nb.generation};
  nb.shape_ids.assign(nb.shapes.size(), -1);
  for (size_t i = 0; i < nb.shapes.size(); ++i) registerShape(id, static_cast<std::int32_t>(i));
  return id;
}

namespace {

// A body whose shapes changed has a new centre of mass, the origin of its
// frame: its manifolds' points, fixed in that frame, moved. None of its
// manifolds may be recycled (world_contacts.cpp); a NaN reference pose
// fails recycling's comparisons.
void forgetManifoldPoses(std::vector<Contact>& contacts, BodyId id) {
  for (Contact& c : contacts)
    if (c.body_a.index == id.index || c.body_b.index == id.index)
      c.made_offset = Vec3::Constant(std::numeric_limits<Real>::quiet_NaN());
}

}  // namespace

// Contacts of the body (or of one of its shapes) leave the cache now; the
// touching ones report End with the next step.
void WorldImpl::dropContactsOf(BodyId id, std::int32_t shape) {
  const auto involved = [&](const Contact& c) {
    if (shape >= 0) return c.shape_a == shape || c.shape_b == shape;
    return c.body_a.index == id.index || c.body_b.index == id.index;
  };
  for (const Contact& c : contacts_)
    if (involved(c)) ended_contacts_.push_back(c);
  contacts_.erase(std::remove_if(contacts_.begin(), contacts_.end(), involved), contacts_.end());
}

void WorldImpl::destroyBody(BodyId id) {
  check(id);
  // What is attached goes with it.
  for (size_t j = 0; j < joints_.size(); ++j)
    if (joints_[j].alive && (joints_[j].def.body_a.index == id.index || joints_[j].def.body_b.index == id.index))
      destroyJoint(jointId(static_cast<int>(j)));
  for (size_t s = 0; s < springs_.size(); ++s)
    if (springs_[s].alive && (springs_[s].def.body_a.index == id.index || springs_[s].def.body_b.index == id.index))
      destroySpring(SpringId{static_cast<std::int32_t>(s), springs_[s].generation});
  wakeBody(id);
  // Bodies it touched wake up (their support may be gone).
  for (const Contact& c : contacts_) {
    const BodyId other = c.body_a.index == id.index ? c.body_b : (c.body_b.index == id.index ? c.body_a : kWorldBody);
    if (!other.isWorld()) wakeBody(other);
  }
  dropContactsOf(id, -1);
  dropDiagnosticsOf(id);
  Body& b = body(id);
  for (const std::int32_t slot : b.shape_ids) {
    ShapeRef& ref = shapes_[static_cast<size_t>(slot)];
    broadphase_.destroyProxy(ref.proxy);
    ref.alive = false;
    ++ref.generation;
    free_shapes_.push_back(slot);
  }
  const std::uint32_t generation = b.generation + 1;
  b = Body{};
  b.alive = false;
  b.generation = generation;
  sleep_island_[static_cast<size_t>(id.index)] = -1;
  free_bodies_.push_back(id.index);
  --alive_bodies_;
}

ShapeId WorldImpl::addShape(BodyId id, const ShapeDesc& shape) {
  check(id);
  Body& b = body(id);
  const std::string obj = "body '" + b.name + "'";
  validateShape(obj, "shapes[" + std::to_string(b.shapes.size()) + "]", shape, b.type);
  Body trial = b;  // mass properties first: a bad result changes nothing
  ShapeDesc local = shape;
  local.local.q.normalize();
  local.local.p -= b.com_local;
  trial.shapes.push_back(local);
  recomputeMass(trial, obj);
  wakeBody(id);
  b.mass = trial.mass;
  b.inv_mass = trial.inv_mass;
  b.inertia_body = trial.inertia_body;
  b.inv_inertia_body = trial.inv_inertia_body;
  b.com_local = trial.com_local;
  b.position = trial.position;
  b.shapes = std::move(trial.shapes);
  b.updateDerived();
  forgetManifoldPoses(contacts_, id);
  b.shape_ids.push_back(-1);
  registerShape(id, static_cast<std::int32_t>(b.shapes.size() - 1));
  const std::int32_t slot = b.shape_ids.back();
  return ShapeId{slot, shapes_[static_cast<size_t>(slot)].generation};
}

void WorldImpl::removeShape(ShapeId sid) {
  check(sid);
  ShapeRef& ref = shapes_[static_cast<size_t>(sid.index)];
  Body& b = body(ref.body);
  const std::string obj = "body '" + b.name + "'";
  Body trial = b;
  trial.shapes.erase(trial.shapes.begin() + ref.index);
  recomputeMass(trial, obj);  // throws (and changes nothing) if the body cannot keep its mass without it
  wakeBody(ref.body);
  dropContactsOf(ref.body, sid.index);
  broadphase_.destroyProxy(ref.proxy);
  const std::int32_t removed = ref.index;
  b.mass = trial.mass;
  b.inv_mass = trial.inv_mass;
  b.inertia_body = trial.inertia_body;
  b.inv_inertia_body = trial.inv_inertia_body;
  b.com_local = trial.com_local;
  b.position = trial.position;
  b.shapes = std::move(trial.shapes);
  b.updateDerived();
  forgetManifoldPoses(contacts_, ref.body);
  b.shape_ids.erase(b.shape_ids.begin() + removed);
  for (size_t i = static_cast<size_t>(removed); i < b.shape_ids.size(); ++i)
    shapes_[static_cast<size_t>(b.shape_ids[i])].index = static_cast<std::int32_t>(i);
  ref.alive = false;
  ++ref.generation;
  free_shapes_.push_back(sid.index);
}

void WorldImpl::setType(BodyId id, BodyType type) {
  check(id);
  Body& b = body(id);
  if (b.type == type) return;
  const std::string obj = "body '" + b.name + "'";
  for (size_t i = 0; i < b.shapes.size(); ++i)
    validateShape(obj, "shapes[" + std::to_string(i) + "]", b.shapes[i], type);
  Body trial = b;
  trial.type = type;
  recomputeMass(trial, obj);
  wakeBody(id);
  for (const Contact& c : contacts_) {  // what it touched may now move or fall
    const BodyId other = c.body_a.index == id.index ? c.body_b : (c.body_b.index == id.index ? c.body_a : kWorldBody);
    if (!other.isWorld()) wakeBody(other);
  }
  // Cached impulses were for the old masses.
  for (Contact& c : contacts_)
    if (c.body_a.index == id.index || c.body_b.index == id.index)
      for (int i = 0; i < c.count; ++i) {
        c.points[i].normal_impulse = 0;
        c.points[i].friction_impulse.setZero();
      }
  b = std::move(trial);
  if (type == BodyType::Static) {
    b.linear_velocity.setZero();
    b.angular_velocity.setZero();
  }
  b.asleep = false;
  b.sleep_timer = 0;
}

int WorldImpl::createSpringIndex(const SpringDef& def, const std::string& obj) {
  const auto checkBody = [&](BodyId bid, const char* field) {
    if (!bid.isWorld() && !valid(bid)) throw InputError(obj, field, "no such body");
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
  std::int32_t index;
  if (!free_springs_.empty()) {
    index = free_springs_.back();
    free_springs_.pop_back();
    s.generation = springs_[static_cast<size_t>(index)].generation;
    springs_[static_cast<size_t>(index)] = s;
  } else {
    index = static_cast<std::int32_t>(springs_.size());
    springs_.push_back(s);
  }
  if (!def.body_a.isWorld()) wakeBody(def.body_a);
  if (!def.body_b.isWorld()) wakeBody(def.body_b);
  return index;
}

SpringId WorldImpl::createSpring(const SpringDef& def) {
  const std::string obj = "spring '" + (def.name.empty() ? "#" + std::to_string(springs_.size()) : def.name) + "'";
  const std::int32_t index = createSpringIndex(def, obj);
  return SpringId{index, springs_[static_cast<size_t>(index)].generation};
}

void WorldImpl::destroySpring(SpringId id) {
  check(id);
  Spring& s = springs_[static_cast<size_t>(id.index)];
  if (!s.def.body_a.isWorld() && valid(s.def.body_a)) wakeBody(s.def.body_a);
  if (!s.def.body_b.isWorld() && valid(s.def.body_b)) wakeBody(s.def.body_b);
  s.alive = false;
  ++s.generation;
  free_springs_.push_back(id.index);
}

BodyId WorldImpl::findBody(const std::string& name) const {
  for (size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].alive && bodies_[i].name == name) return bodyId(static_cast<int>(i));
  return kWorldBody;
}

// --- Handles ------------------------------------------------------------

namespace {
[[noreturn]] void stale(const char* what, std::int32_t index, std::uint32_t generation, bool out_of_range) {
  throw HandleError(std::string(what) + " handle #" + std::to_string(index) + " (generation " +
                    std::to_string(generation) + ")",
                    out_of_range ? "no such " + std::string(what) + " in this world"
                                 : "stale handle: that " + std::string(what) + " was destroyed");
}
}  // namespace

bool WorldImpl::valid(BodyId id) const {
  return id.index >= 0 && static_cast<size_t>(id.index) < bodies_.size() && bodies_[static_cast<size_t>(id.index)].alive &&
         bodies_[static_cast<size_t>(id.index)].generation == id.generation;
}
bool WorldImpl::valid(JointId id) const {
  return id.index >= 0 && static_cast<size_t>(id.index) < joints_.size() && joints_[static_cast<size_t>(id.index)].alive &&
         joints_[static_cast<size_t>(id.index)].generation == id.generation;
}
bool WorldImpl::valid(SpringId id) const {
  return id.index >= 0 && static_cast<size_t>(id.index) < springs_.size() &&
         springs_[static_cast<size_t>(id.index)].alive && springs_[static_cast<size_t>(id.index)].generation == id.generation;
}
bool WorldImpl::valid(ShapeId id) const {
  return id.index >= 0 && static_cast<size_t>(id.index) < shapes_.size() && shapes_[static_cast<size_t>(id.index)].alive &&
         shapes_[static_cast<size_t>(id.index)].generation == id.generation;
}
void WorldImpl::check(BodyId id) const {
  if (!valid(id)) stale("body", id.index, id.generation, id.index < 0 || static_cast<size_t>(id.index) >= bodies_.size());
}
void WorldImpl::check(JointId id) const {
  if (!valid(id)) stale("joint", id.index, id.generation, id.index < 0 || static_cast<size_t>(id.index) >= joints_.size());
}
void WorldImpl::check(SpringId id) const {
  if (!valid(id)) stale("spring", id.index, id.generation, id.index < 0 || static_cast<size_t>(id.index) >= springs_.size());
}
void WorldImpl::check(ShapeId id) const {
  if (!valid(id)) stale("shape", id.index, id.generation, id.index < 0 || static_cast<size_t>(id.index) >= shapes_.size());
}

// Pushing a body wakes it (and its island).
void WorldImpl::applyForce(BodyId id, const Vec3& force, const Vec3& world_point) {
  wakeBody(id);
  external_forces_ = true;  // work from outside: the energy watcher holds off
  forced_bodies_.push_back(id.index);
  applyForceAtPoint(body(id), force, world_point);
}
void WorldImpl::applyCentralForce(BodyId id, const Vec3& force) {
  wakeBody(id);
  external_forces_ = true;  // work from outside: the energy watcher holds off
  forced_bodies_.push_back(id.index);
  body(id).force += force;
}
void WorldImpl::applyTorque(BodyId id, const Vec3& torque) {
  wakeBody(id);
  external_forces_ = true;  // work from outside: the energy watcher holds off
  forced_bodies_.push_back(id.index);
  body(id).torque += torque;
}
void WorldImpl::applyImpulse(BodyId id, const Vec3& impulse, const Vec3& world_point) {
  wakeBody(id);
  applyImpulseAtPoint(body(id), impulse, world_point);
}

void WorldImpl::setKinematicVelocity(BodyId id, const Vec3& linear, const Vec3& angular) {
  Body& b = body(id);
  if (b.type != BodyType::Kinematic) throw InputError("body '" + b.name + "'", "type", "not a kinematic body");
  if (!linear.allFinite() || !angular.allFinite()) throw InputError("body '" + b.name + "'", "velocity", "must be finite");
  b.linear_velocity = linear;
  b.angular_velocity = angular;
  b.asleep = false;
}

void WorldImpl::setGravity(const Vec3& g) {
  requireFinite("world", "gravity", g);
  gravity_ = g;
  for (Body& b : bodies_) {
    b.asleep = false;
    b.sleep_timer = 0;
  }
}

void WorldImpl::setSettings(const SolverSettings& s) {
  validateSettings(s);
  settings_ = s;
}

Real WorldImpl::kineticEnergy() const {
  Real e = 0;
  for (const auto& b : bodies_)
    if (b.alive) e += b.kineticEnergy();
  return e;
}

Real WorldImpl::potentialEnergy() const {
  Real e = 0;
  for (const auto& b : bodies_)
    if (b.alive && b.isDynamic()) e -= b.mass * gravity_.dot(b.position);
  for (const auto& s : springs_) {
    if (!s.alive) continue;
    const Vec3 pa = s.def.body_a.isWorld() ? s.local_a : body(s.def.body_a).transform().apply(s.local_a);
    const Vec3 pb = s.def.body_b.isWorld() ? s.local_b : body(s.def.body_b).transform().apply(s.local_b);
    e += springEnergy((pb - pa).norm(), s.rest_length, s.def.stiffness);
  }
  return e;
}

Vec3 WorldImpl::linearMomentum() const {
  Vec3 p = Vec3::Zero();
  for (const auto& b : bodies_)
    if (b.alive && b.isDynamic()) p += b.mass * b.linear_velocity;
  return p;
}

}  // namespace detail
}  // namespace cairn
