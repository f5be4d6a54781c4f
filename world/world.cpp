// The public World (include/cairn/world.hpp): every call checks its
// handles, then forwards to the WorldImpl.
#include "cairn/world.hpp"

#include "cairn/error.hpp"
#include "dynamics/forces.hpp"
#include "world/world_impl.hpp"

#include <cmath>

namespace cairn {

using detail::WorldImpl;

World::World(const WorldDef& def) : impl_(std::make_unique<WorldImpl>()) {
  impl_->setGravity(def.gravity);
  impl_->setSettings(def.settings);
}
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

// --- Bodies -----------------------------------------------------------------

BodyId World::createBody(const BodyDef& def) { return impl_->createBody(def); }
void World::destroyBody(BodyId id) { impl_->destroyBody(id); }
bool World::isValid(BodyId id) const { return impl_->valid(id); }
int World::bodyCount() const { return impl_->aliveBodies(); }

std::vector<BodyId> World::bodies() const {
  std::vector<BodyId> out;
  out.reserve(static_cast<size_t>(impl_->aliveBodies()));
  for (int i = 0; i < impl_->bodySlots(); ++i)
    if (impl_->body(i).alive) out.push_back(impl_->bodyId(i));
  return out;
}

BodyId World::findBody(const std::string& name) const { return impl_->findBody(name); }

const std::string& World::name(BodyId id) const {
  impl_->check(id);
  return impl_->body(id).name;
}

BodyType World::type(BodyId id) const {
  impl_->check(id);
  return impl_->body(id).type;
}

void World::setType(BodyId id, BodyType type) { impl_->setType(id, type); }

Transform World::transform(BodyId id) const {
  impl_->check(id);
  return impl_->body(id).originTransform();
}

Vec3 World::centerOfMass(BodyId id) const {
  impl_->check(id);
  return impl_->body(id).position;
}

void World::setTransform(BodyId id, const Vec3& position, const Quat& orientation) {
  impl_->check(id);
  Body& b = impl_->body(id);
  const std::string obj = "body '" + b.name + "'";
  if (!position.allFinite()) throw InputError(obj, "position", "must be finite");
  if (!orientation.coeffs().allFinite() || orientation.norm() < Real(1e-9))
    throw InputError(obj, "orientation", "must be a finite, non-zero quaternion");
  b.orientation = orientation.normalized();
  b.position = position + b.orientation * b.com_local;
  b.updateDerived();
  impl_->moveProxies(id, 0);  // queries see it where it now is
  impl_->wakeBody(id);
  for (const Contact& c : impl_->contacts()) {  // what it touched may fall
    const BodyId other = c.body_a.index == id.index ? c.body_b : (c.body_b.index == id.index ? c.body_a : kWorldBody);
    if (!other.isWorld()) impl_->wakeBody(other);
  }
}

Vec3 World::linearVelocity(BodyId id) const {
  impl_->check(id);
  return impl_->body(id).linear_velocity;
}

Vec3 World::angularVelocity(BodyId id) const {
  impl_->check(id);
  return impl_->body(id).angular_velocity;
}

void World::setLinearVelocity(BodyId id, const Vec3& v) {
  impl_->check(id);
  Body& b = impl_->body(id);
  if (!v.allFinite()) throw InputError("body '" + b.name + "'", "linear_velocity", "must be finite");
  if (b.type == BodyType::Static) throw InputError("body '" + b.name + "'", "linear_velocity", "a static body does not move");
  b.linear_velocity = b.isDynamic() ? b.allowedLinear(v) : v;
  impl_->wakeBody(id);
}

void World::setAngularVelocity(BodyId id, const Vec3& w) {
  impl_->check(id);
  Body& b = impl_->body(id);
  if (!w.allFinite()) throw InputError("body '" + b.name + "'", "angular_velocity", "must be finite");
  if (b.type == BodyType::Static) throw InputError("body '" + b.name + "'", "angular_velocity", "a static body does not move");
  b.angular_velocity = b.isDynamic() ? b.allowedAngular(w) : w;
  impl_->wakeBody(id);
}

Vec3 World::velocityAt(BodyId id, const Vec3& world_point) const {
  impl_->check(id);
  return impl_->body(id).velocityAt(world_point);
}

Real World::mass(BodyId id) const {
  impl_->check(id);
  return impl_->body(id).mass;
}

Mat3 World::inertia(BodyId id) const {
  impl_->check(id);
  const Body& b = impl_->body(id);
  if (!b.isDynamic()) return Mat3::Constant(kInf);
  return b.rotation * b.inertia_body * b.rotation.transpose();
}

// --- Shapes ---------------------------------------------------------------------

ShapeId World::addShape(BodyId body, const ShapeDesc& shape) { return impl_->addShape(body, shape); }
void World::removeShape(ShapeId shape) { impl_->removeShape(shape); }

std::vector<ShapeId> World::shapes(BodyId body) const {
  impl_->check(body);
  std::vector<ShapeId> out;
  for (const std::int32_t slot : impl_->body(body).shape_ids)
    out.push_back(ShapeId{slot, impl_->shapes()[static_cast<size_t>(slot)].generation});
  return out;
}

BodyId World::shapeBody(ShapeId shape) const {
  impl_->check(shape);
  return impl_->shapes()[static_cast<size_t>(shape.index)].body;
}

const ShapeDesc& World::shape(ShapeId shape) const {
  impl_->check(shape);
  const ShapeRef& ref = impl_->shapes()[static_cast<size_t>(shape.index)];
  return impl_->body(ref.body).shapes[static_cast<size_t>(ref.index)];
}

// --- Forces -------------------------------------------------------------------------

namespace {
void requireFiniteVec(const Body& b, const char* field, const Vec3& v) {
  if (!v.allFinite()) throw InputError("body '" + b.name + "'", field, "must be finite");
}
}  // namespace

void World::applyForce(BodyId id, const Vec3& force, const Vec3& world_point) {
  impl_->check(id);
  requireFiniteVec(impl_->body(id), "force", force);
  requireFiniteVec(impl_->body(id), "point", world_point);
  impl_->applyForce(id, force, world_point);
}

void World::applyCentralForce(BodyId id, const Vec3& force) {
  impl_->check(id);
  requireFiniteVec(impl_->body(id), "force", force);
  impl_->applyCentralForce(id, force);
}

void World::applyTorque(BodyId id, const Vec3& torque) {
  impl_->check(id);
  requireFiniteVec(impl_->body(id), "torque", torque);
  impl_->applyTorque(id, torque);
}

void World::applyImpulse(BodyId id, const Vec3& impulse, const Vec3& world_point) {
  impl_->check(id);
  requireFiniteVec(impl_->body(id), "impulse", impulse);
  requireFiniteVec(impl_->body(id), "point", world_point);
  impl_->applyImpulse(id, impulse, world_point);
}

void World::applyAngularImpulse(BodyId id, const Vec3& angular_impulse) {
  impl_->check(id);
  Body& b = impl_->body(id);
  requireFiniteVec(b, "angular_impulse", angular_impulse);
  impl_->wakeBody(id);
  if (b.isDynamic()) b.angular_velocity += b.inv_inertia_world * angular_impulse;
}

void World::setKinematicVelocity(BodyId id, const Vec3& linear, const Vec3& angular) {
  impl_->check(id);
  impl_->setKinematicVelocity(id, linear, angular);
}

// --- Joints and springs -------------------------------------------------------------

JointId World::createJoint(const JointDef& def) { return impl_->createJoint(def); }
void World::destroyJoint(JointId id) { impl_->destroyJoint(id); }
bool World::isValid(JointId id) const { return impl_->valid(id); }
JointId World::findJoint(const std::string& name) const { return impl_->findJoint(name); }

const JointDef& World::jointDef(JointId id) const {
  impl_->check(id);
  return impl_->joint(id).def;
}

JointFeedback World::jointFeedback(JointId id) const {
  impl_->check(id);
  return impl_->jointFeedback(id);
}

JointError World::jointError(JointId id) const {
  impl_->check(id);
  return impl_->jointError(id);
}

bool World::isBroken(JointId id) const {
  impl_->check(id);
  return impl_->joint(id).broken;
}

void World::setMotor(JointId id, const MotorDef& motor) {
  impl_->check(id);
  Joint& j = impl_->joint(id);
  JointDef d = j.def;
  d.motor = motor;
  validateJointDef(d, impl_->bodySlots());
  j.def.motor = motor;
  if (!d.body_a.isWorld()) impl_->wakeBody(d.body_a);
  if (!d.body_b.isWorld()) impl_->wakeBody(d.body_b);
}

SpringId World::createSpring(const SpringDef& def) { return impl_->createSpring(def); }
void World::destroySpring(SpringId id) { impl_->destroySpring(id); }
bool World::isValid(SpringId id) const { return impl_->valid(id); }

// --- Contacts -------------------------------------------------------------------------

namespace {
ContactData contactData(const WorldImpl& w, const Contact& c) {
  ContactData d;
  d.body_a = c.body_a;
  d.body_b = c.body_b;
  d.shape_a = ShapeId{c.shape_a, w.shapes()[static_cast<size_t>(c.shape_a)].generation};
  d.shape_b = ShapeId{c.shape_b, w.shapes()[static_cast<size_t>(c.shape_b)].generation};
  d.normal = c.normal;
  d.count = c.count;
  d.touching = c.touching;
  const Transform ta = w.body(c.body_a).transform(), tb = w.body(c.body_b).transform();
  for (int i = 0; i < c.count; ++i) {
    const Vec3 pa = ta.apply(c.points[i].local_a), pb = tb.apply(c.points[i].local_b);
    d.points[i] = Real(0.5) * (pa + pb);
    d.depths[i] = c.points[i].depth;
    d.normal_impulses[i] = c.points[i].normal_impulse;
    d.friction_impulses[i] = c.points[i].friction_impulse;
  }
  return d;
}
}  // namespace

std::vector<ContactData> World::contacts(BodyId id) const {
  impl_->check(id);
  std::vector<ContactData> out;
  for (const Contact& c : impl_->contacts())
    if (c.enabled && (c.body_a.index == id.index || c.body_b.index == id.index)) out.push_back(contactData(*impl_, c));
  return out;
}

std::vector<ContactData> World::contacts() const {
  std::vector<ContactData> out;
  for (const Contact& c : impl_->contacts())
    if (c.enabled) out.push_back(contactData(*impl_, c));
  return out;
}

std::span<const ContactEvent> World::contactEvents() const { return impl_->contactEvents(); }
void World::setPreSolveCallback(ContactCallback callback) { impl_->setContactCallback(std::move(callback)); }

void World::setPairMaterial(BodyId a, BodyId b, Real friction, Real restitution) {
  impl_->check(a);
  impl_->check(b);
  impl_->setPairMaterial(a, b, friction, restitution);
}

// --- Collision filtering ----------------------------------------------------------------

void World::setCollisionFilter(BodyId id, std::uint32_t group, std::uint32_t mask) {
  impl_->check(id);
  Body& b = impl_->body(id);
  b.collision_group = group;
  b.collision_mask = mask;
  for (const std::int32_t slot : b.shape_ids)
    if (slot >= 0) impl_->broadphase_.setFilter(impl_->shapes_[static_cast<size_t>(slot)].proxy, group, mask);
  impl_->forgetProxyFits();  // the next refit decides again whether a proxy stays in the tree
  impl_->wakeBody(id);
}

void World::setCollisionFilterCallback(CollisionFilter filter) { impl_->setCollisionFilterCallback(std::move(filter)); }

// --- Sleeping -------------------------------------------------------------------------------

bool World::isAsleep(BodyId id) const {
  impl_->check(id);
  return impl_->isAsleep(id);
}

void World::wake(BodyId id) {
  impl_->check(id);
  impl_->wakeBody(id);
}

void World::putToSleep(BodyId id) {
  impl_->check(id);
  impl_->putIslandToSleep(id);
}

void World::setSleepingAllowed(BodyId id, bool allowed) {
  impl_->check(id);
  impl_->body(id).sleeping_allowed = allowed;
  if (!allowed) impl_->wakeBody(id);
}

// --- Settings -------------------------------------------------------------------------------

const Vec3& World::gravity() const { return impl_->gravity(); }
void World::setGravity(const Vec3& g) { impl_->setGravity(g); }
const SolverSettings& World::settings() const { return impl_->settings(); }
void World::setSettings(const SolverSettings& s) { impl_->setSettings(s); }

// --- Stepping -------------------------------------------------------------------------------

void World::step(Real h) { impl_->step(h); }
int World::stepCount() const { return impl_->stepCount(); }
Real World::time() const { return impl_->time(); }
const StepStats& World::lastStepStats() const { return impl_->lastStepStats(); }
std::span<const JointBreakEvent> World::jointBreakEvents() const { return impl_->jointBreakEvents(); }
std::span<const NumericalEvent> World::numericalEvents() const { return impl_->numericalEvents(); }
std::span<const Diagnostic> World::diagnostics() const { return impl_->diagnostics(); }

Real World::kineticEnergy() const { return impl_->kineticEnergy(); }
Real World::potentialEnergy() const { return impl_->potentialEnergy(); }
Vec3 World::linearMomentum() const { return impl_->linearMomentum(); }

}  // namespace cairn
